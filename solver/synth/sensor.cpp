#include "solver/synth/sensor.h"

#include <algorithm>
#include <cmath>

#include "solver/render/sampling.h"
#include "tools/common/error.h"
#include "tools/common/parallel.h"

namespace igi::synth {
namespace {

double Normal(render::Pcg32* rng) {
  const double u1 = rng->UniformDouble();
  const double u2 = rng->UniformDouble();
  return std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * render::kPi * u2);
}

// Poisson(mean) exactly for small means (Knuth), Gaussian N(mean, mean) from 30 on.
double Poisson(double mean, render::Pcg32* rng) {
  if (!(mean > 0)) return 0;
  if (mean >= 30) return mean + std::sqrt(mean) * Normal(rng);
  const double limit = std::exp(-mean);
  double p = 1;
  int k = -1;
  do {
    ++k;
    p *= rng->UniformDouble();
  } while (p > limit);
  return k;
}

double Gain(const SensorOptions& o) {
  return o.full_well_e / (double((1 << o.adc_bits) - 1) - o.black_level_dn);
}

// Electrons of one pixel channel: shot and read noise, clipped at the full well.
double NoisyElectrons(double mean_e, double read_noise_e, render::Pcg32* rng) {
  return Poisson(std::max(mean_e, 0.0), rng) + read_noise_e * Normal(rng);
}

}  // namespace

ResponseCurve ResponseCurve::Gamma(double gamma) {
  ResponseCurve r;
  r.kind_ = ResponseKind::kGamma;
  r.gamma_ = gamma;
  return r;
}

ResponseCurve ResponseCurve::Sigmoid(double contrast, double mid) {
  ResponseCurve r;
  r.kind_ = ResponseKind::kSigmoid;
  r.contrast_ = contrast;
  r.mid_ = mid;
  return r;
}

ResponseCurve ResponseCurve::FromFile(const std::filesystem::path& path) {
  const Json doc = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(doc, path.string(), &problems);
  if (auto format = root["format"].String(); format && *format != "igi-response") {
    root["format"].Problem("must be \"igi-response\"");
  }
  const auto levels = root["levels"].Integer(NumberRule::Between(4, 65536));
  const size_t channels = root["g"].ArraySize(1);
  ResponseCurve r;
  r.kind_ = ResponseKind::kFile;
  r.file_ = path.string();
  for (size_t c = 0; c < channels && levels; ++c) {
    auto g = root["g"][c].Numbers(size_t(*levels));
    if (!g) continue;
    std::vector<double> x(g->size());
    for (size_t z = 0; z < g->size(); ++z) {
      x[z] = std::exp((*g)[z] - g->back());
      if (z > 0 && !((*g)[z] > (*g)[z - 1])) {
        root["g"][c][z].Problem("g must increase with the pixel level");
        break;
      }
    }
    r.x_of_level_.push_back(std::move(x));
  }
  problems.ThrowIfAny();
  return r;
}

ResponseCurve ResponseCurve::FromOptions(const BracketOptions& o) {
  switch (o.response) {
    case ResponseKind::kGamma:
      return Gamma(o.gamma);
    case ResponseKind::kSigmoid:
      return Sigmoid(o.sigmoid_contrast, o.sigmoid_mid);
    case ResponseKind::kFile:
      return FromFile(o.response_file);
  }
  return Gamma(o.gamma);
}

double ResponseCurve::Forward(double x, int channel) const {
  x = std::clamp(x, 0.0, 1.0);
  switch (kind_) {
    case ResponseKind::kGamma:
      return std::pow(x, 1.0 / gamma_);
    case ResponseKind::kSigmoid: {
      auto s = [&](double v) {
        const double vc = std::pow(v, contrast_);
        return vc / (vc + std::pow(mid_, contrast_));
      };
      return s(x) / s(1.0);
    }
    case ResponseKind::kFile: {
      const auto& t = x_of_level_[std::min<size_t>(channel, x_of_level_.size() - 1)];
      if (x <= t.front()) return 0.0;
      const size_t hi = std::lower_bound(t.begin(), t.end(), x) - t.begin();
      if (hi >= t.size()) return 1.0;
      const double frac = (x - t[hi - 1]) / (t[hi] - t[hi - 1]);
      return (double(hi - 1) + frac) / double(t.size() - 1);
    }
  }
  return x;
}

double ResponseCurve::Inverse(double v, int channel) const {
  v = std::clamp(v, 0.0, 1.0);
  switch (kind_) {
    case ResponseKind::kGamma:
      return std::pow(v, gamma_);
    case ResponseKind::kSigmoid: {
      // v·s(1) = x^c/(x^c + m^c)  =>  x^c = m^c·w/(1 − w), w = v·s(1).
      const double mc = std::pow(mid_, contrast_);
      const double w = v / (1.0 + mc);
      return std::pow(mc * w / (1.0 - w), 1.0 / contrast_);
    }
    case ResponseKind::kFile: {
      const auto& t = x_of_level_[std::min<size_t>(channel, x_of_level_.size() - 1)];
      const double pos = v * double(t.size() - 1);
      const size_t lo = std::min(size_t(pos), t.size() - 2);
      const double frac = pos - double(lo);
      return t[lo] + frac * (t[lo + 1] - t[lo]);
    }
  }
  return v;
}

