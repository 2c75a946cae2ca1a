#pragma once
// Internal to igi_solver: the solve's estimate of every region's material (what is known and
// what is being fitted, the current values, the per-patch albedos of a region fitted per patch),
// the patches' grouping by region, and the held-out albedos the fits of textured glossy regions
// read (solver/inverse/held_out_albedo.h).

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "recon/scene.h"
#include "solver/inverse/observation_set.h"
#include "solver/inverse/patches.h"
#include "solver/inverse/region_fit.h"
#include "solver/inverse/uv_charts.h"
#include "solver/render/brdf.h"
#include "solver/render/sampling.h"
#include "tools/common/image.h"

namespace igi::solver {

struct MaterialState {
  render::BrdfParams params;  // complete: known values, or the current estimate
  bool reflective = false;
  bool unknown_rho_d = false, unknown_rho_s = false, unknown_alpha = false;
  bool unknown_sigma = false;  // Oren–Nayar's σ (diffuse oren_nayar without "sigma")
  bool no_highlight = false;   // ρs and α cannot be recovered: ρs is held at 0
  std::optional<Eigen::Vector3d> tangent;
  std::shared_ptr<const Image> known_map;    // a known rho_d_map
  std::vector<Eigen::Vector3d> patch_rho_d;  // per region slot; NaN = the region's rho_d
  RegionFitResult last_fit;
  bool stage1_albedo_varies = false;  // stage 1's decision, kept by the refinement
  // Factor applied to the albedo map built from the observations' πL/E (AlbedoMapOf): the
  // refinement's update of the region's scale (1 unless a stage-2 round moved its mean away
  // from its independent refit: the joint update, or a partial step).
  Eigen::Vector3d map_scale = Eigen::Vector3d::Ones();
  int observations = 0;
  // A region no photo sees whose ρd was fitted to the light it bounces onto the seen regions
  // (FitUnobservedAlbedos in solver/inverse/paper_stage.h): its relative uncertainty per channel
  // (NaN: not fitted).
  Eigen::Vector3d bounce_fit_sigma = Eigen::Vector3d::Constant(NAN);
  bool NeedsFit() const {
    return reflective && (unknown_rho_d || unknown_rho_s || unknown_alpha || unknown_sigma);
  }
  // Whether the region's observations keep their incident lists for the fits: a lobe's, or any
  // diffuse term but Lambert's, depends on the directions the light comes from.
  bool KeepsIncident() const {
    return recon::HasSpecularLobe(params.model) || params.diffuse != recon::DiffuseShape::kLambert;
  }
};

struct MaterialEstimate {
  std::vector<MaterialState> regions;            // per scene material
  std::vector<std::vector<int>> region_patches;  // per region: its patches (slot order)
  std::vector<int> patch_slot;                   // per patch: index within its region
  // Per observation of a textured glossy region: the other photos' observations off the
  // highlights at the albedo map's texel (solver/inverse/held_out_albedo.h): their πL/E and their
  // lobe per unit ρs, πT/E (the albedo is the first less ρs times the second); NaN elsewhere.
  std::vector<Eigen::Vector3d> held_rho_d, held_lobe;
  std::vector<std::unique_ptr<RegionAtlas>> held_atlases;  // per region, built when needed

  // The scene's materials as the solve starts: known values as given, unknowns at a
  // placeholder (ρd 0.5, ρs 0, α 0.1), every patch of `patches` in its region's slots.
  static MaterialEstimate FromScene(const recon::Scene& scene, const PatchSet& patches);

  size_t size() const { return regions.size(); }
  MaterialState& operator[](size_t r) { return regions[r]; }
  const MaterialState& operator[](size_t r) const { return regions[r]; }
  std::vector<MaterialState>::iterator begin() { return regions.begin(); }
  std::vector<MaterialState>::iterator end() { return regions.end(); }
  std::vector<MaterialState>::const_iterator begin() const { return regions.begin(); }
  std::vector<MaterialState>::const_iterator end() const { return regions.end(); }

  // The frame a region's lobe is evaluated in at shading normal n (brdf.h): the material's
  // tangent for an anisotropic model.
  render::Frame LocalFrame(int region, const Eigen::Vector3d& n) const;
  // Patch q's albedo: its own where its region is fitted per patch, else its region's.
  Eigen::Vector3d PatchAlbedo(const PatchSet& patches, int q) const;
  // The given albedo at an observation: its region's map where it has one, else its ρd.
  Eigen::Vector3d KnownAlbedo(const recon::TriangleMesh& mesh, const Observation& o) const;
};

// For each glossy region with an unknown, varying albedo and a fitted lobe: every fit sample's
// albedo as the other photos see it off their highlights (modelled specular part ρs∘t + t0
// under 10 % of the modelled radiance in every channel), per texel of `texel_size_m`, into
// estimate->held_rho_d (of the radiance less t0) and held_lobe (solver/inverse/
// held_out_albedo.h). `e`, `t` and `t0`: per observation, its irradiance, its specular term per
// unit ρs and the lobe's part that ρs does not scale (LightModel::t0).
void HeldOutAlbedos(const ObservationSet& obs, const std::vector<Eigen::Vector3d>& e,
                    const std::vector<Eigen::Vector3d>& t, const std::vector<Eigen::Vector3d>& t0,
                    const recon::TriangleMesh& mesh, double texel_size_m,
                    MaterialEstimate* estimate);

}  // namespace igi::solver
