#pragma once
// Image: float pixels, N interleaved channels, row-major with the top row first
// (docs/file-formats.md).
// Reading and writing go through OpenImageIO: OpenEXR (half or float), PNG, TIFF and JPEG, with
// their metadata. Whether the values are linear radiance depends on the file: EXR renders and
// radiance maps are linear; 8/16-bit PNG/TIFF/JPEG values are the camera's encoded levels,
// scaled to [0, 1] (level / 255 or level / 65535), not linearised.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
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

// The smallest integer factor f that brings a width × height image within `max_megapixels`
// as (width / f) × (height / f) pixels (1 when it is within already, or when max_megapixels is 0).
int ReductionFactor(int width, int height, double max_megapixels);

// The means of the image's f × f pixel blocks, (width / f) × (height / f) pixels: the radiance
// a camera with f× larger pixels records. The last columns and rows that fill no block are left
// out. f = 1 returns the image as it is.
Image BlockMeans(const Image& image, int f);

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
  // JPEG only: OpenImageIO's "CompressionQuality", 1..100 (higher: larger, truer files).
  int jpeg_quality = 95;
};

// Writes atomically (temporary file + rename). Integer types clamp to [0, 1] and round. The
// image's metadata is written as attributes. Throws igi::Error if the format can't hold the
// image or the write fails.
void WriteImage(const std::filesystem::path& path, const Image& image,
                const WriteImageOptions& options = {});

// Reads an image a band of rows at a time, so that only those rows are held in memory (scanline
// files read in order decode only the rows asked for; asking for an earlier row re-reads from the
// start). Values as ReadImage gives them (all channels; integer files scaled to [0, 1]).
class ImageRowReader {
 public:
  // Opens the file and reads its header; throws InputError "FILE: cannot read image: REASON".
  explicit ImageRowReader(const std::filesystem::path& path);
  ~ImageRowReader();
  ImageRowReader(const ImageRowReader&) = delete;
  ImageRowReader& operator=(const ImageRowReader&) = delete;

  const ImageInfo& info() const;
  // Reads rows [y0, y1) (0 <= y0 < y1 <= height) into `out`, which holds
  // (y1 - y0) x width x channels floats. Throws InputError naming the file on a read error.
  void ReadRows(int y0, int y1, float* out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes an image a band of rows at a time, top to bottom, to a temporary file beside `path`;
// Commit() after the last row renames it into place (an uncommitted writer removes it).
// Integer types clamp to [0, 1] and round, as WriteImage.
class ImageRowWriter {
 public:
  // Throws igi::Error if there is no writer for the extension or the file cannot be opened.
  ImageRowWriter(const std::filesystem::path& path, int width, int height, int channels,
                 const ImageMetadata& metadata = {}, const WriteImageOptions& options = {});
  ~ImageRowWriter();
  ImageRowWriter(const ImageRowWriter&) = delete;
  ImageRowWriter& operator=(const ImageRowWriter&) = delete;

  // Writes rows [y0, y1) from `rows` ((y1 - y0) x width x channels floats); y0 must be the row
  // after the last one written.
  void WriteRows(int y0, int y1, const float* rows);
  // Closes the file (every row must have been written) and renames it; throws igi::Error.
  void Commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace igi
