#pragma once
// A camera sensor for synthetic photos (SensorOptions of synth_options.h), and camera response
// curves for LDR exposure brackets.
//
// Signal chain of one pixel channel of linear radiance L (W·sr⁻¹·m⁻²), exposure t seconds,
// sensitivity k (e⁻ per radiance unit per second):
//   mean electrons  μ = L·k·t;  e = Poisson(μ) (Gaussian N(μ, μ) for μ >= 30) + N(0, σ_read²)
//   e clipped to [.., full_well];  DN = round(e / gain) + black, clipped to [0, 2^bits − 1],
//   gain = full_well / (2^bits − 1 − black) e⁻/DN
//   HDR photo value = (DN − black)·gain / (k·t)   (radiance units; unbiased below saturation)
// so Var(photo) = (μ + σ_read² + gain²/12) / (k·t)² (SensorVariance).
//
// Brackets: x = clip(e / full_well, 0, 1) through the response f (x -> [0, 1]) and quantised
// to `bits` levels; exposures t_i = t_mid·2^(stops·(i − (n−1)/2)).

#include <cstdint>
#include <vector>

#include "solver/synth/synth_options.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::synth {

class ResponseCurve {
 public:
  static ResponseCurve Gamma(double gamma);
  static ResponseCurve Sigmoid(double contrast, double mid);
  // An igi-response JSON (docs/file-formats.md): x(level) = exp(g(level) − g(levels−1)) per
  // channel; g must increase with the level. Throws InputError naming the file and key.
  static ResponseCurve FromFile(const std::filesystem::path& path);
  static ResponseCurve FromOptions(const BracketOptions& options);

  // Normalised exposure x in [0, 1] (1 = full well) -> encoded value in [0, 1].
  double Forward(double x, int channel) const;
  // Encoded value in [0, 1] -> normalised exposure.
  double Inverse(double v, int channel) const;
  // The curve as an igi-response JSON with `levels` levels: g(z) = ln Inverse(z/(levels−1))
  // (level 0 uses a quarter level, where ln 0 would be −∞).
  Json ToResponseJson(int levels) const;
  // Kind and parameters, for truth.json.
  Json Describe() const;

 private:
  ResponseKind kind_ = ResponseKind::kGamma;
  double gamma_ = 2.2, contrast_ = 1.6, mid_ = 0.18;
  std::vector<std::vector<double>> x_of_level_;  // kFile: per channel, increasing
  std::string file_;
};

// The exposure for `radiance` (linear RGB): options.exposure_s when > 0, else the one that puts
// the 99th percentile of the pixels' brightest channel at 80% of the full well.
double ChooseExposure(const Image& radiance, const SensorOptions& options);

struct SensorResult {
  Image photo;  // linear radiance units, RGB
  Image mask;   // 1 channel: 0 where a channel saturated, 1 elsewhere
  int64_t saturated_pixels = 0;
};

// One noisy exposure of `radiance` (linear RGB) at `exposure_s`; deterministic for `seed`.
SensorResult SimulateSensor(const Image& radiance, const SensorOptions& options, double exposure_s,
                            uint64_t seed, int num_threads = 0);

// Variance (radiance units²) of a photo pixel of true radiance L below saturation.
double SensorVariance(double radiance, const SensorOptions& options, double exposure_s);

struct Bracket {
  Image encoded;  // values in [0, 1]: level / (2^bits − 1)
  double exposure_s = 0;
};

// `brackets.count` LDR exposures of `radiance` centred on `mid_exposure_s`, with sensor noise
// when `noisy` (else only clipping and quantisation).
std::vector<Bracket> MakeBrackets(const Image& radiance, const SensorOptions& sensor,
                                  const BracketOptions& brackets, const ResponseCurve& response,
                                  double mid_exposure_s, bool noisy, uint64_t seed,
                                  int num_threads = 0);

}  // namespace igi::synth
