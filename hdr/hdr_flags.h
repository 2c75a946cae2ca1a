#pragma once
// igi-hdr's flags and its merge of one bracket, defined once for the executable and for the
// Python package: igi.hdr.merge's keyword arguments are these flags' names with '_' for '-'
// (band_rows=32 is --band-rows 32), parsed, checked and merged by the same code.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "hdr/align.h"
#include "hdr/correction.h"
#include "hdr/hdr_input.h"
#include "hdr/merge.h"
#include "hdr/merge_stream.h"
#include "hdr/raw_decode.h"
#include "tools/common/image.h"

namespace igi::hdr {

struct HdrFlags {
  HdrInputOptions input;        // --response, --exposures, --exposure-file, --linear, raw decode
  MergeOptions merge;           // --shot-noise, --read-noise, --saturated (weighting, black below)
  HdrStreamOptions stream;      // --band-rows
  std::optional<double> black;  // --black; absent = MergeOptions' default, raw input 0
  std::string out;              // the radiance map (.exr); empty = not written
  std::string mask_out;         // empty = OUT_mask.png
  std::string camera;           // camera.json whose vignetting is divided out; empty = none
  std::string colour;           // colour.json: camera RGB -> linear sRGB; empty = none
  bool align = false;
  bool whole_images = false;  // load every frame whole instead of merging band by band
  // The choice flags as typed; FinishHdrFlags parses them into `merge` and `input.raw`.
  std::string weighting = "noise";
  std::string raw_white_balance = "camera";
  std::string raw_color = "srgb";
};

// Adds igi-hdr's options, all but the images and --manifest, to `app`, writing into `flags`.
void AddHdrFlags(CLI::App& app, HdrFlags* flags);

// After parsing: the choice flags parsed into the options and every option validated
// (InputError "--FLAG: VALUE: RULE").
void FinishHdrFlags(HdrFlags* flags);

// The raw decode choices from their flags' text into `raw`, validated; InputError
// "--FLAG: VALUE: RULE" for each bad one.
RawDecodeOptions ParseRawChoices(const std::string& white_balance, const std::string& color,
                                 RawDecodeOptions raw);

// OUT_mask.png beside OUT.
std::filesystem::path DefaultMaskPath(const std::filesystem::path& out);

// Throws InputError naming the bracket's first file when its frames do not fit the corrections
// (camera.json's size, the colour matrix's channels and input kind).
void CheckCorrection(const HdrInput& input, const RadianceCorrection& correction);

// What MergeHdrInput did.
struct MergedBracket {
  int width = 0;
  int height = 0;
  int64_t saturated_pixels = 0;  // pixels saturated in every exposure (in some channel)
  int64_t black_pixels = 0;      // pixels black in every exposure (in some channel)
  std::vector<PixelShift> shifts;  // per frame when aligned, else empty
  ImageMetadata radiance_metadata;  // igi:response and igi:weighting, as written
  // Held when the frames were merged whole; a merge band by band leaves them in the files.
  std::optional<Image> radiance;
  std::optional<Image> mask;
};

// Merges one bracket as igi-hdr does: aligned when asked, band by band when the input holds
// headers only (else whole), corrected, and written to `out` and `mask` where they are not
// empty (band by band needs `out`). The merge takes `flags.merge` with the input's bits, and a
// black of 0 for raw input unless --black was given (raw data has its black level subtracted).
MergedBracket MergeHdrInput(HdrInput& input, const HdrFlags& flags,
                            const RadianceCorrection& correction,
                            const std::filesystem::path& out, const std::filesystem::path& mask);

}  // namespace igi::hdr
