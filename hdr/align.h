#pragma once
// Alignment of hand-held brackets by median threshold bitmaps (Ward, "Fast, robust image
// registration for compositing high dynamic range photographs from hand-held exposures",
// JGT 2003): each image is thresholded at its own median, so the bitmaps agree across exposures
// whatever the response; translations are found coarse to fine on an image pyramid, ignoring
// pixels within `exclude_range` levels of the median. igi's own implementation: OpenCV's
// AlignMTB drifts to its largest shift on the Memorial bracket (ties pick the first candidate).
// Two changes to Ward's method: (1) each image is aligned to its neighbour in brightness and the
// shifts are chained out from the reference (the ends of a long bracket share no well-exposed
// pixels); (2) a pair is thresholded at a common percentile whose levels lie between 32 and 223
// in both images rather than at the median, which in a dark scene sits in the noise floor.
// Percentiles do not depend on the response, so the bitmaps of both exposures still correspond.
// Translation only: rotation between frames is not modelled.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tools/common/image.h"

namespace igi::hdr {

struct AlignOptions {
  int max_bits = 6;       // pyramid levels: shifts up to about 2^max_bits pixels
  int exclude_range = 4;  // 8-bit levels around the median ignored in the bitmaps
  void Validate() const;
};

struct PixelShift {
  int dx = 0;  // shift to apply to the image so it lines up with the reference, pixels
  int dy = 0;
};

// What alignment sees of an image: 8-bit grey levels, row-major, 1 byte a pixel (a quarter of
// one float channel), so a bracket too large to hold as float can still be aligned.
struct GreyImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> levels;  // round(255 x mean of the first three channels), clamped
};

// The grey levels of `pixel_count` pixels of `channels` interleaved normalised levels, to `out`.
void ToGreyLevels(const float* pixels, size_t pixel_count, int channels, uint8_t* out);
GreyImage ToGrey(const Image& image);

// The frame of median exposure time (the best-exposed one): the reference to align a bracket to.
int MedianExposureFrame(const std::vector<double>& exposures_s);

// Shifts that align each image to images[reference] (whose shift is 0). Images are normalised
// levels in [0, 1] (any response).
std::vector<PixelShift> ComputeMtbShifts(const std::vector<Image>& images, int reference,
                                         const AlignOptions& options = {});
// The same from the images' grey levels (ToGrey): the same shifts.
std::vector<PixelShift> ComputeMtbShifts(const std::vector<GreyImage>& grey, int reference,
                                         const AlignOptions& options = {});

// Moves the content of `image` by `shift`; pixels shifted in from outside repeat the border.
Image ShiftImage(const Image& image, const PixelShift& shift);

}  // namespace igi::hdr
