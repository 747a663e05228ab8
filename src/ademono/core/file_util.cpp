#include "ademono/core/file_util.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "ademono/core/error.h"

namespace fs = std::filesystem;

namespace ademono {

std::string ReadTextFile(const fs::path& path) {
  RequireFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError(path, "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {
fs::path TempPathFor(const fs::path& path) {
  return path.parent_path() /
         (".tmp." + std::to_string(::getpid()) + "." + path.filename().string());
}
void EnsureParent(const fs::path& path) {
  if (path.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    if (ec) ThrowInputError(path.parent_path(), "cannot create directory: " + ec.message());
  }
}
}  // namespace

void WriteFileAtomic(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  EnsureParent(path);
  const fs::path tmp = TempPathFor(path);
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) ThrowInputError(path, "cannot open for writing");
      write(out);
      out.flush();
      if (!out) ThrowInputError(path, "write failed");
    }
    fs::rename(tmp, path);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

void WriteTextFileAtomic(const fs::path& path, std::string_view text) {
  WriteFileAtomic(path, [&](std::ostream& out) { out << text; });
}

void WriteImageAtomic(const fs::path& path, const cv::Mat& image) {
  EnsureParent(path);
  const fs::path tmp = TempPathFor(path);
  try {
    if (!cv::imwrite(tmp.string(), image)) ThrowInputError(path, "cannot write image");
    fs::rename(tmp, path);
  } catch (const cv::Exception& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    ThrowInputError(path, std::string("cannot write image: ") + e.err);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

namespace {
void SyncPath(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) ThrowInputError(path, std::string("cannot open to sync: ") + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int sync_errno = errno;
  ::close(fd);
  if (rc != 0) ThrowInputError(path, std::string("fsync failed: ") + std::strerror(sync_errno));
}
}  // namespace

void SyncFile(const fs::path& path) { SyncPath(path, O_RDONLY); }
void SyncDirectory(const fs::path& dir) { SyncPath(dir, O_RDONLY | O_DIRECTORY); }

namespace {
// The decode behind both readers, once ReadImageHeader has checked the declared size: OpenCV's
// own limit (2^30 pixels) lets a 60-byte file ask for gigabytes.
cv::Mat DecodeImage(const fs::path& path, int flags) {
  cv::Mat image;
  try {
    image = cv::imread(path.string(), flags);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) ThrowInputError(path, "image does not decode");
  return image;
}
}  // namespace

cv::Mat ReadImage(const fs::path& path, int flags) {
  ReadImageHeader(path);  // throws on a declared size past kMaxImagePixels
  return DecodeImage(path, flags);
}

cv::Mat ReadImage(const fs::path& path, int flags, std::initializer_list<ImageFormat> formats,
                  const std::string& otherwise) {
  const std::optional<ImageHeader> header = ReadImageHeader(path);
  if (!header || std::find(formats.begin(), formats.end(), header->format) == formats.end())
    ThrowInputError(path, otherwise);
  return DecodeImage(path, flags);
}

std::vector<std::string_view> SplitFields(std::string_view line, bool commas) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  auto is_sep = [&](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || (commas && c == ',');
  };
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

double ParseDouble(std::string_view text, const fs::path& path, size_t line, size_t field_index) {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (!text.empty() && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) {
    ThrowInputError(path, line,
                    "field " + std::to_string(field_index + 1) + " '" + std::string(text) +
                        "' is not a finite number");
  }
  return value;
}

void ForEachDataLine(
    const fs::path& path, bool commas,
    const std::function<void(size_t, const std::vector<std::string_view>&)>& on_line) {
  RequireFile(path);
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "cannot open for reading");
  std::string line;
  size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    auto fields = SplitFields(line, commas);
    if (fields.empty() || fields.front().front() == '#') continue;
    on_line(number, fields);
  }
}

}  // namespace ademono
