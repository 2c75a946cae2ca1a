#pragma once
// How a photo's recorded values relate to the scene's radiance (igi extensions of scene.json:
// a camera's "vignetting", a photo's "exposure_scale" and "response"), and the block split of
// photo pixels into fitted and held-out sets used by igi-diagnose.
//
// Forward model of a recorded value v at pixel x:  v = R(s · V(x) · L(x)), with L the radiance,
// V the camera's vignetting factor (applied by Renderer::Render already), s the exposure scale and
// R the response (identity by default).

#include <cstdint>

#include "recon/scene.h"
#include "tools/common/image.h"

namespace igi::solver {

// Pixels are held out in square blocks chosen by a hash of (photo, block, seed); fraction 0 =
// nothing held out.
struct PixelHoldout {
  double fraction = 0;
  int block_px = 16;
  uint64_t seed = 1;

  bool HeldOut(int photo, int x, int y) const;
  // The block's uniform draw in [0, 1): held out below `fraction`. The fitted blocks split
  // further by it (cross-fitting's folds).
  double Draw(int photo, int x, int y) const;
  // Fold of a pixel among `folds` (>= 2): 0 = held out, 1..folds-1 = equal shares of the fitted
  // blocks. With folds < 2 the fitted blocks are all fold 1.
  int Fold(int photo, int x, int y, int folds) const;
};

// True when the photo's values are not plain radiance (a response, a scale or vignetting).
bool HasPhotoModel(const recon::Photo& photo, const recon::Camera& camera);

// Radiance from recorded values: inverse response, / exposure scale, / vignetting.
Image LinearRadianceOfPhoto(const recon::Photo& photo, const recon::Camera& camera,
                            const Image& recorded);

// Recorded values from a render (which carries the camera's vignetting): × scale, response.
void ApplyExposureAndResponse(const recon::Photo& photo, Image* render);

}  // namespace igi::solver
