#pragma once
// A camera response curve in the form of Debevec & Malik (SIGGRAPH 1997): for each channel and
// each pixel level z in [0, levels), g(z) = ln(exposure) = ln(E * t) up to an additive constant.
// Pixel values are normalised to [0, 1] (level / (levels - 1)); between levels g is linear.
//
// response.json (docs/file-formats.md): {"format": "igi-response", "version": 1, "method",
// "levels", "channels", "g": [[levels numbers] per channel]} plus an optional free-form "info"
// object. Reading is strict: a wrong key, type, count or a g that decreases is an InputError naming
// the file and the key path.

#include <filesystem>
#include <string>
#include <vector>

#include "tools/common/json.h"

namespace igi::calib {

struct ResponseCurve {
  // How the curve was made, as the file's "method" text: igi writes "debevec", "robertson"
  // (calib/response_recovery.h) or "linear" (LinearResponse); other writers put their own text
  // (igi-synth: "igi-synth truth"), so any non-empty text is read.
  std::string method = "debevec";
  int levels = 256;                    // number of pixel levels (256 for 8-bit)
  std::vector<std::string> channels;   // e.g. {"R", "G", "B"}
  std::vector<std::vector<double>> g;  // [channel][level]: ln exposure, any additive constant

  int num_channels() const { return int(g.size()); }
  // ln exposure of normalised pixel value `v` in [0, 1] of `channel`, interpolated.
  double LnExposure(int channel, double v) const;
  // Shifts every channel so that g(levels / 2) = 0 of channel `reference` (removes the free
  // additive constant in a fixed way, channels keep their relative offsets).
  void NormaliseAtMiddle(int reference = 1);
};

// The response of a linear sensor: g(z) = ln(max(z, 0.5) / (levels - 1)).
ResponseCurve LinearResponse(int levels, int channels);

// Default channel names for `channels` channels: {"Y"}, {"Y","A"}, {"R","G","B"},
// {"R","G","B","A"}.
std::vector<std::string> DefaultChannelNames(int channels);

// response.json I/O. `info` (may be null) is written under "info".
ResponseCurve ReadResponseJson(const std::filesystem::path& path);
void WriteResponseJson(const std::filesystem::path& path, const ResponseCurve& curve,
                       const Json& info = Json());
Json ResponseToJson(const ResponseCurve& curve, const Json& info = Json());
// Parses a document already read; `file` names it in errors.
ResponseCurve ResponseFromJson(const Json& document, const std::string& file);

}  // namespace igi::calib
