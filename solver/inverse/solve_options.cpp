#include "solver/inverse/solve_options.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"

namespace igi::solver {
namespace {

// The text of a choice's problem, or nullopt when the choice is valid: with `typed` (the flag's
// text), that text when it names no value; else the number of a value outside the enum.
template <typename E>
std::optional<std::string> BadChoice(E value, std::string_view (*name)(E),
                                     std::optional<E> (*from_name)(std::string_view),
                                     const std::string* typed) {
  if (typed) return from_name(*typed) ? std::nullopt : std::optional<std::string>(*typed);
  if (from_name(name(value))) return std::nullopt;
  return std::to_string(int(value));
}

constexpr EnumNames<SpecularColour, 2> kSpecularColourNames{
    {{SpecularColour::kGrey, "grey"}, {SpecularColour::kRgb, "rgb"}}};
constexpr EnumNames<AlbedoMaps, 3> kAlbedoMapsNames{
    {{AlbedoMaps::kAuto, "auto"}, {AlbedoMaps::kAll, "all"}, {AlbedoMaps::kNone, "none"}}};
constexpr EnumNames<AlbedoMapPass, 3> kAlbedoMapPassNames{{{AlbedoMapPass::kAuto, "auto"},
                                                           {AlbedoMapPass::kAlways, "always"},
                                                           {AlbedoMapPass::kNever, "never"}}};
constexpr EnumNames<RefineUpdate, 3> kRefineUpdateNames{
    {{RefineUpdate::kIndependent, "independent"},
     {RefineUpdate::kJoint, "joint"},
     {RefineUpdate::kJointAlbedo, "joint_albedo"}}};
constexpr EnumNames<PhotoScaleMode, 2> kPhotoScaleModeNames{
    {{PhotoScaleMode::kGiven, "given"}, {PhotoScaleMode::kSolve, "solve"}}};

}  // namespace

std::string_view SpecularColourName(SpecularColour colour) {
  return kSpecularColourNames.Name(colour);
}
std::optional<SpecularColour> SpecularColourFromName(std::string_view name) {
  return kSpecularColourNames.FromName(name);
}
std::string_view AlbedoMapsName(AlbedoMaps maps) { return kAlbedoMapsNames.Name(maps); }
std::optional<AlbedoMaps> AlbedoMapsFromName(std::string_view name) {
  return kAlbedoMapsNames.FromName(name);
}
std::string_view AlbedoMapPassName(AlbedoMapPass pass) { return kAlbedoMapPassNames.Name(pass); }
std::optional<AlbedoMapPass> AlbedoMapPassFromName(std::string_view name) {
  return kAlbedoMapPassNames.FromName(name);
}
std::string_view RefineUpdateName(RefineUpdate update) { return kRefineUpdateNames.Name(update); }
std::optional<RefineUpdate> RefineUpdateFromName(std::string_view name) {
  return kRefineUpdateNames.FromName(name);
}
std::string_view PhotoScaleModeName(PhotoScaleMode mode) { return kPhotoScaleModeNames.Name(mode); }
std::optional<PhotoScaleMode> PhotoScaleModeFromName(std::string_view name) {
  return kPhotoScaleModeNames.FromName(name);
}

int FinalRoundRays(int refine_final_rays, int observations) {
  const double scale = double(kFinalRoundRegionObservations) / std::max(1, observations);
  const double rays = refine_final_rays * std::clamp(scale, 1.0, 8.0);
  return int(std::min(4096.0, std::ceil(rays)));
}

namespace {

// Every problem of `o`; with `typed`, each choice is judged by its flag's text.
ProblemList Problems(const SolveOptions& o, const SolveChoiceFlags* typed) {
  ProblemList problems;
  auto check = [&](bool ok, const char* flag, const std::string& value, const char* rule) {
    if (!ok) problems.Add(DescribeProblem("", flag, value, rule));
  };
  // A choice's problem text (BadChoice), if any.
  auto choice = [&](const std::optional<std::string>& bad, const char* flag, const char* rule) {
    if (bad) problems.Add(DescribeProblem("", flag, *bad, rule));
  };
  check(o.pixel_stride >= 1 && o.pixel_stride <= 64, "--pixel-stride",
        std::to_string(o.pixel_stride), "must be in [1, 64]");
  check(o.memory_budget >= 0, "--memory-budget", fmt::format("{}", o.memory_budget),
        "must be >= 0 GiB (0 = the machine's memory less a margin)");
  check(o.max_observations >= 0, "--max-observations", std::to_string(o.max_observations),
        "must be >= 0 (0 = as many as the memory budget allows)");
  check(o.max_observation_block >= 1 && o.max_observation_block <= 64, "--max-observation-block",
        std::to_string(o.max_observation_block), "must be in [1, 64]");
  check(o.saturation >= 0, "--saturation", fmt::format("{}", o.saturation),
        "must be >= 0 (0 = auto)");
  check(o.patch_size_m >= 0, "--patch-size-m", fmt::format("{}", o.patch_size_m),
        "must be >= 0 (0 = auto)");
  check(o.light_samples >= 1 && o.light_samples <= 1024, "--light-samples",
        std::to_string(o.light_samples), "must be in [1, 1024]");
  check(o.indirect_rays >= 0 && o.indirect_rays <= 4096, "--indirect-rays",
        std::to_string(o.indirect_rays), "must be in [0, 4096]");
  check(o.smoothing_radius_m >= 0, "--smoothing-radius-m", fmt::format("{}", o.smoothing_radius_m),
        "must be >= 0 (0 = auto)");
  check(o.smoothing_accuracy >= 0 && o.smoothing_accuracy <= 10, "--smoothing-accuracy",
        fmt::format("{}", o.smoothing_accuracy), "must be in [0, 10] (0 = a fixed radius)");
  check(o.max_iterations >= 1 && o.max_iterations <= 100, "--max-iterations",
        std::to_string(o.max_iterations), "must be in [1, 100]");
  check(o.tolerance > 0 && o.tolerance < 1, "--tolerance", fmt::format("{}", o.tolerance),
        "must be in (0, 1)");
  choice(BadChoice(o.specular_colour, SpecularColourName, SpecularColourFromName,
                   typed ? &typed->specular_colour : nullptr),
         "--specular-colour", "must be grey or rgb");
  choice(BadChoice(o.albedo_maps, AlbedoMapsName, AlbedoMapsFromName,
                   typed ? &typed->albedo_maps : nullptr),
         "--albedo-maps", "must be auto, all or none");
  choice(BadChoice(o.albedo_map_pass, AlbedoMapPassName, AlbedoMapPassFromName,
                   typed ? &typed->albedo_map_pass : nullptr),
         "--albedo-map-pass", "must be auto, always or never");
  check(o.texel_size_m >= 0, "--texel-size-m", fmt::format("{}", o.texel_size_m),
        "must be >= 0 (0 = auto)");
  check(o.max_highlight_samples >= 1, "--max-highlight-samples",
        std::to_string(o.max_highlight_samples), "must be >= 1");
  check(o.max_fit_samples >= 3, "--max-fit-samples", std::to_string(o.max_fit_samples),
        "must be >= 3");
  check(o.refine_iterations >= 0 && o.refine_iterations <= 20, "--refine-iterations",
        std::to_string(o.refine_iterations), "must be in [0, 20]");
  check(o.refine_rays >= 1 && o.refine_rays <= 4096, "--refine-rays", std::to_string(o.refine_rays),
        "must be in [1, 4096]");
  check(o.refine_final_rays >= 1 && o.refine_final_rays <= 4096, "--refine-final-rays",
        std::to_string(o.refine_final_rays), "must be in [1, 4096]");
  check(o.refine_albedo_step > 0 && o.refine_albedo_step <= 1, "--refine-albedo-step",
        std::to_string(o.refine_albedo_step), "must be in (0, 1]");
  choice(BadChoice(o.refine_update, RefineUpdateName, RefineUpdateFromName,
                   typed ? &typed->refine_update : nullptr),
         "--refine-update", "must be joint, joint_albedo or independent");
  choice(BadChoice(o.photo_scale, PhotoScaleModeName, PhotoScaleModeFromName,
                   typed ? &typed->photo_scale : nullptr),
         "--photo-scale", "must be given or solve");
  check(o.holdout_fraction >= 0 && o.holdout_fraction < 1, "--holdout-fraction",
        fmt::format("{}", o.holdout_fraction), "must be in [0, 1)");
  check(o.holdout_block_px >= 1, "--holdout-block-px", std::to_string(o.holdout_block_px),
        "must be >= 1");
  return problems;
}

}  // namespace

void SolveOptions::Validate() const { Problems(*this, nullptr).ThrowIfAny(); }

void SolveOptions::SetChoices(const SolveChoiceFlags& flags) {
  if (auto v = SpecularColourFromName(flags.specular_colour)) specular_colour = *v;
  if (auto v = AlbedoMapsFromName(flags.albedo_maps)) albedo_maps = *v;
  if (auto v = AlbedoMapPassFromName(flags.albedo_map_pass)) albedo_map_pass = *v;
  if (auto v = RefineUpdateFromName(flags.refine_update)) refine_update = *v;
  if (auto v = PhotoScaleModeFromName(flags.photo_scale)) photo_scale = *v;
  Problems(*this, &flags).ThrowIfAny();
}

}  // namespace igi::solver
