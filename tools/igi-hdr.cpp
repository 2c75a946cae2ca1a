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

#include "hdr/hdr_flags.h"
#include "hdr/manifest.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

namespace {

namespace fs = std::filesystem;

struct Job {
  fs::path out;
  igi::hdr::HdrInput input;
};

// Loads every bracket (all problems found before anything is written).
std::vector<Job> LoadJobs(const std::vector<std::string>& images, const std::string& manifest,
                          const igi::hdr::HdrFlags& flags) {
  std::vector<Job> jobs;
  igi::hdr::HdrInputOptions options = flags.input;
  options.headers_only = !flags.whole_images;
  if (!images.empty()) {
    std::vector<fs::path> paths(images.begin(), images.end());
    jobs.push_back({flags.out, igi::hdr::LoadHdrInput(paths, options)});
    return jobs;
  }
  const auto brackets = igi::hdr::ReadManifest(manifest);
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
      problems.Append(e.AddContext("bracket " + bracket.label + " of " + manifest));
    }
  }
  problems.ThrowIfAny();
  return jobs;
}

int Run(const std::vector<std::string>& images, const std::string& manifest,
        igi::hdr::HdrFlags& flags) {
  igi::hdr::FinishHdrFlags(&flags);
  if (images.empty() == manifest.empty()) {
    throw igi::InputError("give either IMAGES or --manifest (exactly one of them)");
  }
  // The corrections are read first: a colour matrix fitted to raw camera RGB sets how raw
  // files are decoded.
  const igi::hdr::RadianceCorrection correction(flags.camera, flags.colour);
  flags.input.raw = correction.RawInputOptions(flags.input.raw);
  std::vector<Job> jobs = LoadJobs(images, manifest, flags);
  // Every bracket is checked before the first is written.
  for (const Job& job : jobs) igi::hdr::CheckCorrection(job.input, correction);
  for (Job& job : jobs) {
    const fs::path mask = !flags.mask_out.empty() && jobs.size() == 1
                              ? fs::path(flags.mask_out)
                              : igi::hdr::DefaultMaskPath(job.out);
    const igi::hdr::MergedBracket merged =
        igi::hdr::MergeHdrInput(job.input, flags, correction, job.out, mask);
    for (size_t j = 0; j < merged.shifts.size(); ++j) {
      if (merged.shifts[j].dx == 0 && merged.shifts[j].dy == 0) continue;
      std::printf("%s: aligned by (%d, %d) px\n", job.input.names[j].c_str(), merged.shifts[j].dx,
                  merged.shifts[j].dy);
    }
    const double total = double(merged.width) * merged.height;
    std::printf(
        "%s: %d images, response %s, %s weights; saturated in every exposure: %lld px "
        "(%.3f %%), black in every exposure: %lld px (%.3f %%), masked in %s\n",
        job.out.string().c_str(), int(job.input.names.size()), job.input.response_source.c_str(),
        std::string(igi::hdr::MergeWeightingName(flags.merge.weighting)).c_str(),
        (long long)merged.saturated_pixels, 100.0 * merged.saturated_pixels / total,
        (long long)merged.black_pixels, 100.0 * merged.black_pixels / total,
        mask.string().c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("igi-hdr: merge exposure brackets into linear radiance maps (OpenEXR)", "igi-hdr");
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common);
  std::vector<std::string> images;
  std::string manifest;
  igi::hdr::HdrFlags flags;
  app.add_option("images", images, "Images of one bracket (8/16-bit or raw files)");
  app.add_option("--manifest", manifest, "igi-capture manifest.jsonl to merge");
  igi::hdr::AddHdrFlags(app, &flags);
  app.get_option("--out")->required();
  return igi::RunMain(app, common, argc, argv, [&]() { return Run(images, manifest, flags); });
}
