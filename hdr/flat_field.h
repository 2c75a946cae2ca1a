#pragma once
// A flat-field photo read into block means of its linear luminance (calib/vignetting.h), for
// igi-calib vignetting. The photo is one of:
//   - a raw file (DNG, CR2, NEF, …): decoded linearly in camera RGB without white balance, 1 =
//     the white level;
//   - an 8- or 16-bit image with a response (response.json, or linear): its levels made linear
//     through the response;
//   - a float image (OpenEXR, Radiance HDR, float TIFF): already linear.
// Non-raw files are read a band of rows at a time. A pixel is unusable when a channel is at or
// above `saturated` or at or below `black` (recorded levels: raw and 8/16-bit), or is not a
// positive finite number (float).

#include <filesystem>
#include <optional>

#include "calib/response_curve.h"
#include "calib/vignetting.h"

namespace igi::hdr {

struct FlatFieldReadOptions {
  std::optional<calib::ResponseCurve> response;  // 8/16-bit input: required (LinearResponse ok)
  double black = 0.02;      // normalised level at or below which a recorded value is unusable
  double saturated = 0.98;  // normalised level at or above which it is clipped
  int block_px = 0;         // 0 = calib::FlatFieldBlockSize of the photo
};

// Throws InputError naming the file: unreadable, 8/16-bit without a response, a response with
// another channel count, or a photo FlatFieldReducer refuses (clipped, black, dark).
calib::FlatField ReadFlatField(const std::filesystem::path& path,
                               const FlatFieldReadOptions& options);

}  // namespace igi::hdr
