#include "solver/inverse/measured_brdf.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "solver/render/brdf.h"
#include "tools/common/error.h"

namespace igi::solver {
namespace {

Eigen::Vector3d Direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// The band of a wavelength: 0 = R [600, 700], 1 = G [500, 600), 2 = B [400, 500); -1 outside.
int Band(double nm) {
  if (nm >= 600 && nm <= 700) return 0;
  if (nm >= 500 && nm < 600) return 1;
  if (nm >= 400 && nm < 500) return 2;
  return -1;
}

double RelativeRms(double err2, double norm2) { return norm2 > 0 ? std::sqrt(err2 / norm2) : 0; }

}  // namespace

MeasuredBrdf ReadCornellBrdf(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(DescribeProblem(file.string(), "", "", "cannot be read"));
  MeasuredBrdf out;
  out.file = file;
  auto fail = [&](int line, const std::string& value, const std::string& rule) {
    throw InputError(DescribeProblem(file.string(), fmt::format("line {}", line), value, rule));
  };
  int count = -1, line_no = 0;
  std::vector<int> bands;
  std::string line;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) {
        fail(line_no, token, "not a finite number");
      }
      values.push_back(v);
    }
    if (count < 0) {
      if (values.size() != 1 || values[0] < 1 || values[0] != std::floor(values[0])) {
        fail(line_no, line, "the first value must be the number of wavelengths (an integer >= 1)");
      }
      count = int(values[0]);
      continue;
    }
    if (int(out.wavelengths_nm.size()) < count) {
      for (double v : values) {
        if (int(out.wavelengths_nm.size()) == count)
          fail(line_no, line, "more wavelengths than given");
        if (Band(v) < 0) fail(line_no, fmt::format("{}", v), "wavelength outside [400, 700] nm");
        out.wavelengths_nm.push_back(v);
        bands.push_back(Band(v));
      }
      continue;
    }
    if (int(values.size()) != 4 + count) {
      fail(line_no, fmt::format("{} values", values.size()),
           fmt::format("a row is θi φi θs φs and {} BRDF values", count));
    }
    if (!(values[0] >= 0 && values[0] < M_PI / 2) || !(values[2] >= 0 && values[2] < M_PI / 2)) {
      fail(line_no, fmt::format("θi {} θs {}", values[0], values[2]),
           "elevations must be in [0, π/2) (above the surface)");
    }
    MeasuredBrdfSample s;
    s.wi = Direction(values[0], values[1]);
    s.wo = Direction(values[2], values[3]);
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (int k = 0; k < count; ++k) {
      const double v = values[4 + k];
      if (v < 0) fail(line_no, fmt::format("{}", v), "BRDF values must be >= 0");
      s.f[bands[k]] += v, n[bands[k]] += 1;
    }
    for (int c = 0; c < 3; ++c) {
      if (n[c] == 0) fail(line_no, "", "no wavelength in one of the R, G, B bands");
      s.f[c] /= n[c];
    }
    out.samples.push_back(s);
  }
  if (out.samples.empty()) fail(line_no, "", "no measurement rows");
  return out;
}

MeasuredFit FitMeasuredBrdf(const MeasuredBrdf& measured, recon::BrdfModel model, double ior) {
  RegionFitInput input;
  input.name = measured.file.stem().string();
  input.model = model;
  input.ior = ior;
  input.slot_area = {1.0};
  input.incident.reserve(measured.samples.size());
  for (const MeasuredBrdfSample& m : measured.samples) {
    const double e = m.wi.z();
    input.incident.emplace_back(m.wi.cast<float>(), Eigen::Vector3f::Constant(float(e)));
    FitSample s;
    s.observed = m.f * e;
    s.irradiance = Eigen::Vector3d::Constant(e);
    s.wo = m.wo.cast<float>();
    s.incident = &input.incident.back();
    s.incident_count = 1;
    input.samples.push_back(s);
  }
  MeasuredFit out;
  out.model = model;
  out.fit = FitRegion(input, RegionFitOptions{});

  render::BrdfParams params;
  params.model = model;
  params.rho_d = out.fit.rho_d;
  params.rho_s = out.fit.rho_s;
  params.alpha = params.alpha_x = params.alpha_y = out.fit.alpha;
  params.ior = ior;
  const double grazing_cos = std::cos(kGrazingDeg * M_PI / 180);
  double err[3] = {0, 0, 0}, norm[3] = {0, 0, 0};  // all, near, grazing
  for (const MeasuredBrdfSample& m : measured.samples) {
    const double w = m.wi.z() * m.wo.z();
    const Eigen::Vector3d d = (render::EvalBrdf(params, m.wo, m.wi) - m.f) * w;
    const double e2 = d.squaredNorm(), n2 = (m.f * w).squaredNorm();
    const bool grazing = m.wi.z() <= grazing_cos || m.wo.z() <= grazing_cos;
    const int part = grazing ? 2 : 1;
    err[0] += e2, norm[0] += n2, err[part] += e2, norm[part] += n2;
    ++(grazing ? out.rows_grazing : out.rows_near);
  }
  out.error_all = RelativeRms(err[0], norm[0]);
  out.error_near = RelativeRms(err[1], norm[1]);
  out.error_grazing = RelativeRms(err[2], norm[2]);
  return out;
}

}  // namespace igi::solver
