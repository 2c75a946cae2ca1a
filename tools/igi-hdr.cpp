// igi-hdr: assembles exposure brackets into linear radiance maps (docs/file-formats.md,
// docs/memory.md).
//   igi-hdr IMAGES… --out radiance.exr [--response response.json] [--exposures LIST |
//           --exposure-file FILE] [--linear] [--weighting noise|hat] [--align] [--mask-out FILE]
//           [--camera camera.json] [--colour colour.json]   (the camera's vignetting divided
//           out, its colour matrix applied: igi-calib vignetting, igi-calib colour)
//   igi-hdr RAW_FILES… --out radiance.exr          (DNG, CR2, NEF, …: decoded linearly)
//   igi-hdr --manifest DIR/manifest.jsonl --out radiance.exr   (one output per bracket)
// Pixels saturated or black in every exposure are counted, printed and masked (mask: 0 = bad).
// 8/16-bit frames with a known response (--response, --linear, a manifest) are merged band by
// band (--band-rows rows of every frame in memory, hdr/merge_stream.h); raw files, a response
// recovered from the bracket and --whole-images load every frame whole.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "hdr/align.h"
#include "hdr/hdr_input.h"
#include "hdr/manifest.h"
#include "hdr/merge.h"
#include "hdr/merge_stream.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace {

namespace fs = std::filesystem;

struct Flags {
  std::vector<std::string> images;
  std::string manifest;
  std::string out;
  std::string mask_out;  // empty = OUT_mask.png
  std::string camera;    // camera.json whose vignetting is divided out; empty = none
  std::string colour;    // colour.json whose matrix takes camera RGB to linear sRGB; empty = none
  bool align = false;
  bool black_given = false;   // --black on the command line (else raw input uses 0)
  bool whole_images = false;  // load every frame whole instead of merging band by band
  igi::hdr::HdrInputOptions input;
  igi::hdr::MergeOptions merge;
  igi::hdr::HdrStreamOptions stream;
  // The choice flags as typed; Validate parses them into `merge` and `input.raw`.
  std::string weighting = "noise";
  std::string raw_white_balance = "camera";
  std::string raw_color = "srgb";
};

struct Job {
  fs::path out;
  igi::hdr::HdrInput input;
};

fs::path MaskPath(const fs::path& out, const std::string& mask_out, bool single) {
  if (!mask_out.empty() && single) return mask_out;
  fs::path mask = out;
  return mask.replace_filename(out.stem().string() + "_mask.png");
}

// The raw decode choices from their flags' text; InputError "--FLAG: VALUE: RULE" for each bad one.
igi::hdr::RawDecodeOptions ParseRawChoices(const Flags& flags) {
  igi::hdr::RawDecodeOptions raw = flags.input.raw;
  igi::ProblemList problems;
  if (const auto wb = igi::hdr::RawWhiteBalanceFromName(flags.raw_white_balance)) {
    raw.white_balance = *wb;
  } else {
    problems.Add("--raw-white-balance", "", flags.raw_white_balance, "must be camera or none");
  }
  if (const auto color = igi::hdr::RawColorFromName(flags.raw_color)) {
    raw.color = *color;
  } else {
    problems.Add("--raw-color", "", flags.raw_color, "must be srgb or raw");
  }
  problems.ThrowIfAny();
  return raw;
}

// Parses the choice flags into the options (--weighting was checked against noise|hat when the
// command line was parsed), then validates every option.
void Validate(Flags& flags) {
  flags.merge.weighting = igi::hdr::MergeWeightingFromName(flags.weighting).value();
  flags.merge.Validate();
  flags.input.raw = ParseRawChoices(flags);
  flags.input.raw.Validate();
  flags.stream.Validate();
  if (flags.images.empty() == flags.manifest.empty()) {
    throw igi::InputError("give either IMAGES or --manifest (exactly one of them)");
  }
  if (igi::ToLower(fs::path(flags.out).extension().string()) != ".exr") {
    throw igi::InputError(igi::DescribeProblem(flags.out, "--out",
                                               fs::path(flags.out).extension().string(),
                                               "radiance maps are written as OpenEXR (.exr)"));
  }
}

