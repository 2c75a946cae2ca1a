#include "hdr/hdr_input.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "calib/exposure_times.h"
#include "calib/response_recovery.h"
#include "tools/common/error.h"

namespace igi::hdr {
namespace {

HdrInput LoadRaw(const std::vector<std::filesystem::path>& paths, const HdrInputOptions& options,
                 const std::vector<double>& exposures_s) {
  HdrInput input;
  input.paths = paths;
  input.raw = true;
  input.bits = 16;
  ProblemList problems;
  std::vector<ImageMetadata> metadata;
  std::vector<double> iso;
  for (const auto& path : paths) {
    input.names.push_back(path.string());
    try {
      RawImage raw = DecodeRaw(path, options.raw);
      iso.push_back(raw.iso);
      metadata.push_back(raw.image.metadata);
      input.images.push_back(std::move(raw.image));
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  calib::CheckSameShape(input.images, input.names);
  if (!exposures_s.empty()) {
    input.exposures_s = exposures_s;
    calib::ValidateExposures(input.exposures_s, input.names, "manifest");
  } else {
    input.exposures_s = calib::ResolveExposures(options.exposures, input.names, metadata);
  }
  // Frames at another ISO collect proportionally more signal per second of exposure.
  for (size_t j = 0; j < iso.size(); ++j) {
    if (iso[j] > 0 && iso[0] > 0 && iso[j] != iso[0]) {
      spdlog::info("{}: ISO {} vs {}: exposure scaled by {}", input.names[j], iso[j], iso[0],
                   iso[j] / iso[0]);
      input.exposures_s[j] *= iso[j] / iso[0];
    }
  }
  input.response = calib::LinearResponse(1 << 16, 3);
  input.response_source = "raw (linear)";
  return input;
}

// The response of a non-raw bracket with `channels` channels: response.json, the curve given,
// linear, or recovered from the bracket's pixels (which must then be loaded).
void ChooseResponse(const calib::Bracket& bracket, int channels, const HdrInputOptions& options,
                    HdrInput* input) {
  if (!options.response.empty() || options.curve) {
    input->response = options.curve ? *options.curve : calib::ReadResponseJson(options.response);
    input->response_source = options.curve ? options.curve_source : options.response.string();
    if (input->response.num_channels() != 1 && input->response.num_channels() != channels) {
      throw InputError(DescribeProblem(
          input->response_source, "channels", fmt::format("{}", input->response.num_channels()),
          fmt::format("must be 1 or the images' channel count ({})", channels)));
    }
  } else if (options.linear) {
    input->response = calib::LinearResponse(bracket.levels(), channels);
    input->response_source = "linear";
  } else {
    spdlog::info("no --response: recovering a Debevec response from the bracket itself");
    input->response = calib::RecoverResponse(bracket, {}).curve;
    input->response_source = "recovered (debevec)";
  }
}

}  // namespace

HdrInput HdrInputFromBracket(calib::Bracket bracket, const HdrInputOptions& options) {
  HdrInput input;
  input.names = bracket.names;
  input.exposures_s = bracket.exposures_s;
  input.bits = bracket.bits_per_sample;
  ChooseResponse(bracket, bracket.channels(), options, &input);
  input.images = std::move(bracket.images);
  return input;
}

HdrInput LoadHdrInput(const std::vector<std::filesystem::path>& paths,
                      const HdrInputOptions& options, const std::vector<double>& exposures_s) {
  size_t raw_count = 0;
  for (const auto& path : paths) raw_count += IsRawFile(path) ? 1 : 0;
  if (raw_count == paths.size() && !paths.empty()) return LoadRaw(paths, options, exposures_s);
  if (raw_count > 0) {
    for (const auto& path : paths) {
      if (IsRawFile(path)) {
        throw InputError(DescribeProblem(path.string(), "format", "raw",
                                         "a bracket must be all raw files or all images"));
      }
    }
  }
  calib::ExposureSource source = options.exposures;
  if (!exposures_s.empty()) {
    source = {};
    for (double t : exposures_s) source.list += fmt::format("{:.17g},", t);
  }
  // Recovering a response samples the whole images: only a known response leaves them unread.
  const bool headers_only =
      options.headers_only && (!options.response.empty() || options.curve || options.linear);
  int channels = 0;
  calib::Bracket bracket = headers_only ? calib::LoadBracketHeaders(paths, source, &channels)
                                        : calib::LoadBracket(paths, source);
  if (!headers_only) channels = bracket.channels();
  HdrInput input;
  input.paths = paths;
  input.headers_only = headers_only;
  input.bits = bracket.bits_per_sample;
  input.names = bracket.names;
  input.exposures_s = bracket.exposures_s;
  ChooseResponse(bracket, channels, options, &input);
  input.images = std::move(bracket.images);
  return input;
}

}  // namespace igi::hdr
