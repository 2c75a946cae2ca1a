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
// Ids: the camera, region or light name made safe (SafeName), "_2", "_3", ... appended where two
// objects would share one; a region's BSDF is "bsdf.<region id>".
//
// MitsubaSceneDict gives the scene of one lighting as a mitsuba.load_dict dictionary. Both
// outputs are rendered from one description of the scene's Mitsuba objects, so every object,
// property name and value of scene_<L>.xml is in the dict:
//   {"type": "scene", "integrator": {...}, <id>: {"type": <plugin>, <property>: <value>, ...}}
// with floats, integers, booleans and strings as JSON values; rgb as {"type": "rgb", "value":
// [r, g, b]}; points and vectors as [x, y, z]; to_world as {"type": "transform", "matrix":
// 4x4 rows} (Mitsuba's look_at of the XML's lookat, row-major; mitsuba.ScalarTransform4f of it);
// a nested object under its name (textures) or its tag ("bsdf", "emitter", "sampler", "film",
// "rfilter"); the XML's <ref id="X"/> as "bsdf": {"type": "ref", "id": "X"}; filenames absolute.

#include <filesystem>

#include "recon/scene.h"
#include "solver/export/export.h"
#include "tools/common/json.h"

namespace igi::exporter {

void WriteMitsubaExport(const recon::Scene& scene, const ExportOptions& options,
                        const std::filesystem::path& dir, ExportReport* report);

// The Mitsuba 3 scene of lighting `lighting` (an index into scene.lightings) as a load_dict
// dictionary (above). The meshes and textures it names are written into `dir` (created when
// absent; files of the same names there are replaced, each written to a temporary name and
// renamed) as the XML export writes them: meshes/<region>.obj, meshes/light.<name>.obj for the
// lighting's area lights, textures/<region>.exr. Validates `options` and requires complete
// materials (CheckExportableScene) first; InputError for a lighting out of range or a `dir`
// that is a file. Approximations and files go to `report`.
Json MitsubaSceneDict(const recon::Scene& scene, int lighting, const ExportOptions& options,
                      const std::filesystem::path& dir, ExportReport* report);

}  // namespace igi::exporter
