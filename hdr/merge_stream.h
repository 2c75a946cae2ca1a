#pragma once
// Merges an exposure bracket band by band, for frames too large to hold whole as float (a 24 MP
// RGB frame is 288 MB as float; a bracket of 7 is 2 GB). Every frame is opened at once and read a
// band of rows at a time (tools/common/image.h ImageRowReader); the band is merged exactly as
// MergeBracket merges whole images (BandMerger, so the values are bit-identical) and written to
// the radiance map and the mask band by band, both to temporary files renamed into place at the
// end. Memory: one band of every frame, the merged band and its mask, so it grows with the width,
// the band height and the frame count, not with the image height (StreamMergeSummary reports it).
//
// Alignment: the frames' 8-bit grey levels (1 byte a pixel, read band by band) give the MTB
// shifts (hdr/align.h); the streamed merge applies them as ShiftImage does, row by row.
//
// Bad input (a frame that cannot be read, frames of different sizes, more than 8 channels, a
// response that does not fit) is an InputError naming the file and the rule, thrown before any
// output is created. A read error part way through removes the partial outputs.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "calib/response_curve.h"
#include "hdr/align.h"
#include "hdr/correction.h"
#include "hdr/merge.h"
#include "tools/common/image.h"

namespace igi::hdr {

struct HdrStreamOptions {
  int band_rows = 64;  // rows of every frame held in memory at once, 1 .. 65536

  // Throws InputError "--band-rows: VALUE: RULE".
  void Validate() const;
};

// Where the streamed merge writes.
struct StreamOutputs {
  std::filesystem::path radiance;   // linear radiance, float (OpenEXR)
  ImageMetadata radiance_metadata;  // written as the radiance map's attributes
  std::filesystem::path mask;       // 8-bit, 1 channel: 1 = good, 0 = bad; empty = none
  RadianceCorrection correction;    // applied to each merged band before it is written
};

struct StreamMergeSummary {
  int width = 0;
  int height = 0;
  int channels = 0;
  int bands = 0;                 // bands merged
  int64_t saturated_pixels = 0;  // pixels saturated in every exposure (in some channel)
  int64_t black_pixels = 0;      // pixels black in every exposure (in some channel)
  // The largest total of pixel buffers held at once, bytes: a band of every frame (plus a row of
  // each shifted frame), the merged band and its mask. Independent of the image height.
  size_t peak_buffer_bytes = 0;
  double seconds = 0.0;  // wall time, reading and writing included
};

// Merges the 8- or 16-bit `frames` (levels as ReadImage gives them, normalised to [0, 1]) with
// their `exposures_s`; `shifts` is empty or one PixelShift per frame (ShiftImage's meaning).
// `merge.bits` must be the frames' bits per sample, as for MergeBracket.
StreamMergeSummary MergeBracketStreamed(const std::vector<std::filesystem::path>& frames,
                                        const std::vector<double>& exposures_s,
                                        const std::vector<PixelShift>& shifts,
                                        const calib::ResponseCurve& response,
                                        const MergeOptions& merge, const HdrStreamOptions& options,
                                        const StreamOutputs& outputs);

// The grey levels of every frame (hdr/align.h ToGrey), read band by band: the input to
// ComputeMtbShifts at 1 byte a pixel a frame. Throws InputError as MergeBracketStreamed.
std::vector<GreyImage> ReadGreyFrames(const std::vector<std::filesystem::path>& frames,
                                      const HdrStreamOptions& options);

}  // namespace igi::hdr
