#pragma once
// The PHOTOS_DIR layout igi-run reads (docs/run.md):
//
//   PHOTOS_DIR/NAME_LIGHTING/   one sub-folder per photo; LIGHTING (the text after the last
//                               '_') names a lighting of scene.json. When the scene has a single
//                               lighting the suffix may be left out.
//     00.png 01.png ...         an exposure bracket of LDR images (PNG/JPEG/TIFF, 8 or 16 bit)
//     exposures.txt             their exposure times, one per line in file-name order (else EXIF)
//   or  *.dng|*.cr2|*.nef|...   raw files (decoded linearly, no response needed; exposures from
//                               exposures.txt or EXIF)
//   or  radiance.exr|.hdr       one radiance map (used as is)
//   or  manifest.jsonl          an igi-capture folder (merged with igi-hdr --manifest)
//   PHOTOS_DIR/camera.json      optional: known intrinsics (igi-calib intrinsics) for igi-register
//                               and vignetting (igi-calib vignetting) for igi-hdr
//   PHOTOS_DIR/colour.json      optional: the colour matrix (igi-calib colour) for igi-hdr
//   PHOTOS_DIR/lights.json      optional: calibrated lights (igi-calib lights) for the scene
//   PHOTOS_DIR/markers.json     optional: control points (igi-markers) for igi-register
//
// Every other entry of PHOTOS_DIR is an error (exit 2), so that a typo is not silently dropped.

#include <filesystem>
#include <string>
#include <vector>

namespace igi::pipeline {

enum class PhotoSourceKind { kBracket, kRaw, kRadiance, kCapture };

struct PhotoSource {
  std::string name;      // the sub-folder's name: the photo's and its camera's name
  std::string lighting;  // a lighting of the scene
  PhotoSourceKind kind = PhotoSourceKind::kBracket;
  std::filesystem::path dir;
  std::vector<std::filesystem::path> images;  // sorted by name (kBracket, kRaw, kRadiance)
  std::filesystem::path exposure_file;        // exposures.txt, empty = EXIF
  std::filesystem::path manifest;             // kCapture
};

struct PhotoLayout {
  std::filesystem::path dir;
  std::vector<PhotoSource> photos;  // sorted by name
  std::filesystem::path camera;     // optional camera.json
  std::filesystem::path markers;    // optional markers.json
  std::filesystem::path colour;     // optional colour.json (igi-calib colour)
  std::filesystem::path lights;     // optional lights.json (igi-calib lights)
  // The bracket the response curve is recovered from (the one with the most images), or -1
  // when no photo is an LDR bracket.
  int ResponseSource() const;
};

// Reads and checks the layout. `lightings`: the scene's lighting names. Every problem is
// reported (InputError, one line each: "FILE: KEY: VALUE: RULE").
PhotoLayout ScanPhotosDir(const std::filesystem::path& dir,
                          const std::vector<std::string>& lightings);

const char* KindName(PhotoSourceKind kind);

}  // namespace igi::pipeline