// Loads every bracket (all problems found before anything is written).
std::vector<Job> LoadJobs(const Flags& flags) {
  std::vector<Job> jobs;
  igi::hdr::HdrInputOptions options = flags.input;
  options.headers_only = !flags.whole_images;
  if (!flags.images.empty()) {
    std::vector<fs::path> paths(flags.images.begin(), flags.images.end());
    jobs.push_back({flags.out, igi::hdr::LoadHdrInput(paths, options)});
    return jobs;
  }
  const auto brackets = igi::hdr::ReadManifest(flags.manifest);
  options.linear = options.response.empty();  // machine-vision frames are linear
  igi::ProblemList problems;
  for (const auto& bracket : brackets) {
    std::vector<fs::path> paths;
    std::vector<double> exposures;
    for (const auto& frame : bracket.frames) {
      paths.push_back(frame.file);
      exposures.push_back(frame.exposure_s);
    }
    fs::path out = flags.out;
    if (brackets.size() > 1) {
      out.replace_filename(fs::path(flags.out).stem().string() + "_" + bracket.label + ".exr");
    }
    try {
      jobs.push_back({out, igi::hdr::LoadHdrInput(paths, options, exposures)});
    } catch (igi::Error& e) {
      problems.Append(e.AddContext("bracket " + bracket.label + " of " + flags.manifest));
    }
  }
  problems.ThrowIfAny();
  return jobs;
}

void PrintShifts(const igi::hdr::HdrInput& input, const std::vector<igi::hdr::PixelShift>& shifts) {
  for (size_t j = 0; j < shifts.size(); ++j) {
    if (shifts[j].dx == 0 && shifts[j].dy == 0) continue;
    std::printf("%s: aligned by (%d, %d) px\n", input.names[j].c_str(), shifts[j].dx, shifts[j].dy);
  }
}

void AlignJob(igi::hdr::HdrInput* input) {
  const auto shifts =
      igi::hdr::ComputeMtbShifts(input->images, igi::hdr::MedianExposureFrame(input->exposures_s));
  PrintShifts(*input, shifts);
  for (size_t j = 0; j < shifts.size(); ++j) {
    if (shifts[j].dx == 0 && shifts[j].dy == 0) continue;
    input->images[j] = igi::hdr::ShiftImage(input->images[j], shifts[j]);
  }
}

// What a merge found, for the summary line.
struct MergeCounts {
  int64_t pixels = 0;
  int64_t saturated = 0;
  int64_t black = 0;
};

MergeCounts MergeWhole(Job& job, const igi::hdr::MergeOptions& merge, const Flags& flags,
                       const igi::hdr::RadianceCorrection& correction, const fs::path& mask) {
  if (flags.align) AlignJob(&job.input);
  const igi::hdr::MergeResult result =
      igi::hdr::MergeBracket(job.input.images, job.input.exposures_s, job.input.response, merge);
  igi::Image radiance = result.radiance;
  correction.Apply(radiance.pixels.data(), 0, radiance.height, radiance.width, radiance.channels);
  radiance.metadata["igi:response"] = job.input.response_source;
  radiance.metadata["igi:weighting"] = std::string(igi::hdr::MergeWeightingName(merge.weighting));
  igi::WriteImage(job.out, radiance);
  igi::WriteImageOptions mask_options;
  mask_options.type = igi::PixelType::kUInt8;
  igi::WriteImage(mask, result.mask, mask_options);
  return {int64_t(result.radiance.width) * result.radiance.height, result.saturated_pixels,
          result.black_pixels};
}

MergeCounts MergeStreamed(const Job& job, const igi::hdr::MergeOptions& merge, const Flags& flags,
                          const igi::hdr::RadianceCorrection& correction, const fs::path& mask) {
  std::vector<igi::hdr::PixelShift> shifts;
  if (flags.align) {
    // Shifts from the frames' 8-bit grey levels (1 byte a pixel), applied while streaming.
    shifts = igi::hdr::ComputeMtbShifts(igi::hdr::ReadGreyFrames(job.input.paths, flags.stream),
                                        igi::hdr::MedianExposureFrame(job.input.exposures_s));
    PrintShifts(job.input, shifts);
  }
  igi::hdr::StreamOutputs outputs;
  outputs.radiance = job.out;
  outputs.radiance_metadata["igi:response"] = job.input.response_source;
  outputs.radiance_metadata["igi:weighting"] =
      std::string(igi::hdr::MergeWeightingName(merge.weighting));
  outputs.mask = mask;
  outputs.correction = correction;
  const igi::hdr::StreamMergeSummary summary =
      igi::hdr::MergeBracketStreamed(job.input.paths, job.input.exposures_s, shifts,
                                     job.input.response, merge, flags.stream, outputs);
  return {int64_t(summary.width) * summary.height, summary.saturated_pixels, summary.black_pixels};
}

