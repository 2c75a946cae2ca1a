#pragma once
// glTF 2.0 export (ExportFormat::kGltf): scene.gltf + scene.bin, textures/<region>.png.
//
// Meshes: one mesh (one triangle primitive: POSITION, NORMAL, TEXCOORD_0 when the scene has UVs,
// uint32 indices) and one node per region with triangles, named after the region; each area
// light is an extra mesh "light.<name>" with an emissive material. glTF's TEXCOORD_0 has v down,
// so t = 1 − v.
// Materials (pbrMetallicRoughness, metallic 0):
//   baseColorFactor = rho_d (clamped to [0, 1]); rho_d_map -> baseColorTexture, an 8-bit PNG
//   sRGB-encoded as glTF requires (the factor is then 1).
//   lambert/black: KHR_materials_specular specularFactor 0 (no specular lobe: exact Lambert).
//   ggx: glTF's own lobe (F_schlick·D_ggx·V with Smith's height-correlated V), so exact:
//   roughness = √α, and with ρd = 0 (no map) metallicFactor 1 and baseColorFactor = ρs (glTF's
//   metal takes F0 = baseColor: the whole BRDF exact); otherwise metallic 0 with
//   KHR_materials_specular specularColorFactor = ρs/0.04 (glTF's dielectric F0 is
//   0.04·specularColorFactor, the factor may exceed 1).
//   Other models with a lobe: the lobe is fitted by glTF's GGX + Schlick (ward_fit.h,
//   kGgxSchlick): roughness = √α_fit, and specularColorFactor = F0_fit·(ρs/mean ρs)/0.04.
//   On a dielectric glTF also weights the diffuse by (1 − F); that darkening (≈ F0 at normal
//   incidence) is not compensated. Anisotropy is dropped (ggx_aniso is fitted).
//   emitter: emissiveFactor = radiance/max, KHR_materials_emissive_strength = max(radiance).
// Lights (KHR_lights_punctual; values passed through 1:1 radiometrically: glTF's candela and lux
//   are taken to mean W·sr⁻¹ and W·m⁻² — multiply by a luminous efficacy (683 lm/W at 555 nm) for
//   photometric viewers): color = value/max, intensity = max channel.
//   point -> point; spot -> spot (cone: inner/outer exactly; cos_power and IES: inner/outer where
//   the profile falls to 90% / 10%, outer at most 90°; a spot without profile -> point);
//   directional -> directional; sphere -> point of intensity radiance·π r² (exact far field);
//   area -> emissive mesh.
// Cameras: perspective yfov = 2 atan(H / 2fy), aspectRatio = W/H, znear 0.01 m, no zfar; the
// principal point offset, fx ≠ fy and OPENCV distortion cannot be represented (reported).
// The asset's extras list the lightings: {"igi_lightings": {"L0": ["lamp"], ...}}.

#include <filesystem>

#include "recon/scene.h"
#include "solver/export/export.h"

namespace igi::exporter {

void WriteGltfExport(const recon::Scene& scene, const ExportOptions& options,
                     const std::filesystem::path& dir, ExportReport* report);

}  // namespace igi::exporter
