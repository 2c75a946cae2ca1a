#include "solver/inverse/albedo_map_stage.h"

#include <algorithm>
#include <string>

#include "solver/render/sampling.h"

namespace igi::solver {

MapLight MapLightOf(const MapStageData& d) {
  const SolveOptions& o = d.options;
  const LightModel& light = d.light;
  const double radius = o.smoothing_radius_m > 0 ? o.smoothing_radius_m : d.scene_scale_m / 96;
  MapLight out;
  std::vector<Eigen::Vector3d> t0_direct;
  const std::vector<Eigen::Vector3d> t_direct =
      DirectSpecularTerms(d.scene, d.obs, d.materials, light, o.num_threads, &t0_direct);
  const bool offsets = light.t0.size() == d.obs.size();
  std::vector<Eigen::Vector3d> t_indirect(d.obs.size()), t0_indirect(d.obs.size());
  for (size_t i = 0; i < d.obs.size(); ++i) {
    t_indirect[i] = light.t[i] - t_direct[i];
    t0_indirect[i].setZero();
    if (offsets) t0_indirect[i] = light.t0[i] - t0_direct[i];
  }
  out.t_indirect =
      NeighbourMean(d.obs, light.lightings, t_indirect, d.scene_scale_m / 96, true, o.num_threads);
  out.t0_indirect =
      NeighbourMean(d.obs, light.lightings, t0_indirect, d.scene_scale_m / 96, true, o.num_threads);
  out.t.resize(d.obs.size());
  out.t0.resize(d.obs.size());
  for (size_t i = 0; i < d.obs.size(); ++i) {
    out.t[i] = (t_direct[i] + out.t_indirect[i]).cwiseMax(0.0);
    out.t0[i] = (t0_direct[i] + out.t0_indirect[i]).cwiseMax(0.0);
  }
  const bool have_stage1 = light.e_stage1.size() == d.obs.size() && d.stage2_iterations > 0;
  if (!have_stage1 || !IsJointUpdate(o.refine_update)) {
    out.e = light.e;
  } else if (!d.refinement_accepted) {
    out.e = light.e_stage1;
  } else {
    const std::vector<Eigen::Vector3d> now =
        NeighbourMean(d.obs, light.lightings, light.e, 4 * radius, false, o.num_threads);
    const std::vector<Eigen::Vector3d> then =
        NeighbourMean(d.obs, light.lightings, light.e_stage1, 4 * radius, false, o.num_threads);
    out.e = light.e;
    for (size_t i = 0; i < d.obs.size(); ++i) {
      if (!(then[i].minCoeff() > 0) || !now[i].allFinite()) continue;
      out.e[i] = light.e_stage1[i].cwiseProduct(now[i].cwiseQuotient(then[i]));
    }
  }
  // On a region whose diffuse term is not Lambert's the maps divide by its column
  // Σ DiffuseFactor(wo, wi_k)·v_k over the observation's incident list (Oren–Nayar's A·E + B·G),
  // not by E, taken at the level of the E above (the list sums to the unsmoothed E).
  for (size_t i = 0; i < d.obs.size() && i < light.incident.size(); ++i) {
    const Observation& o = d.obs[i];
    const render::BrdfParams& p = d.materials[o.region].params;
    if (p.diffuse == recon::DiffuseShape::kLambert) continue;
    const Eigen::Vector3d wo =
        d.materials.LocalFrame(o.region, o.normal.cast<double>()).ToLocal(o.view.cast<double>());
    Eigen::Vector3d column = Eigen::Vector3d::Zero(), sum = column;
    for (const IncidentLocal& inc : light.incident[i]) {
      const Eigen::Vector3d v = inc.Value().cast<double>(), wi = inc.Wi().cast<double>();
      sum += v;
      if (wo.z() > 0 && wi.z() > 0) column += render::DiffuseFactor(p, wo, wi) * v;
    }
    for (int c = 0; c < 3; ++c) {
      if (sum[c] > 0) out.e[i][c] *= column[c] / sum[c];
    }
  }
  return out;
}

bool MapAllowed(const MapStageData& d, size_t r) {
  const std::vector<std::string>& only = d.options.albedo_map_regions;
  return d.options.albedo_maps != AlbedoMaps::kNone &&
         (only.empty() ||
          std::find(only.begin(), only.end(), d.scene.materials[r].name) != only.end());
}

bool MapCandidate(const MapStageData& d, size_t r) {
  const MaterialState& m = d.materials[r];
  return m.reflective && m.unknown_rho_d && m.observations > 0 && MapAllowed(d, r);
}

RegionAtlas MapAtlas(const MapStageData& d, int r) {
  AtlasOptions ao;
  ao.texel_size_m = d.texel_size_m;
  return BuildRegionAtlas(d.scene.mesh, r, ao);
}

namespace {

// Adds region r's observations (of the photos of parity photo_parity, or all with -1) to
// `builder`: π(L − ρs·T)/E, each weighted by its diffuse share.
void AddObservations(const MapStageData& d, int r, const MapLight& light, int photo_parity,
                     AlbedoMapBuilder* builder) {
  const MaterialState& m = d.materials[r];
  for (size_t i = 0; i < d.obs.size(); ++i) {
    const Observation& o = d.obs[i];
    if (o.region != r) continue;
    if (photo_parity >= 0 && o.photo % 2 != photo_parity) continue;
    const Eigen::Vector3d spec = m.params.rho_s.cwiseProduct(light.t[i]) + light.t0[i];
    const Eigen::Vector3d diffuse = o.radiance.cast<double>() - spec;
    // Highlights tell little about the albedo and much about any error in the fitted lobe:
    // weight each observation by its diffuse share, and leave out those under half diffuse.
    // (from the model, not the observation: a test on the observed radiance would favour the
    // bright texels near highlights)
    const double diffuse_pred =
        (d.materials.PatchAlbedo(d.patches, o.patch).cwiseProduct(light.e[i]) / render::kPi).sum();
    const double share = diffuse_pred / std::max(1e-12, diffuse_pred + spec.sum());
    const double w = std::clamp(2.0 * share - 1.0, 0.0, 1.0);
    if (!(w > 0)) continue;
    // No cut on the observation's own albedo πd/E: a photo's noise has a long upper tail (a few
    // paths per pixel), and leaving out what exceeds a bound darkens the map (the demo's 8-spp
    // floor: −4.5 % with observations above 1.2 left out). The texel is a ratio of sums weighted
    // by E, so an E taken at the pixel's centre that differs from its footprint's (a shadow edge)
    // evens out over the texel's observations instead of dominating.
    const Eigen::Vector3d& e_i = light.e[i];
    if (!(e_i.minCoeff() > 0)) continue;
    builder->Add(o.triangle, o.b1, o.b2, w * render::kPi * diffuse.cwiseProduct(m.map_scale),
                 w * e_i);
  }
}

}  // namespace

Image AlbedoMapOf(const MapStageData& d, int r, const RegionAtlas& atlas, const MapLight& light,
                  double* coverage, Image* seen, int photo_parity) {
  AlbedoMapBuilder builder(atlas);
  AddObservations(d, r, light, photo_parity, &builder);
  if (coverage != nullptr) *coverage = builder.Coverage();
  if (seen != nullptr) *seen = builder.DirectMask();
  return builder.Finish(d.materials[r].params.rho_d);
}

Image RefinementAlbedoMap(const MapStageData& d, int r, const RegionAtlas& atlas,
                          const MapLight& light) {
  AlbedoMapBuilder builder(atlas);
  AddObservations(d, r, light, -1, &builder);
  builder.FillTexelCentres([&](int triangle, double b1, double b2) {
    return d.materials.PatchAlbedo(d.patches, d.patches.PatchOf(triangle, b1, b2));
  });
  return builder.Finish(d.materials[r].params.rho_d);
}

bool WritesMap(const MapStageData& d, size_t r, const RegionAtlas& atlas, const MapLight& light,
               TexelDetail* detail) {
  const MaterialState& m = d.materials[r];
  if (!MapCandidate(d, r)) return false;
  if (d.options.albedo_maps == AlbedoMaps::kAll || m.last_fit.albedo_varies) return true;
  Image map[2], seen[2];
  for (int k = 0; k < 2; ++k) {
    map[k] = AlbedoMapOf(d, int(r), atlas, light, nullptr, &seen[k], k);
  }
  std::vector<int> both;  // the texels both halves estimate directly (y·width + x)
  for (int y = 0; y < seen[0].height; ++y) {
    for (int x = 0; x < seen[0].width; ++x) {
      if (seen[0].at(x, y, 0) > 0.5f && seen[1].at(x, y, 0) > 0.5f) {
        both.push_back(y * seen[0].width + x);
      }
    }
  }
  const TexelDetail t = SharedTexelDetail(map[0], map[1], both);
  if (detail) *detail = t;
  return t.variation > kTexelTextureMin && t.z > kTexelTextureZ;
}

}  // namespace igi::solver
