#pragma once
// igi-synth's job: writes a scene folder with known truth (docs/file-formats.md, truth.json):
//   scene.json               the DECLARED scene: unknown material values left out, effects
//                            silent; every lighting (L0, L1), cameras, photos
//   geometry/room.obj        regions by usemtl, UVs, normals
//   photos/CAM_L.exr         linear radiance (float), with sensor noise when asked, and
//                            photos/CAM_L_mask.png where a pixel saturated
//   brackets/CAM_L/NN.png    optional LDR exposures (+ exposures.txt, one time per line)
//   validation/CAM_L1.exr    clean renders of the TRUE scene under the other lighting
//   truth.json               true materials, effects with parameters, validation images,
//                            per-camera highlight targets, sensor and bracket truth
//   truth/scene.json         the TRUE scene, complete (renderable with igi-render)
//   truth/radiance/CAM_L.exr the noise-free radiance each bracket folder exposes (with brackets)
//   truth/...                files only the truth needs (textures, extra geometry, response)
// With `from` (an existing capture's scene.json, any renderer's or camera's), nothing is
// rendered: its photos are written to photos/ with the photo effects (vignetting,
// exposure_scale, camera_response) applied, pose_error changes the declared pose, and
// scene.json / truth/scene.json are its document (absolute paths) declared and true.

#include <cstdint>
#include <string>
#include <vector>

#include "solver/synth/synth_options.h"

namespace igi::synth {

struct SynthSummary {
  std::vector<std::string> photos;      // relative to the folder
  std::vector<std::string> validation;  // relative to the folder
  int64_t saturated_pixels = 0;         // over all photos (--noise realistic)
  double render_seconds = 0;
  double seconds = 0;
};

// Validates `options` (InputError, nothing written), refuses a non-empty folder unless
// options.overwrite (InputError), then renders and writes everything. Deterministic for a seed
// (render and noise streams depend only on the seed and the photo's index).
SynthSummary Synthesize(const SynthOptions& options);

}  // namespace igi::synth
