#pragma once
// The calibrated scene of scene.json (docs/scene-format.md): geometry with regions, materials,
// lights, lightings, cameras and photos. LoadScene validates everything and reports every problem
// it finds (as one igi::InputError carrying one line per problem), not just the first.
//
// Units: metres, radiance in W·sr⁻¹·m⁻² (or any scale consistent between lights and photos),
// point/spot intensity in W·sr⁻¹, directional irradiance in W·m⁻². Directions are unit vectors
// in the world frame. Paths are absolute after loading (resolved against the scene's folder).

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "recon/brdf_model.h"
#include "recon/camera.h"
#include "recon/ies_profile.h"
#include "recon/mesh.h"
#include "tools/common/json.h"

namespace igi::recon {

// What is known of one region's reflectance. Absent values are unknowns for the solver; for
// rendering every value the model needs must be present (Material::MissingForRendering).
struct Material {
  std::string name;
  BrdfModel brdf = BrdfModel::kLambert;
  std::optional<Eigen::Vector3d> rho_d;            // diffuse albedo (region mean), RGB
  std::optional<std::filesystem::path> rho_d_map;  // albedo texture (linear), indexed by UVs
  std::optional<Eigen::Vector3d> rho_s;            // specular albedo, RGB
  std::optional<double> alpha;                     // isotropic roughness
  std::optional<double> alpha_x, alpha_y;          // anisotropic roughness along t and b
  std::optional<Eigen::Vector3d> tangent;          // unit x direction of the lobe (world)
  std::optional<Eigen::Vector3d> radiance;         // "emitter" only, W·sr⁻¹·m⁻²
  // Index of refraction of the *_fresnel models (Schlick F0 = ((ior-1)/(ior+1))²); optional,
  // kDefaultIor when absent (never an unknown to estimate).
  std::optional<double> ior;
  static constexpr double kDefaultIor = 1.5;
  // The diffuse term (reflective models): Lambert's, or Oren–Nayar's with slope deviation
  // `sigma` (radians, an unknown when absent).
  DiffuseShape diffuse = DiffuseShape::kLambert;
  std::optional<double> sigma;

  // Names of the values that rendering needs but this material lacks (empty = complete).
  std::vector<std::string> MissingForRendering() const;
};

// kAmbient (igi extension): radiance `radiance` arriving at every surface point from every
// direction of its hemisphere, unoccluded (like RADIANCE's ambient value) — a model of light from
// sources the scene does not describe.
enum class LightType { kPoint, kSpot, kDirectional, kSphere, kArea, kAmbient };
std::string_view LightTypeName(LightType type);

// A spot light's emission profile. The relative intensity in a direction at angle θ from the
// spot's axis (and azimuth φ around it) multiplies the light's "intensity":
//   none:      1 everywhere;   cos_power: cos(θ)^n for θ < 90°, else 0;
//   cone:      1 inside inner_deg, 0 outside outer_deg, smoothstep between;
//   ies:       candela(θ, φ) / max candela (so "intensity" is the peak intensity).
struct SpotProfile {
  enum class Kind { kNone, kCosPower, kCone, kIes };
  Kind kind = Kind::kNone;
  double cos_power = 0;
  double inner_deg = 0, outer_deg = 0;
  std::filesystem::path ies_file;
  std::shared_ptr<const IesProfile> ies;

