#pragma once
// Linear decoding of camera raw files (DNG, CR2, NEF, ARW, KDC, …) through LibRaw.
//
// The result is linear in scene radiance: the black level is subtracted, values are scaled so
// that the white level (saturation) is 1 and clipped there, no gamma, no auto-brightening, no
// highlight recovery. So a raw bracket needs no response curve. Demosaicing is LibRaw's.
// A file LibRaw cannot open or decode is an InputError "FILE: raw: REASON".

#include <filesystem>
#include <string>

#include "tools/common/image.h"

namespace igi::hdr {

struct RawDecodeOptions {
  // "camera": the white balance the camera recorded; "none": unity multipliers (raw ratios).
  std::string white_balance = "camera";
  // "srgb": linear sRGB primaries (LibRaw's colour matrix); "raw": the camera's own RGB.
  std::string color = "srgb";
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
