// Reads an image file's declared format and size from its header, without decoding it, so that a
// corrupt or hostile file claiming a gigapixel size is refused before OpenCV allocates for it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace ademono {

enum class ImageFormat { kPng, kJpeg, kTiff, kBigTiff };

struct ImageHeader {
  ImageFormat format = ImageFormat::kPng;
  int64_t width = 0;
  int64_t height = 0;
};

// The largest image ademono decodes: 8192 x 8192 (a 16-bit 4-channel image of this size is
// 512 MB). Cameras and depth networks stay far below it.
inline constexpr int64_t kMaxImagePixels = int64_t{1} << 26;

const char* ImageFormatName(ImageFormat format);

// The header of a PNG, JPEG or (Big)TIFF file; std::nullopt for any other signature. InputError
// naming the file when a recognised header is truncated, declares no size or declares more than
// kMaxImagePixels.
std::optional<ImageHeader> ReadImageHeader(const std::filesystem::path& path);

}  // namespace ademono
