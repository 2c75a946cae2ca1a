#pragma once
// Internal to igi_solver: gathering the light that arrives at surface points (Yu et al. 1999 §4:
// "gathering over the other patches and the known lights, its irradiance").
//
// For each query point the gather keeps the incident samples, not only their sum, so that the
// solver can re-weight them with any BRDF (the specular term) and re-evaluate the light leaving
// the patches they hit after each refit (the "specular differences"):
//  - direct samples toward the lighting's lights (stratified over extended lights, shadow rays
//    through Embree), each with value = L_light·cosθ/(pdf·K): their sum is the direct irradiance;
//  - indirect samples over the hemisphere (stratified cosine-weighted, mixed with a Ward lobe
//    around the mirror direction where a specular fit needs them), each with the patch it hits
//    and weight = cosθ/(pdf_mix·N): the irradiance is Σ weight·L(patch → point);
//  - where an indirect ray meets a surface with a specular lobe, one "specular bounce": a
//    direction drawn about the mirror of the ray there and the patch it meets, so that the light
//    the glossy surface reflects specularly from the rest of the scene toward the point (its
//    lobe times the diffuse radiance of that patch) joins the patch's radiance. Without it a
//    glossy patch sends only its diffuse radiance and the direct light's highlight, and every
//    point it lights gathers too little (2 % of the irradiance of igi-synth's ceiling).
// World frame, unit directions from the point toward where the light comes from.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "solver/inverse/patches.h"
#include "solver/render/ray_scene.h"
#include "solver/render/sampling.h"

namespace igi::solver {

struct DirectSample {
  Eigen::Vector3f wi = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f value = Eigen::Vector3f::Zero();  // L·cosθ/(pdf·K), W·m⁻² per channel
};

struct IndirectSample {
  Eigen::Vector3f wi = Eigen::Vector3f::UnitZ();
  float weight = 0;  // cosθ/(pdf·N), sr... so that E = Σ weight·L
  int patch = -1;    // the patch the ray hits; -1: nothing reflective (escaped, light, emitter)
  int bounce = -1;   // index into GatherSet::bounces where the hit has a specular lobe, else -1
};

// A specular bounce at an indirect ray's glossy hit, in the hit's local shading frame (z = the
// shading normal, x = the region's tangent where it is anisotropic): the specular radiance it
// sends back along the ray is ρs·S·W(wo, wi)·weight·L(patch → hit).
struct SpecularBounce {
  Eigen::Vector3f wo = Eigen::Vector3f::UnitZ();  // toward the gathering point
  Eigen::Vector3f wi = Eigen::Vector3f::UnitZ();  // the bounce ray's direction
  float weight = 0;  // cosθ/pdf of the one-sample mixture (cosine, Ward 0.2 and 0.05 lobes)
  int patch = -1;    // the patch the bounce ray meets; -1: nothing reflective
};

struct GatherQuery {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_geo = Eigen::Vector3d::UnitZ();  // face normal on the lit side
  Eigen::Vector3d n_s = Eigen::Vector3d::UnitZ();    // shading normal on the same side
  Eigen::Vector3d view = Eigen::Vector3d::Zero();    // toward the viewer; zero = none
  bool lobe = false;  // mix Ward-lobe directions around the view's mirror into the hemisphere
  // The photo pixel behind the query, where it is an observation (else absent). A pixel records
  // the mean radiance over the surface it covers (a camera's sensor and igi-render's box filter
  // alike), not the radiance where its centre ray lands; where the light changes within a pixel
  // (the falloff and cosine of a nearby lamp, a shadow's edge, a highlight) the two differ (3 %
  // on the floor of a 64×48 test room). So the direct light is sampled over the footprint: its
  // points are where the rays eye + t·(ray00 + u·ray_du + v·ray_dv), u, v in [0, 1), meet the
  // plane through `position` with normal n_geo (exact for a pinhole camera, whose ray
  // directions are affine in the pixel coordinates, scaled to unit depth).
  struct Footprint {
    Eigen::Vector3d eye = Eigen::Vector3d::Zero();
    Eigen::Vector3d ray00 = Eigen::Vector3d::Zero();
    Eigen::Vector3d ray_du = Eigen::Vector3d::Zero();
    Eigen::Vector3d ray_dv = Eigen::Vector3d::Zero();
  };
  std::optional<Footprint> footprint;
  // The surface point at (u, v) of the footprint; `position` without one (or where the plane
  // cannot be met in front of the eye).
  Eigen::Vector3d FootprintPoint(double u, double v) const;
};

struct GatherPoint {
  Eigen::Vector3f e_direct = Eigen::Vector3f::Zero();  // Σ direct values
  // Ranges in GatherSet::direct and ::indirect: 64-bit, as a lighting's records exceed 2³¹ from
  // about 33 M observations at 64 hemisphere rays.
  int64_t direct_begin = 0, direct_end = 0;
  int64_t indirect_begin = 0, indirect_end = 0;
};

struct GatherSet {
  std::vector<GatherPoint> points;  // one per query, same order
  std::vector<DirectSample> direct;
  std::vector<IndirectSample> indirect;
  std::vector<SpecularBounce> bounces;
  uint64_t rays = 0;
  double seconds = 0;
};

struct GatherOptions {
  int light_samples = 16;  // per extended light (delta lights take one)
  // Per delta light (point, spot, directional) at a query with a footprint: the points of the
  // pixel it is sampled at (stratified). Extended lights spread their light_samples over it.
  int footprint_samples = 4;
  // Stratified hemisphere rays per query for the light arriving from other surfaces.
  int indirect_rays = 64;
  double lobe_alpha = 0.2;       // roughness of the mixed-in Ward lobe
  bool specular_bounces = true;  // trace a specular bounce at each glossy indirect hit
  // Seed of the random numbers: each query has its own stream, whatever the threads.
  uint64_t seed = 1;
  // Worker threads; 0 = the process default.
  int num_threads = 0;
  // A progress bar with its label (tools/common/progress.h) on a terminal; empty: none.
  std::string progress_label;
};

// Hemisphere directions for a query: stratified cosine-weighted, half of them from a Ward lobe
// (roughness lobe_alpha) around the view's mirror direction when q.lobe; each with its weight
// cosθ/(pdf_mix·n). Directions under the face (q.n_geo) are dropped.
struct WeightedDirection {
  Eigen::Vector3d wi;
  double weight = 0;
};
std::vector<WeightedDirection> HemisphereDirections(const GatherQuery& q, int n, double lobe_alpha,
                                                    render::Pcg32& rng);

GatherSet Gather(const render::RayScene& scene, const PatchSet& patches,
                 const std::vector<GatherQuery>& queries, const GatherOptions& options);

// The direct light at one query point alone (Gather's direct samples for it): appends its
// samples to *samples and returns their sum, the direct irradiance.
Eigen::Vector3f GatherDirectAt(const render::RayScene& scene, const GatherQuery& query,
                               int light_samples, int footprint_samples, render::Pcg32& rng,
                               std::vector<DirectSample>* samples);

}  // namespace igi::solver