Json ResponseCurve::ToResponseJson(int levels) const {
  Json g = Json::array();
  const int channels = kind_ == ResponseKind::kFile ? int(x_of_level_.size()) : 3;
  for (int c = 0; c < 3; ++c) {
    Json row = Json::array();
    for (int z = 0; z < levels; ++z) {
      const double level = z == 0 ? 0.25 : double(z);
      row.push_back(std::log(Inverse(level / double(levels - 1), std::min(c, channels - 1))));
    }
    g.push_back(std::move(row));
  }
  return Json{{"format", "igi-response"},
              {"version", 1},
              {"method", "igi-synth truth"},
              {"levels", levels},
              {"channels", Json::array({"R", "G", "B"})},
              {"g", std::move(g)}};
}

Json ResponseCurve::Describe() const {
  switch (kind_) {
    case ResponseKind::kGamma:
      return Json{{"kind", "gamma"}, {"gamma", gamma_}, {"formula", "v = x^(1/gamma)"}};
    case ResponseKind::kSigmoid:
      return Json{{"kind", "sigmoid"},
                  {"contrast", contrast_},
                  {"mid", mid_},
                  {"formula", "v = s(x)/s(1), s(x) = x^c/(x^c + mid^c)"}};
    case ResponseKind::kFile:
      return Json{{"kind", "file"}, {"file", file_}};
  }
  return Json::object();
}

double ChooseExposure(const Image& radiance, const SensorOptions& options) {
  if (options.exposure_s > 0) return options.exposure_s;
  std::vector<float> brightest(size_t(radiance.width) * radiance.height);
  for (size_t i = 0; i < brightest.size(); ++i) {
    float m = 0;
    for (int c = 0; c < std::min(radiance.channels, 3); ++c) {
      m = std::max(m, radiance.pixels[i * radiance.channels + c]);
    }
    brightest[i] = m;
  }
  const size_t k = size_t(0.99 * double(brightest.size() - 1));
  std::nth_element(brightest.begin(), brightest.begin() + k, brightest.end());
  const double p99 = std::max<double>(brightest[k], 1e-12);
  return 0.8 * options.full_well_e / (options.electrons_per_radiance_s * p99);
}

SensorResult SimulateSensor(const Image& radiance, const SensorOptions& o, double exposure_s,
                            uint64_t seed, int num_threads) {
  SensorResult out;
  out.photo = Image(radiance.width, radiance.height, 3);
  out.photo.metadata = radiance.metadata;
  out.mask = Image(radiance.width, radiance.height, 1, 1.0f);
  const double kt = o.electrons_per_radiance_s * exposure_s;
  const double gain = Gain(o);
  const double max_dn = double((1 << o.adc_bits) - 1);
  std::vector<int64_t> saturated_rows(radiance.height, 0);
  ParallelFor(
      0, radiance.height,
      [&](int64_t y) {
        for (int x = 0; x < radiance.width; ++x) {
          const uint64_t pixel = uint64_t(y) * radiance.width + x;
          render::Pcg32 rng = render::PixelSampleRng(seed, pixel, 0x5e5);
          bool saturated = false;
          for (int c = 0; c < 3; ++c) {
            const double l = radiance.at(x, int(y), std::min(c, radiance.channels - 1));
            double e = NoisyElectrons(l * kt, o.read_noise_e, &rng);
            if (e >= o.full_well_e) {
              e = o.full_well_e;
              saturated = true;
            }
            const double dn = std::clamp(std::round(e / gain) + o.black_level_dn, 0.0, max_dn);
            out.photo.at(x, int(y), c) = float((dn - o.black_level_dn) * gain / kt);
          }
          if (saturated) {
            out.mask.at(x, int(y)) = 0.0f;
            ++saturated_rows[y];
          }
        }
      },
      num_threads);
  for (int64_t s : saturated_rows) out.saturated_pixels += s;
  return out;
}

double SensorVariance(double radiance, const SensorOptions& o, double exposure_s) {
  const double kt = o.electrons_per_radiance_s * exposure_s;
  const double gain = Gain(o);
  return (radiance * kt + o.read_noise_e * o.read_noise_e + gain * gain / 12.0) / (kt * kt);
}

std::vector<Bracket> MakeBrackets(const Image& radiance, const SensorOptions& sensor,
                                  const BracketOptions& b, const ResponseCurve& response,
                                  double mid_exposure_s, bool noisy, uint64_t seed,
                                  int num_threads) {
  std::vector<Bracket> out;
  const double levels = b.bits == 8 ? 255.0 : 65535.0;
  for (int i = 0; i < b.count; ++i) {
    Bracket br;
    br.exposure_s = mid_exposure_s * std::exp2(b.stops * (i - 0.5 * (b.count - 1)));
    br.encoded = Image(radiance.width, radiance.height, 3);
    const double kt = sensor.electrons_per_radiance_s * br.exposure_s;
    ParallelFor(
        0, radiance.height,
        [&](int64_t y) {
          for (int x = 0; x < radiance.width; ++x) {
            render::Pcg32 rng =
                render::PixelSampleRng(seed, uint64_t(y) * radiance.width + x, 0xb0 + i);
            for (int c = 0; c < 3; ++c) {
              const double mean = radiance.at(x, int(y), std::min(c, radiance.channels - 1)) * kt;
              const double e = noisy ? NoisyElectrons(mean, sensor.read_noise_e, &rng) : mean;
              const double v = response.Forward(e / sensor.full_well_e, c);
              br.encoded.at(x, int(y), c) = float(std::round(v * levels) / levels);
            }
          }
        },
        num_threads);
    out.push_back(std::move(br));
  }
  return out;
}

}  // namespace igi::synth
