#pragma once
// Light calibration from photos of glossy spheres and diffuse targets (the `igi-lights` file of
// docs/file-formats.md):
//
// - A light's direction: the specular highlight on a sphere of known centre and radius, seen by
//   a calibrated camera, marks the surface point whose normal n bisects the directions to the
//   camera v and to the light l, so l = 2(n·v)n − v (the mirror direction).
// - A point light's position: the mirror rays of several views (several cameras, or several
//   spheres) meet at the light; their least-squares closest point is its position. One sphere's
//   baseline is its own diameter, so it locates only lights within a few radii of it; spheres
//   metres apart locate a light across a room.
// - Its strength: a Lambertian target of known reflectance ρ records L = ρ/π · E cosθ, so a
//   point light's intensity is I = π L d² / (ρ cosθ) (W·sr⁻¹) and a directional light's
//   irradiance perpendicular to its direction E = π L / (ρ cosθ) (W·m⁻²), in the photos' radiance
//   units (docs/scene-format.md).
//
// World frame, metres. Pixels are continuous coordinates whose top-left pixel centre is
// (0.5, 0.5). Images are linear radiance (any scale). Bad input (a sphere outside the photo, no
// highlight, parallel rays) throws igi::InputError naming the photo or the light.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::calib {

// A sphere's outline in a photo: centre and radius in pixels.
struct ImageCircle {
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();
  double radius_px = 0;
};

// The circle of a mask's nonzero pixels (first channel): the centroid of their centres and the
// radius of a disc of their area. nullopt when no pixel is nonzero.
std::optional<ImageCircle> CircleFromMask(const Image& mask);

struct HighlightOptions {
  // Fraction of the way from the sphere's median luminance up to its peak that a pixel must
  // reach to belong to the highlight (0..1, exclusive). Low enough that a sharp highlight spans
  // a few tens of pixels, whose weighted centroid is then not locked to the pixel grid.
  double level = 0.2;
  // Value at or above which a channel is clipped (> 0; infinity = none, as in an HDR radiance
  // map); a clipped pixel is part of the highlight's core with the peak's weight.
  double saturated = std::numeric_limits<double>::infinity();
  // The peak must exceed the sphere's median luminance by this factor (> 1).
  double min_contrast = 3.0;
  // Part of the outline's radius searched (0..1]; the rim, whose outline is least certain, is
  // left out.
  double search_radius = 0.98;
  // Least fraction of the searched disc that must lie in the image and the mask (0..1].
  double min_inside = 0.5;

  // Throws InputError naming the field and its rule.
  void Validate() const;
};

struct Highlight {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // weighted centroid, sub-pixel
  int pixels = 0;                                   // pixels of the highlight
  int saturated_pixels = 0;                         // of which clipped
  double peak = 0;                                  // brightest luminance (linear)
  double median = 0;                                // median luminance over the sphere
};

// The specular highlight of the sphere whose outline in `image` (linear radiance; luminance =
// mean of the first three channels) is `circle`: of the connected sets of pixels brighter than
// median + level·(peak − median) inside the searched disc (and inside `mask` where given, 0 =
// ignore), the one of largest weight; its centroid weighted by brightness above the threshold.
// Throws InputError naming `source` when the disc is mostly outside the image or mask, or the
// sphere shows no highlight (peak under min_contrast × median).
Highlight FindSphereHighlight(const Image& image, const ImageCircle& circle, const Image* mask,
                              const HighlightOptions& options, const std::string& source);

// A sphere in the world frame.
struct Sphere {
  std::string name;  // the scene region it was fitted to, or empty
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;   // metres, > 0
  double fit_rms = 0;  // RMS distance of the fitted points from the surface, metres
};

// The least-squares sphere through `points` (the algebraic fit |p|² = 2c·p + k, then
// r = sqrt(k + |c|²)). nullopt for fewer than 4 points or points on a plane.
std::optional<Sphere> FitSphere(const std::vector<Eigen::Vector3d>& points);

// A calibrated view of the scene: the camera centre and the unprojection and projection of its
// camera model (distortion included).
struct SphereView {
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();
  // Continuous pixel -> unit ray direction in the world frame, from `eye`.
  std::function<Eigen::Vector3d(const Eigen::Vector2d&)> world_ray;
  // World point -> continuous pixel; nullopt behind the camera.
  std::function<std::optional<Eigen::Vector2d>(const Eigen::Vector3d&)> project;
};

