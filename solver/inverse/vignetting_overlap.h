#pragma once
// The surface points that two registered photos of one lighting both see, for measuring the
// camera's vignetting from the scene itself (calib/vignetting.h, FitOverlap): where no flat field
// was shot, the same point seen near the centre of one photo and near the corner of another
// records the fall-off between those radii.
//
// Each photo is sampled on a grid of pixels; the ray through a grid pixel finds its surface
// point, which is paired with every other photo of the same lighting that sees it: inside that
// image, from the same side of the surface, neither view more grazing than `min_cos`, and with
// nothing in between. Only diffuse surfaces record the same radiance toward both cameras, so
// only the regions the scene declares Lambertian are used (all regions when it declares none,
// with FitOverlap's robust loss then left to discount the glossy ones). A point is used only
// where the rays one pixel away (diagonally), in both views, meet the same region: a value read
// there mixes no edge of a surface, of a shadow-casting object or of a light. The photos' linear luminance (the mean of the channels, through the
// photo's response and exposure scale, NOT divided by any vignetting the scene declares) is
// then read at both ends, one photo in memory at a time. Masked or non-positive values drop
// the pair.

#include <string>
#include <vector>

#include "calib/vignetting.h"
#include "recon/scene.h"

namespace igi::solver {

struct OverlapOptions {
  int samples_per_photo = 4096;  // grid pixels traced per photo
  double min_cos = 0.3;          // |cos| between a view ray and the surface normal, both views
};

struct OverlapPairs {
  std::vector<calib::OverlapPair> pairs;  // photo indices are the scene's
  int traced = 0;                         // grid pixels traced over all photos
  int surface_hits = 0;                   // of which met a scene surface at min_cos or better
};

// Throws InputError (naming the scene file) when a photo cannot be read.
OverlapPairs CollectOverlapPairs(const recon::Scene& scene, const OverlapOptions& options = {});

}  // namespace igi::solver
