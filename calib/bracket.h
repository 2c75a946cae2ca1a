#pragma once
// An exposure bracket: photos of a still scene taken with different exposure times, loaded as
// the camera's encoded levels (not linear radiance) normalised to [0, 1], with their times.
//
// Bad input (fewer than two images, a corrupt file, images of different sizes or channel counts,
// a float image where levels are needed, missing or duplicate exposure times) is an InputError
// naming the image and the rule.

#include <filesystem>
#include <string>
#include <vector>

#include "tools/common/image.h"

namespace igi::calib {

// Where the exposure times come from: `list` ("1/250,1/60") or `file`; both empty = EXIF.
struct ExposureSource {
  std::string list;
  std::filesystem::path file;
};

struct Bracket {
  std::vector<Image> images;       // encoded levels / (2^bits - 1), same size and channels
  std::vector<std::string> names;  // file paths, for messages
  std::vector<double> exposures_s;
  int bits_per_sample = 8;  // 8 or 16

  int width() const { return images.empty() ? 0 : images[0].width; }
  int height() const { return images.empty() ? 0 : images[0].height; }
  int channels() const { return images.empty() ? 0 : images[0].channels; }
  int levels() const { return 1 << bits_per_sample; }
};

// Resolves the exposure times of `names` from `source` (EXIF read from `metadata` when empty).
std::vector<double> ResolveExposures(const ExposureSource& source,
                                     const std::vector<std::string>& names,
                                     const std::vector<ImageMetadata>& metadata);

// Checks that every image has the size and channel count of the first.
void CheckSameShape(const std::vector<Image>& images, const std::vector<std::string>& names);

// Loads 8- or 16-bit images (PNG, TIFF, JPEG, …) with their exposure times.
// LoadBracket's checks on the files' headers alone (pixel types, sizes and channels, exposure
// times), without reading their pixels: a Bracket without images; *channels gets the frames'
// channel count. For merges that stream the frames (hdr/merge_stream.h).
Bracket LoadBracketHeaders(const std::vector<std::filesystem::path>& paths,
                           const ExposureSource& source, int* channels);

Bracket LoadBracket(const std::vector<std::filesystem::path>& paths, const ExposureSource& source);

}  // namespace igi::calib
