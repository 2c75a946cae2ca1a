#pragma once
// The peer of the ray-throughput benchmark: a minimal path tracer written directly on Embree 3
// (rtcIntersect1 / rtcOccluded1, single-precision, no shading beyond what decides where rays
// go). It traces the same kind of rays as igi's Renderer on the same scene:
//   - one camera ray per pixel sample (pinhole, jittered in the pixel);
//   - at every surface hit, one shadow ray (rtcOccluded1) toward a point sampled on one of the
//     lighting's lights (chosen uniformly), when that point is above the surface;
//   - then one cosine-distributed bounce ray around the face normal, with the path throughput
//     multiplied by the hit triangle's albedo (rho_d + rho_s), Russian roulette from
//     `rr_start_bounce` on with survival probability min(0.95, max throughput), as igi does.
// A path ends when a ray escapes or hits an emitter (sphere or area light).
// "Rays" = calls of rtcIntersect1 plus calls of rtcOccluded1, the same definition as
// RenderSummary::rays.

#include <cstdint>
#include <memory>

#include "recon/scene.h"

namespace igi::bench {

struct RawTraceOptions {
  int spp = 16;
  int rr_start_bounce = 3;
  int max_bounces = 64;
  int num_threads = 0;
  uint64_t seed = 1;
};

struct RawTraceSummary {
  double seconds = 0;
  uint64_t rays = 0;
  uint64_t shadow_rays = 0;
  double RaysPerSecond() const { return seconds > 0 ? double(rays) / seconds : 0.0; }
};

class RawEmbreeTracer {
 public:
  // Builds its own Embree scene (scene mesh, lighting's area-light meshes and, when
  // `embree_spheres`, sphere lights as Embree point-spheres; otherwise they are intersected
  // analytically in float after rtcIntersect1, as igi does in double) with the same build
  // quality as the Renderer.
  RawEmbreeTracer(const recon::Scene& scene, int lighting, bool embree_spheres = false);
  ~RawEmbreeTracer();
  RawEmbreeTracer(const RawEmbreeTracer&) = delete;
  RawEmbreeTracer& operator=(const RawEmbreeTracer&) = delete;

  RawTraceSummary Trace(const recon::Camera& camera, const RawTraceOptions& options) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace igi::bench
