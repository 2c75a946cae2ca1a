#pragma once
// Linear decoding of camera raw files (DNG, CR2, NEF, ARW, KDC, …) through LibRaw.
//
// The result is linear in scene radiance: the black level is subtracted, values are scaled so
// that the white level (saturation) is 1 and clipped there, no gamma, no auto-brightening, no
// highlight recovery. So a raw bracket needs no response curve. Demosaicing is LibRaw's.
// A file LibRaw cannot open or decode is an InputError "FILE: raw: REASON".

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "tools/common/image.h"

namespace igi::hdr {

// The white balance of a decode: kCamera, the multipliers the camera recorded; kNone, unity
// multipliers (the raw channel ratios).
enum class RawWhiteBalance { kCamera, kNone };
// "camera", "none" (the --raw-white-balance flag's spelling).
std::string_view RawWhiteBalanceName(RawWhiteBalance white_balance);
std::optional<RawWhiteBalance> RawWhiteBalanceFromName(std::string_view name);

// The primaries of a decode: kSrgb, linear sRGB (LibRaw's colour matrix); kRaw, the camera's own
// RGB.
enum class RawColor { kSrgb, kRaw };
// "srgb", "raw" (the --raw-color flag's spelling).
std::string_view RawColorName(RawColor color);
std::optional<RawColor> RawColorFromName(std::string_view name);

struct RawDecodeOptions {
  RawWhiteBalance white_balance = RawWhiteBalance::kCamera;  // kCamera (default) or kNone
  RawColor color = RawColor::kSrgb;                          // kSrgb (default) or kRaw
  bool half_size = false;  // 2x2 binning instead of demosaicing (faster, half resolution)

  void Validate() const;
};

struct RawImage {
  Image image;            // linear RGB, 1 = white level; metadata has ExposureTime etc.
  double exposure_s = 0;  // shutter time from the file (0 if unknown)
  double iso = 0;
  double aperture = 0;  // f-number
  int black_level = 0;  // raw counts
  int white_level = 0;  // raw counts
  int raw_bits = 0;     // bits per raw sample (from the white level)
  std::string camera;   // "Make Model"
};

// True for the extensions of raw formats LibRaw reads.
bool IsRawFile(const std::filesystem::path& path);

RawImage DecodeRaw(const std::filesystem::path& path, const RawDecodeOptions& options = {});

}  // namespace igi::hdr
