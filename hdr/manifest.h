#pragma once
// Reading igi-capture's manifest.jsonl (docs/file-formats.md): one JSON object per line and frame
// with "file" (relative to the manifest's folder), "camera", "exposure_us", "gain", "pixel_format",
// "timestamp". An optional "bracket" key (string or integer) separates brackets of one camera.
//
// Frames are grouped into brackets by (camera, gain, bracket): frames with another gain are
// another bracket, since the gain's unit is the camera's own. Within a bracket, frames keep the
// file's order. Keys other than these are ignored (igi-capture may add some). "gain" and
// "timestamp" may be null (unknown: frames of unknown gain share gain 0). A line that is not a
// JSON object, a missing or wrongly typed required key, or a non-positive exposure is an
// InputError "MANIFEST: line N: KEY: VALUE: RULE"; every bad line is reported, but a last line
// without its newline that is not JSON (a capture stopped mid-write) is skipped with a warning.

#include <filesystem>
#include <string>
#include <vector>

namespace igi::hdr {

struct ManifestFrame {
  std::filesystem::path file;  // resolved against the manifest's folder
  std::string camera;
  double exposure_s = 0.0;
  double gain = 0.0;
  std::string pixel_format;
  std::string bracket;  // "" when the line has no "bracket"
  int line = 0;         // 1-based line in the manifest
};

struct ManifestBracket {
  std::string camera;
  double gain = 0.0;
  std::string bracket;
  std::vector<ManifestFrame> frames;
  // A name for outputs: "CAMERA", plus "_gGAIN" and "_BRACKET" where they tell brackets apart.
  std::string label;
};

std::vector<ManifestBracket> ReadManifest(const std::filesystem::path& path);

}  // namespace igi::hdr
