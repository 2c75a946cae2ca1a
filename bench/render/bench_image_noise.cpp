// bench_image_noise A.exr B.exr: the noise of two renders of the same view that differ only in
// their random seed (time-to-noise benchmark, run_cycles_bench.sh). With luminance
// Y = 0.2126 R + 0.7152 G + 0.0722 B, one render's relative RMS noise is
//   sqrt(mean over pixels of (Y_A - Y_B)^2 / 2) / mean(Y)
// (A - B has twice the variance of one render; independent seeds, no bias term). Prints
// "mean_a MEAN mean_b MEAN noise REL". With --compare, A and B may come from different
// renderers: it also prints the relative difference of the means and the RMS relative
// difference of 16x16-pixel block means ("block_rms REL").
#include <cmath>
#include <cstdio>
#include <string>

#include "tools/common/image.h"

namespace {

double Luminance(const igi::Image& im, int x, int y) {
  return 0.2126 * im.at(x, y, 0) + 0.7152 * im.at(x, y, 1) + 0.0722 * im.at(x, y, 2);
}

double BlockRms(const igi::Image& a, const igi::Image& b, int block) {
  double sum2 = 0;
  int n = 0;
  for (int by = 0; by + block <= a.height; by += block) {
    for (int bx = 0; bx + block <= a.width; bx += block) {
      double ya = 0, yb = 0;
      for (int y = by; y < by + block; ++y) {
        for (int x = bx; x < bx + block; ++x) {
          ya += Luminance(a, x, y);
          yb += Luminance(b, x, y);
        }
      }
      if (yb > 0) {
        sum2 += (ya / yb - 1) * (ya / yb - 1);
        ++n;
      }
    }
  }
  return n > 0 ? std::sqrt(sum2 / n) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  bool compare = argc == 4 && std::string(argv[1]) == "--compare";
  if (argc != 3 && !compare) {
    std::fprintf(stderr, "usage: bench_image_noise [--compare] A.exr B.exr\n");
    return 2;
  }
  try {
    const igi::Image a = igi::ReadImage(argv[compare ? 2 : 1], 3);
    const igi::Image b = igi::ReadImage(argv[compare ? 3 : 2], 3);
    if (a.width != b.width || a.height != b.height) {
      std::fprintf(stderr, "bench_image_noise: sizes differ\n");
      return 2;
    }
    double sum_a = 0, sum_b = 0, sum_d2 = 0;
    for (int y = 0; y < a.height; ++y) {
      for (int x = 0; x < a.width; ++x) {
        const double ya = Luminance(a, x, y), yb = Luminance(b, x, y);
        sum_a += ya;
        sum_b += yb;
        sum_d2 += (ya - yb) * (ya - yb);
      }
    }
    const double n = double(a.width) * a.height;
    const double mean = 0.5 * (sum_a + sum_b) / n;
    std::printf("mean_a %.6g mean_b %.6g noise %.6f", sum_a / n, sum_b / n,
                std::sqrt(sum_d2 / n / 2) / mean);
    if (compare) std::printf(" mean_ratio %.5f block_rms %.5f", sum_a / sum_b, BlockRms(a, b, 16));
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_image_noise: %s\n", e.what());
    return 1;
  }
  return 0;
}