int Run(Flags& flags) {
  Validate(flags);
  // The corrections are read first: a colour matrix fitted to raw camera RGB sets how raw
  // files are decoded.
  const igi::hdr::RadianceCorrection correction(flags.camera, flags.colour);
  flags.input.raw = correction.RawInputOptions(flags.input.raw);
  std::vector<Job> jobs = LoadJobs(flags);
  // Every bracket is checked before the first is written.
  for (const Job& job : jobs) {
    const fs::path& first = job.input.paths.front();
    if (job.input.headers_only) {
      const igi::ImageInfo info = igi::ReadImageInfo(first);
      correction.Check(first.string(), info.width, info.height, info.channels, job.input.raw);
    } else {
      const igi::Image& image = job.input.images[0];
      correction.Check(first.string(), image.width, image.height, image.channels, job.input.raw);
    }
  }
  for (Job& job : jobs) {
    igi::hdr::MergeOptions merge = flags.merge;
    merge.bits = job.input.bits;
    // Raw data has its black level subtracted: only a zero value carries no signal.
    if (job.input.raw && !flags.black_given) merge.black = 0.0;
    const fs::path mask = MaskPath(job.out, flags.mask_out, jobs.size() == 1);
    const MergeCounts counts = job.input.headers_only
                                   ? MergeStreamed(job, merge, flags, correction, mask)
                                   : MergeWhole(job, merge, flags, correction, mask);
    const double total = double(counts.pixels);
    std::printf(
        "%s: %d images, response %s, %s weights; saturated in every exposure: %lld px "
        "(%.3f %%), black in every exposure: %lld px (%.3f %%), masked in %s\n",
        job.out.string().c_str(), int(job.input.names.size()), job.input.response_source.c_str(),
        std::string(igi::hdr::MergeWeightingName(merge.weighting)).c_str(),
        (long long)counts.saturated, 100.0 * counts.saturated / total, (long long)counts.black,
        100.0 * counts.black / total, mask.string().c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("igi-hdr: merge exposure brackets into linear radiance maps (OpenEXR)", "igi-hdr");
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common);
  Flags flags;
  app.add_option("images", flags.images, "Images of one bracket (8/16-bit or raw files)");
  app.add_option("--manifest", flags.manifest, "igi-capture manifest.jsonl to merge");
  app.add_option("--out", flags.out, "Output radiance map (.exr)")->required();
  app.add_option("--response", flags.input.response, "response.json (igi-calib response)");
  auto* list = app.add_option("--exposures", flags.input.exposures.list,
                              "Exposure times in seconds, comma-separated (0.004 or 1/250)");
  app.add_option("--exposure-file", flags.input.exposures.file, "One exposure time per line")
      ->excludes(list);
  app.add_flag("--linear", flags.input.linear, "Non-raw input is linear (no response needed)");
  app.add_option("--weighting", flags.weighting, "noise (inverse variance) or hat")
      ->check(CLI::IsMember({"noise", "hat"}));
  app.add_option("--shot-noise", flags.merge.shot_noise, "Variance per unit signal (full scale 1)");
  app.add_option("--read-noise", flags.merge.read_noise, "Read noise std, full scale 1");
  CLI::Option* black =
      app.add_option("--black", flags.merge.black,
                     "Normalised level at or below which = black (default 0.02; raw: 0)");
  app.add_option("--saturated", flags.merge.saturated, "Normalised level at or above = saturated");
  app.add_flag("--align", flags.align, "Align hand-held brackets (median threshold bitmaps)");
  app.add_option("--mask-out", flags.mask_out, "Mask of bad pixels (default OUT_mask.png)");
  app.add_option("--camera", flags.camera,
                 "camera.json whose vignetting (igi-calib vignetting) is divided out");
  app.add_option("--colour", flags.colour,
                 "colour.json (igi-calib colour): camera RGB -> linear sRGB; with a matrix of raw "
                 "camera RGB, raw files are decoded without white balance or colour matrix");
  app.add_option("--raw-white-balance", flags.raw_white_balance, "camera or none");
  app.add_option("--raw-color", flags.raw_color, "srgb (linear) or raw (camera RGB)");
  app.add_flag("--half-size", flags.input.raw.half_size, "Raw: 2x2 binning, no demosaicing");
  app.add_option("--band-rows", flags.stream.band_rows,
                 "Rows of every frame held in memory when merging band by band (default 64)");
  app.add_flag("--whole-images", flags.whole_images,
               "Load every frame whole instead of merging band by band");
  return igi::RunMain(app, common, argc, argv, [&]() {
    flags.black_given = black->count() > 0;
    return Run(flags);
  });
}
