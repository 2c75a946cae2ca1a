#pragma once
// --from-raw DIR: imports a folder of camera raw files into the capture layout,
// so that igi-hdr reads a raw bracket and an igi-capture bracket alike. The raw
// files are copied unchanged (atomically) into OUT/frames/, and each gets a
// manifest line (manifest.h) with the camera, exposure and ISO read by LibRaw
// from the file's metadata: gain = ISO / 100 (null when the file gives no ISO),
// pixel_format "raw:<extension>", plus iso, black_level, white_level, width,
// height and source (the original path). Brackets are the distinct exposures,
// shortest first; frames within a bracket follow file-name order.
//
// Every raw file is read before anything is written: a file LibRaw cannot open,
// or one without a positive exposure time, is an InputError (exit 2) and
// nothing is written.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace igi::capture {

// Files with these extensions are raw candidates ("dng", "cr2", "nef", "kdc",
// …; lower case).
bool IsRawExtension(const std::string& extension);

struct RawFileInfo {
  std::string camera;  // "Make Model"
  double exposure_us = 0.0;
  std::optional<double> iso;  // nullopt when the file records none
  std::string timestamp;      // ISO 8601 UTC, empty when unknown
  int black_level = 0;
  int white_level = 0;
  int width = 0;  // raw sensor pixels
  int height = 0;
};

// Reads the metadata of one raw file through LibRaw; InputError "FILE: cannot
// read raw: …".
RawFileInfo ReadRawInfo(const std::filesystem::path& path);

struct RawImportOptions {
  std::filesystem::path raw_dir;  // folder of raw files (not recursive)
  // The capture folder written (required): frames/ and manifest.jsonl.
  std::filesystem::path out_dir;
  bool resume = false;  // add only the files the manifest lacks
  void Validate() const;
};

struct RawImportSummary {
  int files_found = 0;
  int files_imported = 0;            // by this run
  int files_already_done = 0;        // listed before (resume)
  std::vector<std::string> ignored;  // files without a raw extension
};

RawImportSummary ImportRaw(const RawImportOptions& options);

}  // namespace igi::capture
