#include "hdr/align.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "tools/common/error.h"

namespace igi::hdr {
namespace {

using Grey = GreyImage;

Grey HalfSize(const Grey& g) {
  Grey h{std::max(g.width / 2, 1), std::max(g.height / 2, 1), {}};
  h.levels.resize(size_t(h.width) * h.height);
  for (int y = 0; y < h.height; ++y) {
    for (int x = 0; x < h.width; ++x) {
      const int x0 = std::min(2 * x, g.width - 1), x1 = std::min(2 * x + 1, g.width - 1);
      const int y0 = std::min(2 * y, g.height - 1), y1 = std::min(2 * y + 1, g.height - 1);
      const int sum = g.levels[size_t(y0) * g.width + x0] + g.levels[size_t(y0) * g.width + x1] +
                      g.levels[size_t(y1) * g.width + x0] + g.levels[size_t(y1) * g.width + x1];
      h.levels[size_t(y) * h.width + x] = uint8_t((sum + 2) / 4);
    }
  }
  return h;
}

// Threshold bitmap (1 = above the median) and exclusion bitmap (1 = far enough from it).
struct Bitmaps {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> threshold;
  std::vector<uint8_t> keep;
};

// The level below which a fraction `rank` of the pixels lie.
int Percentile(const Grey& g, double rank) {
  int histogram[256] = {};
  for (uint8_t v : g.levels) ++histogram[v];
  int level = 0;
  for (size_t seen = 0; level < 255; ++level) {
    seen += size_t(histogram[level]);
    if (double(seen) >= rank * double(g.levels.size())) break;
  }
  return level;
}

// Fraction of pixels below `level`.
double RankOf(const Grey& g, int level) {
  size_t below = 0;
  for (uint8_t v : g.levels) below += v < level ? 1 : 0;
  return double(below) / double(g.levels.size());
}

Bitmaps MakeBitmaps(const Grey& g, int exclude_range, double rank) {
  const int median = Percentile(g, rank);
  Bitmaps b{g.width, g.height, std::vector<uint8_t>(g.levels.size()),
            std::vector<uint8_t>(g.levels.size())};
  for (size_t i = 0; i < g.levels.size(); ++i) {
    b.threshold[i] = g.levels[i] > median ? 1 : 0;
    b.keep[i] = std::abs(int(g.levels[i]) - median) > exclude_range ? 1 : 0;
  }
  return b;
}

// Pixels where the bitmaps disagree when `b` is moved by (dx, dy); pixels moved in from outside
// count as excluded.
int64_t Disagreement(const Bitmaps& a, const Bitmaps& b, int dx, int dy) {
  int64_t count = 0;
  for (int y = std::max(0, dy); y < std::min(a.height, a.height + dy); ++y) {
    const size_t row_a = size_t(y) * a.width;
    const size_t row_b = size_t(y - dy) * b.width;
    for (int x = std::max(0, dx); x < std::min(a.width, a.width + dx); ++x) {
      const size_t ia = row_a + x, ib = row_b + (x - dx);
      count += (a.threshold[ia] ^ b.threshold[ib]) & a.keep[ia] & b.keep[ib];
    }
  }
  return count;
}

// Ward's coarse-to-fine search: at each level, the best of the 9 neighbours of twice the coarser
// shift (ties keep the centre, so flat or empty bitmaps do not drift).
PixelShift FindShift(const Grey& reference, const Grey& image, int level, double rank,
                     const AlignOptions& options) {
  PixelShift shift;
  if (level > 0 && reference.width >= 16 && reference.height >= 16) {
    const PixelShift coarse =
        FindShift(HalfSize(reference), HalfSize(image), level - 1, rank, options);
    shift = {2 * coarse.dx, 2 * coarse.dy};
  }
  const Bitmaps a = MakeBitmaps(reference, options.exclude_range, rank);
  const Bitmaps b = MakeBitmaps(image, options.exclude_range, rank);
  PixelShift best = shift;
  int64_t best_error = Disagreement(a, b, shift.dx, shift.dy);
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const int64_t error = Disagreement(a, b, shift.dx + dx, shift.dy + dy);
      if (error < best_error) {
        best_error = error;
        best = {shift.dx + dx, shift.dy + dy};
      }
    }
  }
  return best;
}

}  // namespace

