#pragma once
// Mitsuba 3 export (ExportFormat::kMitsuba): scene_<L>.xml per lighting L (every camera as a
// sensor, the lights of L as emitters), meshes/<region>.obj (v, vt, vn: Mitsuba flips OBJ's v so
// that v = 0 is an image's bottom row, as in igi), textures/<region>.exr (linear, raw).
//
// BSDFs (each wrapped in `twosided`, as igi's renderer shades both sides):
//   lambert -> diffuse (exact); black -> diffuse 0; emitter -> an `area` emitter on its shape.
//   Models with a lobe -> roughplastic, distribution ggx for the ggx models and beckmann for the
//     others: int_ior η with ((η−1)/(η+1))² = mean ρs (clamped to [1e-4, 0.5]); alpha and
//     specular_reflectance = k·ρs/mean ρs from the fit of the lobe by
//     k·F_dielectric(η)·D·G1(wi)·G1(wo)/(4 cosθi cosθo) (ward_fit.h, kGgxDielectric or
//     kBeckmannDielectric; the error is reported). A microfacet lobe keeps its distribution; what
//     the fit absorbs is Mitsuba's exact dielectric Fresnel term against igi's Schlick factor and
//     its separable Smith term against igi's height-correlated one. diffuse_reflectance = rho_d (or
//     a bitmap of rho_d_map); Mitsuba's roughplastic scales its diffuse term by the Fresnel
//     transmittances and internal reflection, which is not compensated (reported). Anisotropy is
//     dropped.
// Emitters: point -> point (intensity); spot -> spot along `direction` (cone: beam_width =
//   inner_deg, cutoff_angle = outer_deg; cos_power / IES: the 90% and 10% angles; without a
//   profile -> point); directional -> directional (irradiance); sphere -> sphere shape with an
//   area emitter (radiance, exact); area -> its mesh as meshes/light.<name>.obj with an area
//   emitter (exact: front = CCW).
// Sensors: perspective with fov_axis x, fov = 2 atan(W / 2fx) degrees, principal_point_offset
//   from cx, cy, an hdrfilm of the camera's size and a box filter; fx ≠ fy and OPENCV
//   distortion are dropped (reported). Integrator: path, max_depth −1.

#include <filesystem>

#include "recon/scene.h"
#include "solver/export/export.h"

namespace igi::exporter {

void WriteMitsubaExport(const recon::Scene& scene, const ExportOptions& options,
                        const std::filesystem::path& dir, ExportReport* report);

}  // namespace igi::exporter
