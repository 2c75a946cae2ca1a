#include "hdr/hdr_flags.h"

#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::hdr {

namespace fs = std::filesystem;

void AddHdrFlags(CLI::App& app, HdrFlags* flags) {
  app.add_option("--out", flags->out, "Output radiance map (.exr)");
  app.add_option("--response", flags->input.response, "response.json (igi-calib response)");
  CLI::Option* list =
      app.add_option("--exposures", flags->input.exposures.list,
                     "Exposure times in seconds, comma-separated (0.004 or 1/250)");
  app.add_option("--exposure-file", flags->input.exposures.file, "One exposure time per line")
      ->excludes(list);
  app.add_flag("--linear", flags->input.linear, "Non-raw input is linear (no response needed)");
  app.add_option("--weighting", flags->weighting, "noise (inverse variance) or hat");
  app.add_option("--shot-noise", flags->merge.shot_noise,
                 "Variance per unit signal (full scale 1)");
  app.add_option("--read-noise", flags->merge.read_noise, "Read noise std, full scale 1");
  app.add_option_function<double>(
      "--black", [flags](double black) { flags->black = black; },
      "Normalised level at or below which = black (default 0.02; raw: 0)");
  app.add_option("--saturated", flags->merge.saturated,
                 "Normalised level at or above = saturated");
  app.add_flag("--align", flags->align, "Align hand-held brackets (median threshold bitmaps)");
  app.add_option("--mask-out", flags->mask_out, "Mask of bad pixels (default OUT_mask.png)");
  app.add_option("--camera", flags->camera,
                 "camera.json whose vignetting (igi-calib vignetting) is divided out");
  app.add_option("--colour", flags->colour,
                 "colour.json (igi-calib colour): camera RGB -> linear sRGB; with a matrix of raw "
                 "camera RGB, raw files are decoded without white balance or colour matrix");
  app.add_option("--raw-white-balance", flags->raw_white_balance, "camera or none");
  app.add_option("--raw-color", flags->raw_color, "srgb (linear) or raw (camera RGB)");
  app.add_flag("--half-size", flags->input.raw.half_size, "Raw: 2x2 binning, no demosaicing");
  app.add_option("--band-rows", flags->stream.band_rows,
                 "Rows of every frame held in memory when merging band by band (default 64)");
  app.add_flag("--whole-images", flags->whole_images,
               "Load every frame whole instead of merging band by band");
}

RawDecodeOptions ParseRawChoices(const std::string& white_balance, const std::string& color,
                                 RawDecodeOptions raw) {
  ProblemList problems;
  if (const auto wb = RawWhiteBalanceFromName(white_balance)) {
    raw.white_balance = *wb;
  } else {
    problems.Add("--raw-white-balance", "", white_balance, "must be camera or none");
  }
  if (const auto c = RawColorFromName(color)) {
    raw.color = *c;
  } else {
    problems.Add("--raw-color", "", color, "must be srgb or raw");
  }
  problems.ThrowIfAny();
  raw.Validate();
  return raw;
}

void FinishHdrFlags(HdrFlags* flags) {
  const auto weighting = MergeWeightingFromName(flags->weighting);
  if (!weighting) {
    throw InputError(DescribeProblem("--weighting", "", flags->weighting, "must be noise or hat"));
  }
  flags->merge.weighting = *weighting;
  if (flags->black) flags->merge.black = *flags->black;
  flags->merge.Validate();
  flags->input.raw = ParseRawChoices(flags->raw_white_balance, flags->raw_color, flags->input.raw);
  flags->stream.Validate();
  const std::string extension = fs::path(flags->out).extension().string();
  if (!flags->out.empty() && ToLower(extension) != ".exr") {
    throw InputError(DescribeProblem(flags->out, "--out", extension,
                                     "radiance maps are written as OpenEXR (.exr)"));
  }
}

fs::path DefaultMaskPath(const fs::path& out) {
  fs::path mask = out;
  return mask.replace_filename(out.stem().string() + "_mask.png");
}

void CheckCorrection(const HdrInput& input, const RadianceCorrection& correction) {
  const std::string first = input.names.front();
  if (input.headers_only) {
    const ImageInfo info = ReadImageInfo(input.paths.front());
    correction.Check(first, info.width, info.height, info.channels, input.raw);
  } else {
    const Image& image = input.images.front();
    correction.Check(first, image.width, image.height, image.channels, input.raw);
  }
}

MergedBracket MergeHdrInput(HdrInput& input, const HdrFlags& flags,
                            const RadianceCorrection& correction, const fs::path& out,
                            const fs::path& mask) {
  MergeOptions merge = flags.merge;
  merge.bits = input.bits;
  if (input.raw && !flags.black) merge.black = 0.0;
  MergedBracket merged;
  merged.radiance_metadata["igi:response"] = input.response_source;
  merged.radiance_metadata["igi:weighting"] = std::string(MergeWeightingName(merge.weighting));
  const int reference = MedianExposureFrame(input.exposures_s);
  if (input.headers_only) {
    if (flags.align) {
      // Shifts from the frames' 8-bit grey levels (1 byte a pixel), applied while streaming.
      merged.shifts = ComputeMtbShifts(ReadGreyFrames(input.paths, flags.stream), reference);
    }
    StreamOutputs outputs;
    outputs.radiance = out;
    outputs.radiance_metadata = merged.radiance_metadata;
    outputs.mask = mask;
    outputs.correction = correction;
    const StreamMergeSummary summary =
        MergeBracketStreamed(input.paths, input.exposures_s, merged.shifts, input.response, merge,
                             flags.stream, outputs);
    merged.width = summary.width;
    merged.height = summary.height;
    merged.saturated_pixels = summary.saturated_pixels;
    merged.black_pixels = summary.black_pixels;
    return merged;
  }
  if (flags.align) {
    merged.shifts = ComputeMtbShifts(input.images, reference);
    for (size_t j = 0; j < merged.shifts.size(); ++j) {
      if (merged.shifts[j].dx == 0 && merged.shifts[j].dy == 0) continue;
      input.images[j] = ShiftImage(input.images[j], merged.shifts[j]);
    }
  }
  MergeResult result = MergeBracket(input.images, input.exposures_s, input.response, merge);
  correction.Apply(result.radiance.pixels.data(), 0, result.radiance.height,
                   result.radiance.width, result.radiance.channels);
  for (const auto& [key, value] : merged.radiance_metadata) result.radiance.metadata[key] = value;
  if (!out.empty()) WriteImage(out, result.radiance);
  if (!mask.empty()) {
    WriteImageOptions mask_options;
    mask_options.type = PixelType::kUInt8;
    WriteImage(mask, result.mask, mask_options);
  }
  merged.width = result.radiance.width;
  merged.height = result.radiance.height;
  merged.saturated_pixels = result.saturated_pixels;
  merged.black_pixels = result.black_pixels;
  merged.radiance = std::move(result.radiance);
  merged.mask = std::move(result.mask);
  return merged;
}

}  // namespace igi::hdr
