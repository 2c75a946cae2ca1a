#pragma once
// The files igi-run makes between stages: the tone-mapped photos COLMAP registers, and the
// solvable scene.json (the user's scene, the registered cameras, the HDR photos).

#include <filesystem>
#include <string>
#include <vector>

#include "tools/common/json.h"
#include "tools/pipeline/photo_layout.h"

namespace igi::pipeline {

// An 8-bit PNG of a radiance map for feature matching: scaled so the 99th percentile maps to
// 0.9, gamma 2.2, then a 3x3 median (takes out render/sensor speckle, moves no edge).
void TonemapForRegistration(const std::filesystem::path& radiance,
                            const std::filesystem::path& png);

struct SolvableSceneInputs {
  Json input_scene;                 // the user's scene.json
  std::filesystem::path input_dir;  // its folder
  Json registered_scene;            // igi-register's DIR/scene.json (cameras)
  std::vector<PhotoSource> photos;  // the layout's photos
  std::filesystem::path hdr_dir;    // NAME.exr and NAME_mask.png per photo
  std::filesystem::path out_dir;    // where the result is written
};

// The input scene (paths rebased to out_dir) with the registered cameras and one photo per
// registered camera: the HDR map, its mask when there is one, the lighting of the layout.
// `unregistered` receives the photos without a camera.
Json SolvableScene(const SolvableSceneInputs& in, std::vector<std::string>* unregistered);

}  // namespace igi::pipeline
