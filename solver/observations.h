#pragma once
// The photographed radiance samples the solver fits (Yu et al. 1999 §4): one per photo pixel that
// sees a reflective surface cleanly. A pixel is kept when its centre ray and four rays at
// (±¼, ±¼) of a pixel hit the same region with normals within a few degrees (so the pixel's mean
// radiance, CONTRACT.md §1, and its centre's agree), the mask allows it, every channel is finite
// and non-negative, and no channel is clipped.
//
// Frames and units: world frame, metres; radiance linear in the scene's units.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "tools/common/image.h"

namespace igi {

struct Observation {
  int photo = -1;      // index into Scene::photos
  int x = 0, y = 0;    // pixel (column, row), row 0 at the top
  int triangle = -1;   // index into Scene::mesh.triangles
  float b1 = 0, b2 = 0;  // barycentrics of the triangle's vertices 1 and 2 at the hit
  int region = -1;     // index into Scene::materials
  int patch = -1;      // index into the solver's PatchSet (solver/patches.h)
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // hit point, world
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();   // shading normal, on the viewer's side
  Eigen::Vector3f view = Eigen::Vector3f::UnitZ();     // unit, from the surface toward the camera
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();  // the photo's pixel, linear RGB
};

}  // namespace igi
