#include "calib/response_curve.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/common/error.h"

namespace igi::calib {

double ResponseCurve::LnExposure(int channel, double v) const {
  const std::vector<double>& curve = g[size_t(channel)];
  const double x = std::clamp(v, 0.0, 1.0) * double(levels - 1);
  const int k = std::min(int(x), levels - 2);
  const double a = x - k;
  return (1.0 - a) * curve[size_t(k)] + a * curve[size_t(k) + 1];
}

void ResponseCurve::NormaliseAtMiddle(int reference) {
  if (g.empty()) return;
  reference = std::clamp(reference, 0, num_channels() - 1);
  const double offset = g[size_t(reference)][size_t(levels / 2)];
  for (auto& curve : g) {
    for (double& value : curve) value -= offset;
  }
}

ResponseCurve LinearResponse(int levels, int channels) {
  ResponseCurve curve;
  curve.method = "linear";
  curve.levels = levels;
  curve.channels = DefaultChannelNames(channels);
  curve.g.assign(size_t(channels), std::vector<double>(static_cast<size_t>(levels)));
  for (auto& c : curve.g) {
    for (int z = 0; z < levels; ++z) {
      c[size_t(z)] = std::log(std::max(double(z), 0.5) / double(levels - 1));
    }
  }
  return curve;
}

std::vector<std::string> DefaultChannelNames(int channels) {
  switch (channels) {
    case 1:
      return {"Y"};
    case 2:
      return {"Y", "A"};
    case 3:
      return {"R", "G", "B"};
    case 4:
      return {"R", "G", "B", "A"};
    default:
      break;
  }
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c) names.push_back(fmt::format("C{}", c));
  return names;
}

Json ResponseToJson(const ResponseCurve& curve, const Json& info) {
  Json out;
  out["format"] = "igi-response";
  out["version"] = 1;
  out["method"] = curve.method;
  out["levels"] = curve.levels;
  out["channels"] = curve.channels;
  Json g = Json::array();
  for (const auto& channel : curve.g) {
    Json values = Json::array();
    for (double v : channel) values.push_back(std::round(v * 1e7) / 1e7);
    g.push_back(std::move(values));
  }
  out["g"] = std::move(g);
  if (!info.is_null()) out["info"] = info;
  return out;
}

void WriteResponseJson(const std::filesystem::path& path, const ResponseCurve& curve,
                       const Json& info) {
  WriteJsonFile(path, ResponseToJson(curve, info), 1);
}

ResponseCurve ResponseFromJson(const Json& document, const std::string& file) {
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(document, file, &problems);
  root.ExpectObject({"format", "version", "method", "levels", "channels", "g", "info"});
  if (const auto format = root["format"].String(); format && *format != "igi-response") {
    root["format"].Problem("must be \"igi-response\"");
  }
  if (const auto version = root["version"].Integer(); version && *version != 1) {
    root["version"].Problem("must be 1");
  }
  ResponseCurve curve;
  if (const auto method = root["method"].NonEmptyString()) curve.method = *method;
  const auto levels = root["levels"].Integer(NumberRule::Between(2, 1 << 20));
  const size_t num_channels = root["channels"].ArraySize(1);
  for (size_t c = 0; c < num_channels; ++c) {
    if (const auto name = root["channels"][c].NonEmptyString()) curve.channels.push_back(*name);
  }
  problems.ThrowIfAny();
  curve.levels = int(*levels);
  const JsonCursor g = root["g"];
  if (g.ArraySize() != num_channels) {
    g.Problem(fmt::format("must hold one curve per channel ({})", num_channels));
  }
  problems.ThrowIfAny();
  for (size_t c = 0; c < num_channels; ++c) {
    const auto values = g[c].Numbers(size_t(curve.levels));
    if (!values) continue;
    for (size_t z = 1; z < values->size(); ++z) {
      if ((*values)[z] < (*values)[z - 1]) {
        g[c][z].Problem("g must not decrease with the pixel level");
        break;
      }
    }
    curve.g.push_back(*values);
  }
  problems.ThrowIfAny();
  return curve;
}

ResponseCurve ReadResponseJson(const std::filesystem::path& path) {
  return ResponseFromJson(ReadJsonFile(path), path.string());
}

}  // namespace igi::calib