// The circle enclosing the sphere's outline in the view: the mean of 64 projected rim points
// and their greatest distance from it. nullopt when the eye is inside the sphere or the rim is
// behind the camera.
std::optional<ImageCircle> ProjectSphere(const Sphere& sphere, const SphereView& view);

// The mirror direction l = 2(n·v)n − v (unit) of the unit direction `to_viewer` about the unit
// `normal`.
Eigen::Vector3d MirrorDirection(const Eigen::Vector3d& normal, const Eigen::Vector3d& to_viewer);

// One photo's evidence of a light: the highlight on a sphere and the ray toward the light.
struct LightRay {
  std::string photo;   // the photo, for messages and the calibration record
  std::string sphere;  // the sphere's name
  Highlight highlight;
  Eigen::Vector3d surface = Eigen::Vector3d::Zero();   // the highlight's point on the sphere
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // the sphere's normal there
  Eigen::Vector3d to_light = Eigen::Vector3d::Zero();  // unit mirror direction
  double miss_px = 0;  // how far outside the sphere the highlight's ray passed, pixels (0: hit)
};

// The light ray of `image` (linear radiance, taken by `view`): the highlight inside the
// sphere's projected outline, the viewing ray through it met with the sphere (a ray that misses
// by a fraction of a pixel at the rim is taken to the rim's nearest point), and the mirror
// direction there. Throws InputError naming `source` (FindSphereHighlight's, or the sphere
// behind the camera).
LightRay MeasureLightRay(const Image& image, const Image* mask, const Sphere& sphere,
                         const SphereView& view, const HighlightOptions& options,
                         const std::string& source);

// The mean direction of the rays (toward the light) and the largest angle of one from it.
struct DirectionEstimate {
  Eigen::Vector3d to_light = Eigen::Vector3d::UnitZ();
  double spread_deg = 0;
};
DirectionEstimate AverageDirection(const std::vector<LightRay>& rays);

// The least-squares closest point to the rays: argmin Σ |(I − d dᵀ)(x − o)|².
struct PositionEstimate {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double rms_distance = 0;  // RMS distance of the rays from it, metres
  double max_distance = 0;
  // The largest angle between two rays, degrees: the triangulation's baseline angle.
  double ray_angle_deg = 0;
};
// Throws InputError naming `light` when fewer than two rays are given, the rays are nearly
// parallel (under `min_ray_angle_deg` apart), or the point lies behind a ray's origin.
PositionEstimate TriangulateRays(const std::vector<LightRay>& rays, const std::string& light,
                                 double min_ray_angle_deg = 0.5);

// A pixel of a Lambertian target: its linear radiance, surface point and unit normal (on the
// side of the camera).
struct TargetSample {
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

struct EmissionEstimate {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();  // per channel, the median over samples
  int samples = 0;                                  // samples lit at cosθ ≥ min_cos
  double spread = 0;  // (90th − 10th percentile) / median of the luminance estimates
};
// A point light's intensity at `position` from target samples of reflectance `rho` (RGB, > 0):
// the median of π L d² / (ρ cosθ). Samples at cosθ < min_cos are left out. Throws InputError
// naming `light` when no sample is left.
EmissionEstimate PointIntensityFromTarget(const std::vector<TargetSample>& samples,
                                          const Eigen::Vector3d& position,
                                          const Eigen::Vector3d& rho, const std::string& light,
                                          double min_cos = 0.2);
// A directional light's irradiance (perpendicular to its travel `direction`, unit): the median
// of π L / (ρ cosθ).
EmissionEstimate DirectionalIrradianceFromTarget(const std::vector<TargetSample>& samples,
                                                 const Eigen::Vector3d& direction,
                                                 const Eigen::Vector3d& rho,
                                                 const std::string& light, double min_cos = 0.2);

// One light as calibrated: its scene.json entry and how it was measured.
struct CalibratedLight {
  std::string name;      // the light's name in the scene
  std::string lighting;  // the lighting whose photos measured it
  Json entry;            // the scene.json light object
  std::vector<LightRay> rays;
  std::optional<DirectionEstimate> direction;  // a directional light's
  std::optional<PositionEstimate> position;    // a positioned light's
  std::optional<EmissionEstimate> emission;    // from a target; none = the scene's value kept
};

// Writes lights.json ("format": "igi-lights", docs/file-formats.md) atomically: "lights" (the
// entries, ready for scene.json), "calibration" (per light: lighting, method, views, spreads,
// emission source) and "spheres".
void WriteLightsFile(const std::filesystem::path& path, const std::vector<Sphere>& spheres,
                     const std::vector<CalibratedLight>& lights);

}  // namespace igi::calib
