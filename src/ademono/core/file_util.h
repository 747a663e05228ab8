#pragma once
// File helpers: whole-file reads, atomic writes (temp file + rename, so a failed run never leaves
// half-written output), strict number parsing for text formats.

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <opencv2/core.hpp>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "ademono/core/image_header.h"

namespace ademono {

std::string ReadTextFile(const std::filesystem::path& path);

// Writes through `write` into "<path>.tmp.<pid>" and renames it onto `path` on success.
// Creates the parent directory. On any exception the temp file is removed and the error rethrown.
void WriteFileAtomic(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write);
void WriteTextFileAtomic(const std::filesystem::path& path, std::string_view text);
// cv::imwrite through a temp file with the same extension.
void WriteImageAtomic(const std::filesystem::path& path, const cv::Mat& image);

// Flushes a written file, or a directory's entries (after renames into it), to the disk, so the
// data survives a power loss, not only a killed process. InputError naming the path on failure.
void SyncFile(const std::filesystem::path& path);
void SyncDirectory(const std::filesystem::path& dir);

// Reads an image (cv::IMREAD_* flags); InputError naming the file if it is missing, declares
// more than kMaxImagePixels (image_header.h) or does not decode.
cv::Mat ReadImage(const std::filesystem::path& path, int flags);
// The same for content of `formats` only (OpenCV picks its decoder by content, not by name):
// InputError "path: <otherwise>" for anything else.
cv::Mat ReadImage(const std::filesystem::path& path, int flags,
                  std::initializer_list<ImageFormat> formats, const std::string& otherwise);

// Splits on whitespace (and commas when `commas` is true), dropping empty fields.
std::vector<std::string_view> SplitFields(std::string_view line, bool commas = false);
// Parses a finite double; InputError "path:line: field N 'text' is not a number" otherwise.
double ParseDouble(std::string_view text, const std::filesystem::path& path, size_t line,
                   size_t field_index);

// Reads `path` line by line, skipping empty lines and lines starting with '#'.
// Calls `on_line(line_number, fields)`.
void ForEachDataLine(
    const std::filesystem::path& path, bool commas,
    const std::function<void(size_t, const std::vector<std::string_view>&)>& on_line);

}  // namespace ademono
