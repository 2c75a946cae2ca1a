#include "solver/inverse/fit_inputs.h"

namespace igi::solver {

std::vector<RegionFitInput> FitInputs(const recon::Scene& scene, const PatchSet& patches,
                                      const ObservationSet& obs, const LightModel& light,
                                      const MaterialEstimate& materials, int stage,
                                      const SolveOptions& options, std::vector<int>* regions) {
  const bool grey_specular = options.specular_colour == SpecularColour::kGrey;
  regions->clear();
  for (size_t r = 0; r < materials.size(); ++r) {
    if (materials[r].NeedsFit() && materials[r].observations > 0) regions->push_back(int(r));
  }
  std::vector<RegionFitInput> inputs(regions->size());
  for (size_t k = 0; k < regions->size(); ++k) {
    const int r = (*regions)[k];
    const MaterialState& m = materials[r];
    RegionFitInput& in = inputs[k];
    in.name = scene.materials[r].name;
    in.model = m.params.model;
    in.fit_rho_d = m.unknown_rho_d;
    in.grey_specular = grey_specular;
    if (m.no_highlight) {
      in.rho_s_grey = 0.0;
    } else if (!m.unknown_rho_s) {
      in.rho_s_rgb = m.params.rho_s;
    }
    if (!m.unknown_alpha || m.no_highlight) {
      in.alpha = m.params.alpha;
      in.alpha_x = m.params.alpha_x;
      in.alpha_y = m.params.alpha_y;
    }
    in.ior = m.params.ior;
    in.diffuse = m.params.diffuse;
    if (!m.unknown_sigma) in.sigma = m.params.sigma;
    if (m.last_fit.fitted && recon::HasSpecularLobe(m.params.model)) in.alpha_hint = m.params.alpha;
    if (stage == 2 && m.last_fit.fitted) in.albedo_varies = m.stage1_albedo_varies;
    if (options.uniform_albedo) in.albedo_varies = false;
    in.use_held_albedo = options.held_out_albedo;
    in.num_slots = static_cast<int>(materials.region_patches[r].size());
    for (int q : materials.region_patches[r]) in.slot_area.push_back(patches.area[q]);
  }
  std::vector<int> index_of(materials.size(), -1);
  for (size_t k = 0; k < regions->size(); ++k) index_of[(*regions)[k]] = int(k);
  std::vector<size_t> samples(regions->size(), 0);
  for (size_t i = 0; i < obs.size(); ++i) {
    if (obs.in_fit[i] && index_of[obs[i].region] >= 0) ++samples[index_of[obs[i].region]];
  }
  for (size_t k = 0; k < regions->size(); ++k) inputs[k].samples.reserve(samples[k]);
  for (size_t i = 0; i < obs.size(); ++i) {
    const Observation& o = obs[i];
    if (!obs.in_fit[i] || index_of[o.region] < 0) continue;
    RegionFitInput& in = inputs[index_of[o.region]];
    FitSample s;
    s.observed = o.radiance.cast<double>();
    s.irradiance = light.e[i];
    s.rho_d_known = in.fit_rho_d ? Eigen::Vector3d::Zero() : materials.KnownAlbedo(scene.mesh, o);
    s.slot = materials.patch_slot[o.patch];
    if (i < materials.held_rho_d.size()) {  // (HeldOutAlbedos ran: else NaN, unknown)
      s.rho_d_held = materials.held_rho_d[i];
      s.held_lobe = materials.held_lobe[i];
    }
    s.wo = materials.LocalFrame(o.region, o.normal.cast<double>())
               .ToLocal(o.view.cast<double>())
               .cast<float>();
    s.lobe_blur2 = o.lobe_blur2;
    s.incident = light.incident[i].data();  // read in place: the fit copies nothing
    s.incident_count = int64_t(light.incident[i].size());
    if (i < light.incident_direct.size()) s.incident_rays_from = light.incident_direct[i];
    in.samples.push_back(s);
  }
  return inputs;
}

}  // namespace igi::solver
