#pragma once
// What igi-hdr merges: a bracket of raw files (decoded linearly, no response needed) or of 8/16-bit
// images (with a response.json, --linear, or a Debevec response recovered from the bracket
// itself), with exposure times from a list, a file, the manifest or the files' metadata.
// Mixed raw and non-raw inputs, and every problem of calib::LoadBracket, are InputErrors.

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
  std::filesystem::path response;   // response.json; empty = see `linear`
  bool linear = false;              // non-raw input is linear (no response.json needed)
  RawDecodeOptions raw;
};

struct HdrInput {
  std::vector<Image> images;  // normalised levels in [0, 1]
  std::vector<std::string> names;
  std::vector<double> exposures_s;
  calib::ResponseCurve response;
  int bits = 8;  // quantisation of the levels (16 for raw)
  bool raw = false;
  std::string response_source;  // "raw (linear)", "linear", the response file, or "recovered"
};

// `exposures_s` (non-empty, e.g. from a manifest) overrides options.exposures and metadata.
HdrInput LoadHdrInput(const std::vector<std::filesystem::path>& paths,
                      const HdrInputOptions& options, const std::vector<double>& exposures_s = {});

}  // namespace igi::hdr
