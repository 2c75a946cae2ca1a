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

// calib::LoadBracket's checks on the files' headers, without reading their pixels; `channels`
// gets the frames' channel count.
calib::Bracket LoadBracketHeaders(const std::vector<std::filesystem::path>& paths,
                                  const calib::ExposureSource& source, int* channels) {
  calib::Bracket bracket;
  if (paths.size() < 2) {
    throw InputError(DescribeProblem(paths.empty() ? "" : paths[0].string(), "images",
                                     fmt::format("{}", paths.size()),
                                     "a bracket needs at least 2 images"));
  }
  ProblemList problems;
  std::vector<ImageMetadata> metadata;
  std::vector<ImageInfo> infos;
  for (const auto& path : paths) {
    const std::string name = path.string();
    bracket.names.push_back(name);
    try {
      const ImageInfo info = ReadImageInfo(path);
      const int bits = info.type == PixelType::kUInt8    ? 8
                       : info.type == PixelType::kUInt16 ? 16
                                                         : 0;
      if (bits == 0) {
        problems.Add(name, "pixel type", fmt::format("{} bits", info.bits_per_sample),
                     "bracket images must be 8- or 16-bit integer levels");
        continue;
      }
      if (infos.empty()) bracket.bits_per_sample = bits;
      if (bits != bracket.bits_per_sample) {
        problems.Add(
            name, "pixel type", fmt::format("{} bits", bits),
            fmt::format("must match {} ({} bits)", bracket.names[0], bracket.bits_per_sample));
        continue;
      }
      metadata.push_back(info.metadata);
      infos.push_back(info);
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  for (size_t i = 1; i < infos.size(); ++i) {
    if (infos[i].width != infos[0].width || infos[i].height != infos[0].height ||
        infos[i].channels != infos[0].channels) {
      problems.Add(
          bracket.names[i], "size",
          fmt::format("{}x{}x{}", infos[i].width, infos[i].height, infos[i].channels),
          fmt::format("every image of a bracket must have the size of {} ({}x{}x{})",
                      bracket.names[0], infos[0].width, infos[0].height, infos[0].channels));
    }
  }
  problems.ThrowIfAny();
  bracket.exposures_s = calib::ResolveExposures(source, bracket.names, metadata);
  *channels = infos[0].channels;
  return bracket;
}

}  // namespace

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
  const bool headers_only = options.headers_only && (!options.response.empty() || options.linear);
  int channels = 0;
  calib::Bracket bracket = headers_only ? LoadBracketHeaders(paths, source, &channels)
                                        : calib::LoadBracket(paths, source);
  if (!headers_only) channels = bracket.channels();
  HdrInput input;
  input.paths = paths;
  input.headers_only = headers_only;
  input.bits = bracket.bits_per_sample;
  input.names = bracket.names;
  input.exposures_s = bracket.exposures_s;
  if (!options.response.empty()) {
    input.response = calib::ReadResponseJson(options.response);
    input.response_source = options.response.string();
    if (input.response.num_channels() != 1 && input.response.num_channels() != channels) {
      throw InputError(DescribeProblem(
          options.response.string(), "channels", fmt::format("{}", input.response.num_channels()),
          fmt::format("must be 1 or the images' channel count ({})", channels)));
    }
  } else if (options.linear) {
    input.response = calib::LinearResponse(bracket.levels(), channels);
    input.response_source = "linear";
  } else {
    spdlog::info("no --response: recovering a Debevec response from the bracket itself");
    input.response = calib::RecoverResponse(bracket, {}).curve;
    input.response_source = "recovered (debevec)";
  }
  input.images = std::move(bracket.images);
  return input;
}

}  // namespace igi::hdr
