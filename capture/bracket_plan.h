#pragma once
// A bracket plan: which exposures to take, how many frames each, in which pixel
// format, gain and file format. It is written to DIR/plan.json before the first
// frame, so that --resume finishes exactly the same plan (an --auto plan is
// metered once, not again on resume).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/common/json.h"

namespace igi::capture {

// The file format of a plan's frames, both 16-bit and lossless: PNG (".png") or TIFF (".tif").
enum class PlanFileFormat { kPng, kTiff };
// "png", "tiff" (the --format flag's and plan.json's spelling).
std::string_view PlanFileFormatName(PlanFileFormat format);
// The format a name spells; nullopt for anything but "png" and "tiff".
std::optional<PlanFileFormat> PlanFileFormatFromName(std::string_view name);

struct BracketPlan {
  std::string camera;                // CameraInfo::id of the camera the plan was made for
  std::vector<double> exposures_us;  // in capture order; > 0, distinct
  int frames = 1;                    // frames per exposure
  int settle_frames = 1;             // frames dropped after each exposure change
  std::string pixel_format;          // GenICam name as the camera reported it
  double gain = 0.0;                 // camera units, as read back
  // Frame files: kPng (default) or kTiff, 16-bit lossless.
  PlanFileFormat file_format = PlanFileFormat::kPng;
  bool auto_metered = false;  // the exposures came from --auto

  // InputError (one line per problem, `source` as the file) when a field is out
  // of range.
  void Validate(const std::string& source) const;
  int total_frames() const { return int(exposures_us.size()) * frames; }
};

// One frame of a plan: bracket (exposure index) and frame index within the
// exposure.
struct PlanSlot {
  int bracket = 0;
  int frame = 0;
  bool operator<(const PlanSlot& o) const {
    return bracket != o.bracket ? bracket < o.bracket : frame < o.frame;
  }
  bool operator==(const PlanSlot& o) const = default;
};

// The file a slot is written to, relative to the output folder:
// "frames/b00_e000010000us_f000.png" (bracket, exposure in µs, frame).
std::string SlotFileName(const BracketPlan& plan, const PlanSlot& slot);

// Parses "--exposures-us 1000,4000,16000" (commas or spaces). InputError on a
// bad list: empty, a value that is not a positive number, or a repeated value.
std::vector<double> ParseExposureList(const std::string& text);

Json PlanToJson(const BracketPlan& plan);
// Reads DIR/plan.json strictly; InputError naming the file and key.
BracketPlan ReadPlan(const std::filesystem::path& path);
void WritePlan(const std::filesystem::path& path, const BracketPlan& plan);

}  // namespace igi::capture
