#include "solver/inverse/solve_memory.h"

#include <algorithm>

#include "solver/inverse/gather.h"
#include "solver/inverse/observations.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/solve_internal.h"
#include "solver/render/brdf.h"
#include "tools/common/memory.h"

namespace igi::solver {
namespace {

// The process before it holds anything of the solve: its libraries, the thread pool, the scene.
constexpr double kProcessBytes = 256.0 * 1024 * 1024;
// Per scene triangle and lighting: the renderer's shading record and Embree's geometry and BVH.
constexpr double kTriangleBytes = 256;

// Direct-light samples per gathered point: the largest over the photographed lightings.
double DirectSamples(const recon::Scene& scene, const SolveOptions& options) {
  double most = 1;
  for (const recon::Lighting& lighting : scene.lightings) {
    double n = 0;
    for (int index : lighting.lights) {
      const recon::Light& light = scene.lights[index];
      const bool delta = light.type == recon::LightType::kPoint ||
                         light.type == recon::LightType::kSpot ||
                         light.type == recon::LightType::kDirectional;
      if (light.type == recon::LightType::kAmbient) continue;
      n +=
          delta ? (options.pixel_footprint ? options.footprint_samples : 1) : options.light_samples;
    }
    most = std::max(most, n);
  }
  return most;
}

}  // namespace

double SolveMemoryBudgetBytes(const SolveOptions& options) {
  return options.memory_budget > 0 ? options.memory_budget * kGiB
                                   : double(DefaultMemoryBudgetBytes());
}

SolveMemoryEstimate EstimateSolveMemory(const recon::Scene& scene, const SolveOptions& options,
                                        int patches) {
  SolveMemoryEstimate e;
  e.budget_bytes = SolveMemoryBudgetBytes(options);
  const double direct = DirectSamples(scene, options);
  const double rays = options.indirect_rays;
  // One gathered point: its record, its direct samples, its hemisphere rays and (at glossy hits,
  // counted for every ray) their specular bounces.
  const double gathered = sizeof(GatherPoint) + direct * sizeof(DirectSample) +
                          rays * sizeof(IndirectSample) +
                          (options.specular_bounces ? rays * sizeof(SpecularBounce) : 0.0);
  // The observation, the solver's arrays per observation (fit flag, gather index, the lighting's
  // list, seven irradiance and albedo vectors, the smoothing radius, the incident list's header),
  // the gather's query and the neighbour means' temporaries.
  const double arrays = sizeof(Observation) + 1 + 4 + 4 + 7 * 24 + 4 + 24 + 200 + 64;
  e.observation_bytes = arrays + gathered;
  // On a region with a lobe: stage 1's incident list and stage 2's, both counted (the freed
  // lists of one size are not reused for the other's: the heap keeps them).
  const double stage2_rays = options.refine_iterations > 0
                                 ? std::max(options.refine_rays, options.refine_final_rays)
                                 : 0.0;
  e.lobe_observation_bytes =
      e.observation_bytes + (2 * direct + rays + stage2_rays) * sizeof(IncidentLocal);
  // A fitted one: three times stage 2's directions more, and its fit's lobe table (an entry per
  // incident sample, seven floats, for every region at once in the worst case).
  e.fitted_lobe_bytes = 3 * stage2_rays * sizeof(IncidentLocal) +
                        (direct + 4 * std::max(rays, stage2_rays)) * 7 * sizeof(float);

  double lightings = 0;
  for (const recon::Lighting& l : scene.lightings) lightings += l.lights.empty() ? 0.0 : 1.0;
  lightings = std::max(1.0, lightings);
  const double triangles = double(scene.mesh.triangles.size());
  e.fixed_bytes = kProcessBytes + triangles * kTriangleBytes * lightings +
                  patches * (gathered + 200) * lightings;
  double largest = 0;
  for (const recon::Photo& p : scene.photos) {
    const recon::Camera& cam = scene.cameras[p.camera];
    const double pixels = double(cam.width) * cam.height;
    largest = std::max(largest, pixels);
    const double report = std::min(pixels, double(kReportMaxSide) * kReportMaxSide);
    e.fixed_bytes += 3 * report * 3 * sizeof(float);  // photo, render, residual
  }
  // The photo as read (float RGB), its linearised copy, the mask as read (float) and kept (8-bit).
  e.photo_bytes = largest * (2 * 3 * sizeof(float) + sizeof(float) + 1);
  return e;
}

}  // namespace igi::solver
