#pragma once
// Image: float pixels, N interleaved channels, row-major with the top row first (CONTRACT.md §1).
// Reading and writing go through OpenImageIO: OpenEXR (half or float), PNG, TIFF and JPEG, with
// their metadata. Whether the values are linear radiance depends on the file: EXR renders and
// radiance maps are linear; 8/16-bit PNG/TIFF/JPEG values are the camera's encoded levels,
// scaled to [0, 1] (level / 255 or level / 65535), not linearised.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace igi {

using MetadataValue = std::variant<int64_t, double, std::string>;
// Image attributes by OpenImageIO name ("ExposureTime", "Exif:ISOSpeedRatings", "igi:camera").
using ImageMetadata = std::map<std::string, MetadataValue>;

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // size width * height * channels
  ImageMetadata metadata;

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f)
      : width(w), height(h), channels(c), pixels(size_t(w) * h * c, fill) {}

  bool empty() const { return pixels.empty(); }
  size_t index(int x, int y, int c = 0) const {
    return (size_t(y) * width + x) * channels + c;
  }
  float& at(int x, int y, int c = 0) { return pixels[index(x, y, c)]; }
  float at(int x, int y, int c = 0) const { return pixels[index(x, y, c)]; }
};

// The stored sample type of an image file.
enum class PixelType { kAuto, kUInt8, kUInt16, kHalf, kFloat };

struct ImageInfo {
  int width = 0;
  int height = 0;
  int channels = 0;
  PixelType type = PixelType::kFloat;
  int bits_per_sample = 32;
  std::string format;  // OpenImageIO's format name: "openexr", "png", "tiff", "jpeg", …
  ImageMetadata metadata;
};

// Reads only the header; throws InputError "FILE: cannot read image: REASON".
ImageInfo ReadImageInfo(const std::filesystem::path& path);

// Reads the whole image as float. Integer files are scaled to [0, 1]. `channels` > 0 keeps only
// the first `channels` channels (a grey image is repeated to fill 3). Throws InputError.
Image ReadImage(const std::filesystem::path& path, int channels = 0);

struct WriteImageOptions {
  // kAuto: float for EXR, uint16 for TIFF, uint8 for PNG and JPEG.
  PixelType type = PixelType::kAuto;
  // Passed to OpenImageIO ("zip", "piz", "none" for EXR; "lzw" for TIFF). Empty = its default.
  std::string compression;
  int jpeg_quality = 95;
};

// Writes atomically (temporary file + rename). Integer types clamp to [0, 1] and round. The
// image's metadata is written as attributes. Throws igi::Error if the format can't hold the
// image or the write fails.
void WriteImage(const std::filesystem::path& path, const Image& image,
                const WriteImageOptions& options = {});

}  // namespace igi