void ToGreyLevels(const float* pixels, size_t pixel_count, int channels, uint8_t* out) {
  const int n = std::min(channels, 3);
  for (size_t i = 0; i < pixel_count; ++i) {
    float sum = 0.0f;
    for (int c = 0; c < n; ++c) sum += pixels[i * size_t(channels) + size_t(c)];
    out[i] = uint8_t(std::clamp(sum / float(n) * 255.0f + 0.5f, 0.0f, 255.0f));
  }
}

GreyImage ToGrey(const Image& image) {
  GreyImage g{image.width, image.height, std::vector<uint8_t>(size_t(image.width) * image.height)};
  ToGreyLevels(image.pixels.data(), g.levels.size(), image.channels, g.levels.data());
  return g;
}

void AlignOptions::Validate() const {
  if (max_bits < 1 || max_bits > 10 || exclude_range < 0 || exclude_range > 64) {
    throw InputError(DescribeProblem("--align", "", fmt::format("{}/{}", max_bits, exclude_range),
                                     "need 1 <= max_bits <= 10 and 0 <= exclude_range <= 64"));
  }
}

namespace {

// The rank at which to threshold a pair: mid-way in the ranks whose levels are neither dark
// (< 32, the noise floor) nor bright (> 223) in both images; the median when there are none.
double PairRank(const Grey& a, const Grey& b) {
  const double lo = std::max(RankOf(a, 32), RankOf(b, 32));
  const double hi = std::min(RankOf(a, 224), RankOf(b, 224));
  return hi > lo ? 0.5 * (lo + hi) : 0.5;
}

double MeanLevel(const Grey& g) {
  double sum = 0.0;
  for (uint8_t v : g.levels) sum += v;
  return sum / double(g.levels.size());
}

}  // namespace

std::vector<PixelShift> ComputeMtbShifts(const std::vector<Image>& images, int reference,
                                         const AlignOptions& options) {
  options.Validate();
  std::vector<GreyImage> grey;
  for (const Image& image : images) grey.push_back(ToGrey(image));
  return ComputeMtbShifts(grey, reference, options);
}

std::vector<PixelShift> ComputeMtbShifts(const std::vector<GreyImage>& grey, int reference,
                                         const AlignOptions& options) {
  options.Validate();
  for (size_t j = 0; j < grey.size(); ++j) {
    if (grey[j].width != grey[0].width || grey[j].height != grey[0].height ||
        grey[j].levels.size() != size_t(grey[j].width) * size_t(grey[j].height)) {
      throw InputError(DescribeProblem(fmt::format("image {}", j), "size",
                                       fmt::format("{}x{}", grey[j].width, grey[j].height),
                                       "every image must have the size of the first"));
    }
  }
  if (!grey.empty() && (reference < 0 || size_t(reference) >= grey.size())) {
    throw InputError(DescribeProblem("--align", "reference", fmt::format("{}", reference),
                                     fmt::format("must be an image index below {}", grey.size())));
  }
  // Chain neighbours in brightness order outwards from the reference: two frames a stop or two
  // apart share many well-exposed pixels, the ends of a long bracket share none.
  std::vector<int> order(grey.size());
  for (size_t j = 0; j < order.size(); ++j) order[j] = int(j);
  std::vector<double> mean;
  for (const Grey& g : grey) mean.push_back(MeanLevel(g));
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return mean[size_t(a)] < mean[size_t(b)]; });
  const int at = int(std::find(order.begin(), order.end(), reference) - order.begin());
  std::vector<PixelShift> shifts(grey.size());
  for (int step : {-1, 1}) {
    for (int k = at + step; k >= 0 && k < int(order.size()); k += step) {
      const int previous = order[size_t(k - step)], current = order[size_t(k)];
      const double rank = PairRank(grey[size_t(previous)], grey[size_t(current)]);
      const PixelShift relative = FindShift(grey[size_t(previous)], grey[size_t(current)],
                                            options.max_bits - 1, rank, options);
      shifts[size_t(current)] = {shifts[size_t(previous)].dx + relative.dx,
                                 shifts[size_t(previous)].dy + relative.dy};
    }
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

int MedianExposureFrame(const std::vector<double>& exposures_s) {
  int reference = 0;
  for (size_t j = 0; j < exposures_s.size(); ++j) {
    int below = 0;
    for (double t : exposures_s) below += t < exposures_s[j] ? 1 : 0;
    if (below == int(exposures_s.size()) / 2) reference = int(j);
  }
  return reference;
}

}  // namespace igi::hdr
