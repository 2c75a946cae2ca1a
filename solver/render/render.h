#pragma once
// The forward model: a physically based path tracer on Embree 3 (next-event estimation with
// multiple importance sampling, every BRDF of docs/scene-format.md, every light type, albedo
// textures, PINHOLE/OPENCV cameras, unbiased Russian roulette). Results are deterministic for
// a given seed, whatever the number of threads.
//
// Output: linear radiance in the scene's units (W·sr⁻¹·m⁻² per channel), RGB, each pixel the
// mean over its square (docs/scene-format.md). Lights not in the rendered lighting are absent,
// geometry included (area and sphere emitters), as in the RADIANCE references.

#include <cstdint>
#include <memory>
#include <vector>

#include "recon/scene.h"
#include "solver/render/ray_scene.h"
#include "tools/common/image.h"

namespace igi::render {

struct RenderOptions {
  int spp = 64;             // samples (paths) per pixel, >= 1
  uint64_t seed = 0;        // same seed -> same image
  int max_bounces = 64;     // path length cap (Russian roulette ends paths long before)
  int rr_start_bounce = 3;  // Russian roulette from this bounce on (unbiased)
  int num_threads = 0;      // 0 = the process default (--threads), 0 there = all cores
  int width = 0;            // output size; 0 = the camera's. Another size rescales the
  int height = 0;           // intrinsics (same field of view).
  bool show_progress = true;
  // When set: one value per output pixel (row-major), and only the pixels whose value is nonzero
  // are rendered; the others are NaN. A pixel's value does not depend on which others are
  // rendered (each has its own random streams), so parts rendered separately equal one render.
  const std::vector<uint8_t>* pixel_mask = nullptr;

  // Throws InputError naming the field and the rule.
  void Validate() const;
};

struct RenderSummary {
  double seconds = 0;
  uint64_t camera_rays = 0;
  uint64_t rays = 0;  // all rays traced (camera, bounce and shadow rays)
  double RaysPerSecond() const { return seconds > 0 ? double(rays) / seconds : 0.0; }
};

// One lighting of a scene, ready to render from any camera: the Embree scene, materials with
// textures loaded, and the lighting's emitters. Build once, render many cameras.
class Renderer {
 public:
  // `scene` must have complete materials (SceneLoadOptions::require_complete_materials) and
  // outlive the renderer. Throws InputError when the lighting has no light and the scene no
  // emitter material, or a texture cannot be read.
  Renderer(const recon::Scene& scene, int lighting);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders `camera`'s view (linear radiance, RGB).
  Image Render(const recon::Camera& camera, const RenderOptions& options,
               RenderSummary* summary = nullptr) const;

  // Radiance arriving along one ray (world frame), estimated with `spp` paths; for tests and
  // the solver.
  Eigen::Vector3d Radiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, int spp,
                           uint64_t seed) const;

  // Radiance reflected toward `origin` by the first surface along the ray, the emission of
  // whatever the ray meets first (a light, an emitter) left out: the light a surface at
  // `origin` receives from that direction by reflection (the solver's indirect light).
  Eigen::Vector3d ReflectedRadiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                    int spp, uint64_t seed) const;
  // The same (the same paths and value), and in `d_ln_params` its derivatives with respect to
  // the logarithm of a scale applied to each region's (scene material's) parameters, per
  // channel: kDerivativeKinds entries per region, region-major — its diffuse albedo (map
  // included), its ρs, and its roughness (α, or αx and αy together). Each is the part of the
  // radiance whose paths reflect off the region, weighted at each such reflection by the share
  // of the BRDF value (or ∂ln f) that the parameter makes. The inverse solver's joint
  // refinement uses them (solver/inverse/refine_stage.cpp).
  static constexpr int kDerivativeKinds = 3;
  enum DerivativeKind { kLnRhoD = 0, kLnRhoS = 1, kLnAlpha = 2 };
  Eigen::Vector3d ReflectedRadiance(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                    int spp, uint64_t seed,
                                    std::vector<Eigen::Vector3d>* d_ln_params) const;

  // Ray queries on the scene this renderer traces.
  const RayScene& rays() const { return rays_; }

 private:
  RayScene rays_;
};

}  // namespace igi::render
