#include "hdr/align.h"

#include <algorithm>
#include <fmt/format.h>
#include <opencv2/photo.hpp>

#include "tools/common/error.h"

namespace igi::hdr {
namespace {

cv::Mat Grey8(const Image& image) {
  cv::Mat grey(image.height, image.width, CV_8UC1);
  for (int y = 0; y < image.height; ++y) {
    auto* row = grey.ptr<uint8_t>(y);
    for (int x = 0; x < image.width; ++x) {
      float sum = 0.0f;
      for (int c = 0; c < std::min(image.channels, 3); ++c) sum += image.at(x, y, c);
      const float v = sum / float(std::min(image.channels, 3));
      row[x] = uint8_t(std::clamp(v * 255.0f + 0.5f, 0.0f, 255.0f));
    }
  }
  return grey;
}

}  // namespace

void AlignOptions::Validate() const {
  if (max_bits < 1 || max_bits > 10 || exclude_range < 0 || exclude_range > 64) {
    throw InputError(DescribeProblem("--align", "", fmt::format("{}/{}", max_bits, exclude_range),
                                     "need 1 <= max_bits <= 10 and 0 <= exclude_range <= 64"));
  }
}

std::vector<PixelShift> ComputeMtbShifts(const std::vector<Image>& images, int reference,
                                         const AlignOptions& options) {
  options.Validate();
  cv::Ptr<cv::AlignMTB> mtb = cv::createAlignMTB(options.max_bits, options.exclude_range, false);
  const cv::Mat ref = Grey8(images[size_t(reference)]);
  std::vector<PixelShift> shifts(images.size());
  for (size_t j = 0; j < images.size(); ++j) {
    if (int(j) == reference) continue;
    const cv::Point shift = mtb->calculateShift(ref, Grey8(images[j]));
    shifts[j] = {shift.x, shift.y};
  }
  return shifts;
}

Image ShiftImage(const Image& image, const PixelShift& shift) {
  Image out(image.width, image.height, image.channels);
  out.metadata = image.metadata;
  for (int y = 0; y < image.height; ++y) {
    const int sy = std::clamp(y - shift.dy, 0, image.height - 1);
    for (int x = 0; x < image.width; ++x) {
      const int sx = std::clamp(x - shift.dx, 0, image.width - 1);
      for (int c = 0; c < image.channels; ++c) out.at(x, y, c) = image.at(sx, sy, c);
    }
  }
  return out;
}

}  // namespace igi::hdr
