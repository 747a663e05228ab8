#include "ademono/core/image_header.h"

#include <array>
#include <cstring>
#include <fstream>
#include <string_view>

#include "ademono/core/error.h"

namespace fs = std::filesystem;

namespace ademono {
namespace {

class ByteReader {
 public:
  explicit ByteReader(const fs::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) ThrowInputError(path, "cannot open for reading");
  }

  // Up to `n` bytes from `offset`; fewer at the end of the file.
  std::string Read(uint64_t offset, size_t n) {
    std::string bytes(n, '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    if (!in_) return {};
    in_.read(bytes.data(), static_cast<std::streamsize>(n));
    bytes.resize(static_cast<size_t>(in_.gcount()));
    return bytes;
  }
  std::string ReadExactly(uint64_t offset, size_t n, const char* what) {
    std::string bytes = Read(offset, n);
    if (bytes.size() != n) ThrowInputError(path_, std::string("truncated image header: ") + what);
    return bytes;
  }
  [[noreturn]] void Fail(const std::string& message) const { ThrowInputError(path_, message); }

 private:
  fs::path path_;
  std::ifstream in_;
};

uint64_t Unsigned(std::string_view bytes, size_t at, size_t n, bool big_endian) {
  uint64_t value = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto byte = static_cast<uint8_t>(bytes[big_endian ? at + i : at + n - 1 - i]);
    value = (value << 8) | byte;
  }
  return value;
}

ImageHeader PngHeader(ByteReader& file) {
  // Signature (8), then the IHDR chunk: length (4), "IHDR", width (4), height (4), big-endian.
  const std::string ihdr = file.ReadExactly(8, 16, "PNG IHDR");
  if (ihdr.compare(4, 4, "IHDR") != 0) file.Fail("PNG does not start with an IHDR chunk");
  return {ImageFormat::kPng, static_cast<int64_t>(Unsigned(ihdr, 8, 4, true)),
          static_cast<int64_t>(Unsigned(ihdr, 12, 4, true))};
}

ImageHeader JpegHeader(ByteReader& file) {
  // Walk the marker segments to the first start-of-frame (SOF0-SOF15 but DHT, JPG, DAC).
  uint64_t at = 2;
  for (int segment = 0; segment < 4096; ++segment) {
    const std::string marker = file.ReadExactly(at, 4, "JPEG marker");
    if (static_cast<uint8_t>(marker[0]) != 0xFF) file.Fail("JPEG marker segment is malformed");
    const auto code = static_cast<uint8_t>(marker[1]);
    if (code == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (code == 0x01 || (code >= 0xD0 && code <= 0xD8)) {  // TEM, RSTn, SOI: no length field
      at += 2;
      continue;
    }
    const uint64_t length = Unsigned(marker, 2, 2, true);
    if (code >= 0xC0 && code <= 0xCF && code != 0xC4 && code != 0xC8 && code != 0xCC) {
      const std::string sof = file.ReadExactly(at + 4, 5, "JPEG frame header");
      return {ImageFormat::kJpeg, static_cast<int64_t>(Unsigned(sof, 3, 2, true)),
              static_cast<int64_t>(Unsigned(sof, 1, 2, true))};
    }
    if (code == 0xD9 || code == 0xDA) break;  // end of image or scan data before any frame
    if (length < 2) file.Fail("JPEG marker segment is malformed");
    at += 2 + length;
  }
  file.Fail("JPEG has no frame header");
}

ImageHeader TiffHeader(ByteReader& file, bool big_endian, bool big_tiff) {
  // The first IFD's ImageWidth (256) and ImageLength (257), SHORT or LONG (LONG8 in BigTIFF).
  const std::string head = file.ReadExactly(0, big_tiff ? 16 : 8, "TIFF header");
  const uint64_t ifd =
      big_tiff ? Unsigned(head, 8, 8, big_endian) : Unsigned(head, 4, 4, big_endian);
  const size_t count_size = big_tiff ? 8 : 2;
  const size_t entry_size = big_tiff ? 20 : 12;
  const uint64_t entries =
      Unsigned(file.ReadExactly(ifd, count_size, "TIFF directory"), 0, count_size, big_endian);
  if (entries > 4096) file.Fail("TIFF directory has " + std::to_string(entries) + " entries");
  const std::string table = file.ReadExactly(
      ifd + count_size, static_cast<size_t>(entries) * entry_size, "TIFF directory");
  int64_t size[2] = {0, 0};
  for (uint64_t e = 0; e < entries; ++e) {
    const size_t at = static_cast<size_t>(e) * entry_size;
    const uint64_t tag = Unsigned(table, at, 2, big_endian);
    if (tag != 256 && tag != 257) continue;
    const uint64_t type = Unsigned(table, at + 2, 2, big_endian);
    const size_t value_at = at + (big_tiff ? 12 : 8);
    // SHORT, LONG, and LONG8 (BigTIFF only: a classic entry's value field has 4 bytes).
    const size_t bytes = type == 3 ? 2 : type == 4 ? 4 : (type == 16 && big_tiff) ? 8 : 0;
    if (bytes == 0) file.Fail("TIFF image size tag has type " + std::to_string(type));
    size[tag - 256] = static_cast<int64_t>(Unsigned(table, value_at, bytes, big_endian));
  }
  return {big_tiff ? ImageFormat::kBigTiff : ImageFormat::kTiff, size[0], size[1]};
}

}  // namespace

const char* ImageFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kPng:
      return "PNG";
    case ImageFormat::kJpeg:
      return "JPEG";
    case ImageFormat::kTiff:
      return "TIFF";
    case ImageFormat::kBigTiff:
      return "BigTIFF";
  }
  return "?";
}

std::optional<ImageHeader> ReadImageHeader(const fs::path& path) {
  RequireFile(path);
  ByteReader file(path);
  const std::string magic = file.Read(0, 8);
  auto starts = [&](std::string_view prefix) {
    return magic.size() >= prefix.size() &&
           std::memcmp(magic.data(), prefix.data(), prefix.size()) == 0;
  };
  ImageHeader header;
  if (starts("\x89PNG\r\n\x1a\n")) {
    header = PngHeader(file);
  } else if (starts("\xFF\xD8\xFF")) {
    header = JpegHeader(file);
  } else if (starts(std::string_view("II*\0", 4)) || starts(std::string_view("MM\0*", 4))) {
    header = TiffHeader(file, magic[0] == 'M', false);
  } else if (starts(std::string_view("II+\0", 4)) || starts(std::string_view("MM\0+", 4))) {
    header = TiffHeader(file, magic[0] == 'M', true);
  } else {
    return std::nullopt;
  }
  const bool empty = header.width <= 0 || header.height <= 0;
  // Both sides at most 2^26 before the product is taken: no overflow.
  const bool huge = !empty && (header.width > kMaxImagePixels || header.height > kMaxImagePixels ||
                               header.width * header.height > kMaxImagePixels);
  if (empty || huge) {
    ThrowInputError(path, std::string(ImageFormatName(header.format)) + " header declares a " +
                              std::to_string(header.width) + " x " + std::to_string(header.height) +
                              " image" +
                              (huge ? "; the limit is " + std::to_string(kMaxImagePixels) +
                                          " pixels"
                                    : ""));
  }
  return header;
}

}  // namespace ademono
