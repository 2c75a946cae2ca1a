#pragma once
// What igi-hdr merges: a bracket of raw files (decoded linearly, no response needed) or of 8/16-bit
// images (with a response.json, --linear, or a Debevec response recovered from the bracket
// itself), with exposure times from a list, a file, the manifest or the files' metadata.
// Mixed raw and non-raw inputs, and every problem of calib::LoadBracket, are InputErrors.
//
// With `headers_only`, 8/16-bit frames whose response is known (a response.json, or --linear)
// are checked on their headers alone (calib::LoadBracket's rules: at least two images, 8- or
// 16-bit levels of one depth, one size, valid exposure times) and their pixels are left to a
// streamed merge (hdr/merge_stream.h). Raw files (LibRaw decodes a whole frame) and a response
// recovered from the bracket itself (it samples the whole images) still load every frame.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calib/bracket.h"
#include "calib/response_curve.h"
#include "hdr/raw_decode.h"
#include "tools/common/image.h"

namespace igi::hdr {

struct HdrInputOptions {
  calib::ExposureSource exposures;  // both empty = EXIF / raw metadata
  std::filesystem::path response;   // response.json; empty = see `curve`, then `linear`
  // A response already in memory, used in place of a response.json (igi.calib.ResponseCurve in
  // Python), its origin in `curve_source` (HdrInput::response_source).
  std::optional<calib::ResponseCurve> curve;
  std::string curve_source;
  bool linear = false;              // non-raw input is linear (no response.json needed)
  // How raw input is decoded (white balance, colour, binning).
  RawDecodeOptions raw;
  bool headers_only = false;  // leave the pixels of non-raw frames unread where possible
};

struct HdrInput {
  std::vector<Image> images;  // normalised levels in [0, 1]; empty when `headers_only` held
  std::vector<std::filesystem::path> paths;
  std::vector<std::string> names;
  std::vector<double> exposures_s;
  calib::ResponseCurve response;
  int bits = 8;  // quantisation of the levels (16 for raw)
  bool raw = false;
  bool headers_only = false;    // the pixels were not read: `images` is empty
  std::string response_source;  // "raw (linear)", "linear", the response file, or "recovered"
};

// `exposures_s` (non-empty, e.g. from a manifest) overrides options.exposures and metadata.
HdrInput LoadHdrInput(const std::vector<std::filesystem::path>& paths,
                      const HdrInputOptions& options, const std::vector<double>& exposures_s = {});

// A bracket of 8/16-bit levels already in memory (arrays from Python) with its response chosen as
// LoadHdrInput chooses it: response.json, `curve`, `linear`, or recovered from the bracket.
HdrInput HdrInputFromBracket(calib::Bracket bracket, const HdrInputOptions& options);

}  // namespace igi::hdr
