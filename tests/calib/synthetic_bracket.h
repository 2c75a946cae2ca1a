#pragma once
// Test helper (header only, shared by tests/calib and tests/hdr): a synthetic exposure bracket
// with known truth, standing in for igi-synth brackets until igi-synth exists.
//
// The scene is a grid of 8x8 tiles (each a gentle horizontal ramp) of log-uniform radiance over 3.5
// decades (per-channel factors 1, 0.8, 0.6). Exposure X = E * t (1 = full scale) is recorded with
// shot noise (full_well electrons at full scale), Gaussian read noise, then a known film-like
// response
//   v = f(X) = (1 - exp(-3 X^0.6)) / (1 - exp(-3)),  X clipped to [0, 1],
// and quantised to `bits`. The true g is ln f^-1(v).

#include <cmath>
#include <random>
#include <vector>

#include "calib/bracket.h"

namespace igi::testing {

struct SyntheticOptions {
  int width = 256;
  int height = 192;
  int bits = 8;
  std::vector<double> exposures_s = {1.0 / 64, 1.0 / 16, 1.0 / 4, 1.0, 4.0};
  double full_well = 20000.0;  // electrons at full scale (shot noise); 0 = no noise
  double read_noise = 5.0;     // electrons (std)
  double min_radiance = 0.02;  // radiance range of the tiles
  double max_radiance = 60.0;
  unsigned seed = 1;
};

struct SyntheticBracket {
  calib::Bracket bracket;
  std::vector<double> radiance;  // true radiance, interleaved like the images
};

// The known response and its inverse (X in [0, 1] <-> v in [0, 1]).
inline double SyntheticResponse(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return (1.0 - std::exp(-3.0 * std::pow(x, 0.6))) / (1.0 - std::exp(-3.0));
}
inline double SyntheticLnExposure(double v) {
  const double inner = -std::log(1.0 - std::clamp(v, 1e-9, 1.0) * (1.0 - std::exp(-3.0))) / 3.0;
  return std::log(std::pow(inner, 1.0 / 0.6));
}

inline SyntheticBracket MakeSyntheticBracket(const SyntheticOptions& o = {}) {
  SyntheticBracket s;
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> uniform(std::log(o.min_radiance),
                                                 std::log(o.max_radiance));
  std::normal_distribution<double> normal(0.0, 1.0);
  const double factor[3] = {1.0, 0.8, 0.6};
  s.radiance.resize(size_t(o.width) * o.height * 3);
  const int tiles_x = (o.width + 7) / 8;
  std::vector<double> tile_radiance(size_t(tiles_x) * ((o.height + 7) / 8));
  for (double& r : tile_radiance) r = std::exp(uniform(rng));
  for (int y = 0; y < o.height; ++y) {
    for (int x = 0; x < o.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        // A gentle ramp inside each tile (x 0.8 .. 1.25) keeps the levels continuous.
        const double ramp = std::exp(0.446 * ((x % 8) / 7.0 - 0.5));
        s.radiance[(size_t(y) * o.width + x) * 3 + c] =
            tile_radiance[size_t(y / 8) * tiles_x + x / 8] * factor[c] * ramp;
      }
    }
  }
  const double top = double((1 << o.bits) - 1);
  for (size_t j = 0; j < o.exposures_s.size(); ++j) {
    Image image(o.width, o.height, 3);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      double x = s.radiance[i] * o.exposures_s[j];
      if (o.full_well > 0) {
        const double electrons = x * o.full_well;
        x = (electrons + std::sqrt(std::max(electrons, 0.0)) * normal(rng) +
             o.read_noise * normal(rng)) /
            o.full_well;
      }
      image.pixels[i] = float(std::round(SyntheticResponse(x) * top) / top);
    }
    s.bracket.images.push_back(std::move(image));
    s.bracket.names.push_back("synthetic" + std::to_string(j));
  }
  s.bracket.exposures_s = o.exposures_s;
  s.bracket.bits_per_sample = o.bits;
  return s;
}

}  // namespace igi::testing
