#include "solver/inverse/material_estimate.h"

#include "solver/inverse/held_out_albedo.h"
#include "solver/render/ray_scene.h"

namespace igi::solver {

MaterialEstimate MaterialEstimate::FromScene(const recon::Scene& scene, const PatchSet& patches) {
  MaterialEstimate out;
  const size_t n = scene.materials.size();
  out.regions.resize(n);
  for (size_t r = 0; r < n; ++r) {
    const recon::Material& m = scene.materials[r];
    MaterialState& s = out.regions[r];
    s.params.model = m.brdf;
    s.reflective = recon::IsReflective(m.brdf);
    if (!s.reflective) continue;
    const bool spec = recon::HasSpecularLobe(m.brdf), aniso = recon::IsAnisotropic(m.brdf);
    s.unknown_rho_d = !m.rho_d && !m.rho_d_map;
    s.unknown_rho_s = spec && !m.rho_s;
    s.unknown_alpha = spec && (aniso ? !(m.alpha_x && m.alpha_y) : !m.alpha);
    s.unknown_sigma = recon::HasSigma(m.diffuse) && !m.sigma;
    s.params.rho_d = m.rho_d.value_or(Eigen::Vector3d::Constant(0.5));
    s.params.rho_s = m.rho_s.value_or(Eigen::Vector3d::Zero());
    s.params.alpha = m.alpha.value_or(0.1);
    s.params.alpha_x = m.alpha_x.value_or(m.alpha.value_or(0.1));
    s.params.alpha_y = m.alpha_y.value_or(m.alpha.value_or(0.1));
    s.params.ior = m.ior.value_or(recon::Material::kDefaultIor);
    s.params.diffuse = m.diffuse;
    s.params.sigma = m.sigma.value_or(0.0);
    s.tangent = m.tangent;
    if (m.rho_d_map) s.known_map = std::make_shared<const Image>(ReadImage(*m.rho_d_map, 3));
  }
  out.region_patches.assign(n, {});
  out.patch_slot.assign(patches.size(), -1);
  for (int q = 0; q < patches.size(); ++q) {
    const int r = patches.patch_region[q];
    out.patch_slot[q] = static_cast<int>(out.region_patches[r].size());
    out.region_patches[r].push_back(q);
  }
  for (size_t r = 0; r < n; ++r) {
    out.regions[r].patch_rho_d.assign(out.region_patches[r].size(), Eigen::Vector3d::Constant(NAN));
  }
  return out;
}

render::Frame MaterialEstimate::LocalFrame(int region, const Eigen::Vector3d& n) const {
  const MaterialState& m = regions[region];
  if (recon::IsAnisotropic(m.params.model) && m.tangent)
    return render::Frame::FromNormalTangent(n, *m.tangent);
  return render::Frame::FromNormal(n);
}

Eigen::Vector3d MaterialEstimate::PatchAlbedo(const PatchSet& patches, int q) const {
  const int r = patches.patch_region[q];
  const Eigen::Vector3d& v = regions[r].patch_rho_d[patch_slot[q]];
  return v.allFinite() ? v : regions[r].params.rho_d;
}

Eigen::Vector3d MaterialEstimate::KnownAlbedo(const recon::TriangleMesh& mesh,
                                              const Observation& o) const {
  const MaterialState& m = regions[o.region];
  if (m.known_map && mesh.has_uvs()) {
    const Eigen::Vector3i& t = mesh.triangles[o.triangle];
    const Eigen::Vector2d uv =
        ((1.0f - o.b1 - o.b2) * mesh.uvs[t[0]] + o.b1 * mesh.uvs[t[1]] + o.b2 * mesh.uvs[t[2]])
            .cast<double>();
    return render::SampleTexture(*m.known_map, uv);
  }
  return m.params.rho_d;
}

// Kept as two parts, the held-out πL/E (held_rho_d) and the lobe those samples carry per unit
// ρs, πT/E (held_lobe): the albedo is their difference at the ρs being fitted, so that the fit
// takes ρs from both (solver/inverse/region_fit.h) instead of from the previous iteration.
void HeldOutAlbedos(const ObservationSet& obs, const std::vector<Eigen::Vector3d>& e,
                    const std::vector<Eigen::Vector3d>& t, const std::vector<Eigen::Vector3d>& t0,
                    const recon::TriangleMesh& mesh, double texel_size_m,
                    MaterialEstimate* estimate) {
  estimate->held_rho_d.assign(obs.size(), Eigen::Vector3d::Constant(NAN));
  estimate->held_lobe.assign(obs.size(), Eigen::Vector3d::Constant(NAN));
  estimate->held_atlases.resize(estimate->size());
  for (size_t r = 0; r < estimate->size(); ++r) {
    const MaterialState& m = (*estimate)[r];
    if (!m.NeedsFit() || !m.unknown_rho_d || m.no_highlight ||
        !recon::HasSpecularLobe(m.params.model) || !m.last_fit.fitted ||
        !m.last_fit.albedo_varies || m.observations == 0) {
      continue;
    }
    std::unique_ptr<RegionAtlas>& atlas = estimate->held_atlases[r];
    if (!atlas) {
      AtlasOptions ao;
      ao.texel_size_m = texel_size_m;
      atlas = std::make_unique<RegionAtlas>(BuildRegionAtlas(mesh, int(r), ao));
    }
    HeldOutAlbedo held(*atlas), lobe(*atlas);
    for (size_t i = 0; i < obs.size(); ++i) {
      const Observation& o = obs[i];
      if (o.region != int(r)) continue;
      const Eigen::Vector3d spec = m.params.rho_s.cwiseProduct(t[i]) + t0[i];
      // Off the highlight by the model, not by the observation: a test on the observed radiance
      // would let noise that brightens a pixel pass and bias the albedo. The model's diffuse part
      // takes the region's mean albedo, not the patch's: a patch's albedo follows its texels
      // (and its own samples' noise), and a bright patch would pass more of its samples closer
      // to the highlight than a dark one, raising the held-out albedo where the lobe is fitted
      // (on the true floor texture with exact radiances, the patch's albedo moved rho_s by
      // several per cent, the region's mean by 0.2 %).
      const Eigen::Vector3d diffuse = m.params.rho_d.cwiseProduct(e[i]) / render::kPi;
      if ((spec.array() > 0.1 * (diffuse + spec).array()).any()) continue;
      // The lobe's part that ρs does not scale is known at the current α: taken off the radiance.
      held.Add(o.photo, o.triangle, o.b1, o.b2, render::kPi * (o.radiance.cast<double>() - t0[i]),
               e[i]);
      lobe.Add(o.photo, o.triangle, o.b1, o.b2, render::kPi * t[i], e[i]);
    }
    for (size_t i = 0; i < obs.size(); ++i) {
      const Observation& o = obs[i];
      if (o.region != int(r) || !obs.in_fit[i]) continue;
      estimate->held_rho_d[i] = held.At(o.photo, o.triangle, o.b1, o.b2);
      estimate->held_lobe[i] = lobe.At(o.photo, o.triangle, o.b1, o.b2);
    }
  }
}

}  // namespace igi::solver
