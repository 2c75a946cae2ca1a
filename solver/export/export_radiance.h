#pragma once
// RADIANCE export (ExportFormat::kRadiance). Files, relative to the output folder:
//   scene.rad            one material per region, then one `polygon` per triangle grouped per
//                        region (no external tools needed: `oconv scene.rad lighting_L0.rad`);
//   lighting_<L>.rad     the lights of lighting L;
//   <camera>.vf          one view per camera (`rview -vtv -vp -vd -vu -vh -vv -vs -vl`).
//
// Materials (docs/scene-format.md → RADIANCE; "exact" = the same BRDF):
//   lambert             plastic R G B 0 0 with RGB = rho_d                               exact
//   black               plastic 0 0 0 0 0                                                exact
//   emitter             light R G B = radiance                                           exact
//   ward_gmd, grey ρs   plastic RGB = rho_d/(1−ρs), spec = ρs, rough = alpha              exact
//   ward_gmd, ρs ∝ ρd   metal (specular coloured by RGB): spec = t/(1+t) with t = ρs/ρd,
//                       RGB = rho_d/(1−spec)                                             exact
//   ward_gmd, other ρs  plastic with spec = mean(ρs) (RADIANCE cannot colour a plastic's
//                       highlight independently); the report gives the ρs colour error
//   ward_gmd_aniso      plastic2 (metal2 when ρs ∝ ρd) with the tangent as the u vector,
//                       urough = alpha_x, vrough = alpha_y                               exact
//   ward, *_fresnel     the lobe fitted by ward_gmd (ward_fit.h): rough = fitted alpha,
//                       spec = fitted scale·ρs; the report gives the fitted error
//   ward_aniso          both roughnesses scaled by the isotropic fit's alpha ratio
//   rho_d_map           the region mean albedo (a `colorpict` on per-triangle polygons would need
//                       per-polygon UV functions); a comment line in scene.rad says so
// Polygons are flat: vertex normals are dropped (reported when the mesh had smooth normals).
//
// Lights (a `light` material's value is radiance, W·sr⁻¹·m⁻²):
//   sphere        light + sphere                                                         exact
//   point         light sphere of radius r = point_light_radius_m with radiance I/(π r²):
//                 the same intensity I in every direction at distances ≫ r
//   spot          spotlight on such a sphere, axis = direction; full cone angle: cone profile
//                 inner_deg + outer_deg (RADIANCE's cut-off is hard), cos_power n: twice the
//                 half-power angle acos(0.5^(1/n)); IES: a comment names the .ies file (convert
//                 it with RADIANCE's ies2rad) and a spotlight of the half-peak angle stands in
//   directional   source toward −direction, apparent diameter source_angle_deg, radiance
//                 E/Ω with Ω = 2π(1 − cos(angle/2)) so the irradiance is E
//   area          light + one polygon per triangle (same winding: front = CCW)       exact
// Cameras: PINHOLE exact (-vh/-vv from fx/fy, -vs/-vl from the principal point); OPENCV drops
// the distortion (reported).

#include <filesystem>

#include "recon/scene.h"
#include "solver/export/export.h"

namespace igi::exporter {

void WriteRadianceExport(const recon::Scene& scene, const ExportOptions& options,
                         const std::filesystem::path& dir, ExportReport* report);

}  // namespace igi::exporter
