#include "capture/bracket_plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::capture {

constexpr EnumNames<PlanFileFormat, 2> kPlanFileFormatNames{
    {{PlanFileFormat::kPng, "png"}, {PlanFileFormat::kTiff, "tiff"}}};

std::string_view PlanFileFormatName(PlanFileFormat format) {
  return kPlanFileFormatNames.Name(format);
}
std::optional<PlanFileFormat> PlanFileFormatFromName(std::string_view name) {
  return kPlanFileFormatNames.FromName(name);
}

void BracketPlan::Validate(const std::string& source) const {
  ProblemList problems;
  if (exposures_us.empty()) problems.Add(source, "exposures_us", "[]", "must list exposures");
  for (size_t i = 0; i < exposures_us.size(); ++i) {
    if (!(exposures_us[i] > 0) || !std::isfinite(exposures_us[i])) {
      problems.Add(source, fmt::format("exposures_us[{}]", i), fmt::format("{}", exposures_us[i]),
                   "must be a positive number of microseconds");
    }
  }
  if (frames < 1) problems.Add(source, "frames", std::to_string(frames), "must be >= 1");
  if (settle_frames < 0) {
    problems.Add(source, "settle_frames", std::to_string(settle_frames), "must be >= 0");
  }
  if (!PlanFileFormatFromName(PlanFileFormatName(file_format))) {
    problems.Add(source, "file_format", std::to_string(int(file_format)), "must be png or tiff");
  }
  problems.ThrowIfAny();
}

std::string SlotFileName(const BracketPlan& plan, const PlanSlot& slot) {
  const double exposure = plan.exposures_us.at(size_t(slot.bracket));
  return fmt::format("frames/b{:02d}_e{:09d}us_f{:03d}.{}", slot.bracket,
                     static_cast<long long>(std::llround(exposure)), slot.frame,
                     plan.file_format == PlanFileFormat::kTiff ? "tif" : "png");
}

std::vector<double> ParseExposureList(const std::string& text) {
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  const std::vector<std::string> tokens = SplitTokens(spaced);
  ProblemList problems;
  std::vector<double> exposures;
  for (const std::string& token : tokens) {
    const auto value = ParseDouble(token);
    if (!value || !(*value > 0) || !std::isfinite(*value)) {
      problems.Add("", "--exposures-us", token, "must be a positive number of microseconds");
      continue;
    }
    if (std::find(exposures.begin(), exposures.end(), *value) != exposures.end()) {
      problems.Add("", "--exposures-us", token, "is listed twice");
      continue;
    }
    exposures.push_back(*value);
  }
  if (tokens.empty()) problems.Add("", "--exposures-us", text, "must list at least one exposure");
  problems.ThrowIfAny();
  return exposures;
}

Json PlanToJson(const BracketPlan& plan) {
  Json json;
  json["format"] = "igi-capture-plan";
  json["version"] = 1;
  json["camera"] = plan.camera;
  json["exposures_us"] = plan.exposures_us;
  json["frames"] = plan.frames;
  json["settle_frames"] = plan.settle_frames;
  json["pixel_format"] = plan.pixel_format;
  json["gain"] = plan.gain;
  json["file_format"] = std::string(PlanFileFormatName(plan.file_format));
  json["auto_metered"] = plan.auto_metered;
  return json;
}

BracketPlan ReadPlan(const std::filesystem::path& path) {
  const Json json = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, path.string(), &problems);
  BracketPlan plan;
  root.ExpectObject({"format", "version", "camera", "exposures_us", "frames", "settle_frames",
                     "pixel_format", "gain", "file_format", "auto_metered"});
  // "format" and "version" are checked where present: a plan written before they were added
  // (a capture to be resumed) has neither.
  if (root["format"].present()) root["format"].Enum({"igi-capture-plan"});
  if (root["version"].present()) {
    if (const auto version = root["version"].Integer(); version && *version != 1) {
      root["version"].Problem("must be 1");
    }
  }
  plan.camera = root["camera"].String().value_or("");
  const size_t count = root["exposures_us"].ArraySize(1);
  for (size_t i = 0; i < count; ++i) {
    plan.exposures_us.push_back(root["exposures_us"][i].Number(NumberRule::Positive()).value_or(1));
  }
  plan.frames = int(root["frames"].Integer(NumberRule::Between(1, 1e6)).value_or(1));
  plan.settle_frames = int(root["settle_frames"].Integer(NumberRule::Between(0, 1e6)).value_or(0));
  plan.pixel_format = root["pixel_format"].String().value_or("");
  plan.gain = root["gain"].Number().value_or(0.0);
  if (const auto format = root["file_format"].Enum({"png", "tiff"})) {
    plan.file_format = PlanFileFormatFromName(*format).value_or(PlanFileFormat::kPng);
  }
  plan.auto_metered = root["auto_metered"].Bool().value_or(false);
  problems.ThrowIfAny();
  plan.Validate(path.string());
  return plan;
}

void WritePlan(const std::filesystem::path& path, const BracketPlan& plan) {
  WriteJsonFile(path, PlanToJson(plan), 2);
}

}  // namespace igi::capture