  // Relative intensity (0..1) at `theta` radians from the axis and azimuth `phi` radians.
  double Relative(double theta, double phi) const;
};

struct Light {
  std::string name;
  LightType type = LightType::kPoint;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    // point, spot
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // spot axis; directional: travel dir.
  Eigen::Vector3d intensity = Eigen::Vector3d::Zero();   // point, spot: W·sr⁻¹
  Eigen::Vector3d irradiance = Eigen::Vector3d::Zero();  // directional: W·m⁻² ⟂ to direction
  Eigen::Vector3d center = Eigen::Vector3d::Zero();      // sphere
  double radius = 0;                                     // sphere, metres
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();    // sphere, area, ambient: W·sr⁻¹·m⁻²
  std::filesystem::path file;                            // area: mesh (front = CCW)
  TriangleMesh mesh;                                     // area: loaded mesh
  SpotProfile profile;                                   // spot
};

struct Lighting {
  std::string name;
  std::vector<int> lights;  // indices into Scene::lights
};

struct Photo {
  std::filesystem::path file;
  std::optional<std::filesystem::path> mask;
  int camera = -1;    // index into Scene::cameras
  int lighting = -1;  // index into Scene::lightings
  // igi extensions (both describe how the photo's values relate to radiance):
  // "exposure_scale": the photo records exposure_scale × radiance (default 1);
  // "response": {"exponent": e, "reference": r}: a recorded value v relates to the linear one u
  // (after scale and vignetting) by v = r·(u/r)^e (default linear).
  double exposure_scale = 1.0;
  double response_exponent = 1.0, response_reference = 1.0;
  bool HasResponse() const { return response_exponent != 1.0; }
  // Linear value u from a recorded value v (the inverse of the response), and the reverse.
  double LinearFromRecorded(double v) const;
  double RecordedFromLinear(double u) const;
};

struct Scene {
  std::filesystem::path file;  // the scene.json read
  std::filesystem::path dir;   // its folder (paths in the file are relative to it)
  Json document;               // the file as read, for writers that fill values in
  std::vector<std::filesystem::path> geometry_files;
  TriangleMesh mesh;  // all geometry files; triangle_region indexes `materials`
  std::vector<Material> materials;
  std::vector<Light> lights;
  std::vector<Lighting> lightings;
  std::vector<Camera> cameras;
  std::optional<std::filesystem::path> colmap_model;  // when cameras came from COLMAP
  std::vector<Photo> photos;

  int FindMaterial(std::string_view name) const;
  int FindLight(std::string_view name) const;
  int FindLighting(std::string_view name) const;
  int FindCamera(std::string_view name) const;
};

struct SceneLoadOptions {
  bool load_geometry = true;  // read meshes (area lights' too)
  bool check_images = true;   // read the headers of photos, masks and textures
  // Require every material value rendering needs (igi-render); otherwise absent = unknown.
  bool require_complete_materials = false;
};

// Applies `fn` to every file path of an igi-scene document: geometry and area-light meshes, IES
// profiles, albedo maps, the COLMAP model, photos and masks.
void ForEachScenePath(Json* doc, const std::function<std::string(const std::string&)>& fn);
// The document with every path absolute (a relative one taken from `dir`) and normalised.
Json AbsoluteScenePaths(Json doc, const std::filesystem::path& dir);
// The document with every (absolute) path made relative to `base`.
Json RelativeScenePaths(Json doc, const std::filesystem::path& base);

// The scene.json entry of a camera: model, size, params, qvec, tvec, and vignetting when it has
// any.
Json CameraJson(const Camera& camera);

// One material entry (a value of scene.json's "materials") read by LoadScene's rules as the
// material of region `name`: relative paths (rho_d_map) are taken from `dir`, and problems name
// `file` and the entry's own keys ("rho_s", not "materials.NAME.rho_s"). Throws InputError
// listing every problem.
Material ReadMaterialEntry(const Json& entry, const std::string& name,
                           const std::filesystem::path& dir, const std::string& file,
                           const SceneLoadOptions& options = {});

// Loads and validates `path`. Throws InputError listing every problem ("FILE: KEY: VALUE: RULE").
Scene LoadScene(const std::filesystem::path& path, const SceneLoadOptions& options = {});
// Loads and validates a document held in memory as if it were read from the file `path`: `path`'s
// folder resolves relative paths and messages name `path`, which need not exist.
Scene LoadSceneFromDocument(Json document, const std::filesystem::path& path,
                              const SceneLoadOptions& options = {});

}  // namespace igi::recon
