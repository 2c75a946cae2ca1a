#pragma once
// The photographed radiance samples the solver fits (Yu et al. 1999 §4): one per photo pixel that
// sees a reflective surface cleanly. A pixel is kept when its centre ray and four rays at
// (±¼, ±¼) of a pixel hit the same region with normals within a few degrees (so the pixel's mean
// radiance, docs/scene-format.md, and its centre's agree), the mask allows it, every channel is
// finite and non-negative, and no channel is clipped. Where the observations are drawn to a budget,
// one may stand for a square block of pixels instead (solver/inverse/observation_draw.h): their
// mean, kept when every pixel of it is usable and the rays through the centres of its stride cells
// and its quarter points meet one smooth piece of one region.
//
// Frames and units: world frame, metres; radiance linear in the scene's units.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "tools/common/image.h"

namespace igi::solver {

struct Observation {
  int photo = -1;        // index into Scene::photos
  int x = 0, y = 0;      // pixel (column, row), row 0 at the top: the footprint's top-left
  int size = 1;          // the footprint's side in pixels: a pixel (1) or a block's mean
  int triangle = -1;     // index into Scene::mesh.triangles
  float b1 = 0, b2 = 0;  // barycentrics of the triangle's vertices 1 and 2 at the hit
  int region = -1;       // index into Scene::materials
  int patch = -1;        // index into the solver's PatchSet (solver/inverse/patches.h)
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // hit point, world
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();   // shading normal, on the viewer's side
  Eigen::Vector3f view = Eigen::Vector3f::UnitZ();     // unit, from the surface toward the camera
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();  // the photo's pixel, linear RGB
  // The spread of the shading normal over the pixel's footprint: the trace of its covariance
  // (radians², linear change over the pixel, box-averaged). A pixel records a lobe convolved
  // with that spread; for Ward's near-Gaussian lobe that is α² + lobe_blur2 (the normal
  // filtering of specular antialiasing). Zero on flat surfaces.
  float lobe_blur2 = 0;
};

struct PatchSet;
struct ObservationDraw;

struct ObservationOptions {
  int pixel_stride = 2;   // every stride-th pixel in x and y
  double saturation = 0;  // values >= this are clipped; 0 = auto (see AutoSaturation)
  // Keeps a pixel that sees a reflective surface only where the draw does
  // (solver/inverse/observation_draw.h); null: every such pixel.
  const ObservationDraw* draw = nullptr;
  // Worker threads; 0 = the process default.
  int num_threads = 0;
};

// What became of a photo's pixels.
struct PhotoObservationStats {
  int pixels = 0;         // looked at (after the stride)
  int valid = 0;          // kept as observations
  int masked = 0;         // mask = 0
  int clipped = 0;        // a channel at or above the saturation value
  int invalid = 0;        // a channel non-finite or negative
  int background = 0;     // sees no reflective surface (nothing, a light, an emitter or black)
  int edge = 0;           // footprint straddles regions, creases or depth steps
  int undrawn = 0;        // sees a reflective surface, not drawn (ObservationOptions::draw)
  int blocks = 0;         // of the valid: blocks of pixels (Observation::size > 1)
  double saturation = 0;  // the clipping value used (infinity: none)
};

// Observation::lobe_blur2 from the shading normals of a pixel's four quarter-pixel rays (at
// (0.25|0.75, 0.25|0.75), index bit 0: x, bit 1: y) and its centre's normal n.
double PixelNormalSpread(const std::array<Eigen::Vector3d, 4>& quarter, const Eigen::Vector3d& n);

// The shading normals at the four quarter points of the square of `size` pixels whose top-left
// pixel is (x, y) (pixel (x, y) itself for size 1) of `camera` (the order of PixelNormalSpread),
// traced through `geometry`; none when a ray misses `centre`'s region, turns its normal to a
// cosine of `cos_min` or less from the centre's, or meets a point off the centre's face plane by
// `max_offset`·centre.t or more.
std::optional<std::array<Eigen::Vector3d, 4>> QuarterPixelNormals(
    const render::RayScene& geometry, const recon::Camera& camera, int x, int y,
    const render::SurfaceHit& centre, double cos_min,
    double max_offset = std::numeric_limits<double>::infinity(), int size = 1);

// The roughness a pixel sees: α widened by its spread of normals (√(α² + spread)).
inline double WidenedAlpha(double alpha, double spread) {
  return std::sqrt(alpha * alpha + spread);
}

// Whether pixel (x, y) of a linear radiance image can be an observation's: masked out (mask 0),
// invalid (a channel non-finite or negative), clipped (a channel at or above `saturation`), or
// usable, its RGB in *value.
enum class PixelUse { kUsable, kMasked, kInvalid, kClipped };
PixelUse CheckPixel(const Image& radiance, const std::vector<uint8_t>* mask, int x, int y,
                    double saturation, Eigen::Vector3f* value);

// The clipping value of a photo: its maximum when 3 or more pixels share it exactly (a sensor's
// clipped highlight), else infinity.
double AutoSaturation(const Image& image);

// The observations of photo `photo` (its linear radiance image and optional 8-bit mask of the
// photo's size, row by row, 0 = ignore), traced through `geometry`, the ray queries on the
// photo's lighting.
std::vector<Observation> CollectObservations(
    const recon::Scene& scene, int photo, const Image& radiance, const std::vector<uint8_t>* mask,
    const render::RayScene& geometry, const PatchSet& patches, const ObservationOptions& options,
    PhotoObservationStats* stats);

}  // namespace igi::solver
