// LoadScene: strict reading and validation of scene.json (docs/scene-format.md). Every problem
// found is collected; the load fails at the end with all of them.
#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "recon/scene_loader.h"

namespace igi::recon {

namespace fs = std::filesystem;

std::optional<fs::path> SceneLoader::File(const JsonCursor& c) const {
  auto name = c.NonEmptyString();
  if (!name) return std::nullopt;
  fs::path p = fs::path(*name).is_absolute() ? fs::path(*name) : dir / *name;
  p = p.lexically_normal();
  if (!fs::is_regular_file(p)) {
    c.Problem("file not found (" + p.string() + ")");
    return std::nullopt;
  }
  return p;
}

std::optional<ImageInfo> SceneLoader::ImageHeader(const JsonCursor& c, const fs::path& p) const {
  if (!options.check_images) return std::nullopt;
  try {
    return ReadImageInfo(p);
  } catch (const Error& e) {
    c.Problem("unreadable image: " + e.Lines().front());
    return std::nullopt;
  }
}

void SceneLoader::Nested(const JsonCursor& c, const Error& e) const {
  for (const std::string& line : e.Lines()) problems->Add(file, c.path(), "", line);
}

namespace {

// Reads every geometry file; returns the regions of files without UVs.
std::set<std::string> ReadGeometry(const SceneLoader& ld, const JsonCursor& root, Scene* scene) {
  std::set<std::string> regions_without_uvs;
  const JsonCursor geometry = root["geometry"];
  const size_t n = geometry.ArraySize(1);
  for (size_t i = 0; i < n; ++i) {
    const JsonCursor entry = geometry[i];
    if (!entry.ExpectObject({"file"})) continue;
    auto path = ld.File(entry["file"]);
    if (!path) continue;
    scene->geometry_files.push_back(*path);
    if (!ld.options.load_geometry) continue;
    ProblemList mesh_problems;
    TriangleMesh mesh = LoadMesh(*path, &mesh_problems);
    for (const std::string& p : mesh_problems.problems()) {
      ld.problems->Add(ld.file, entry["file"].path(), "", p);
    }
    for (const std::string& region : mesh.region_names) {
      if (scene->FindMaterial(region) < 0) {
        entry["file"].Problem("region '" + region +
                              "' (a material name in the mesh) has no entry in materials");
      }
    }
    if (!mesh_problems.empty()) continue;
    if (!mesh.has_uvs())
      regions_without_uvs.insert(mesh.region_names.begin(), mesh.region_names.end());
    scene->mesh.Append(mesh);
  }
  return regions_without_uvs;
}

// A dielectric's index of refraction: > 1 (so Schlick's F0 > 0) and at most 5 (beyond any
// dielectric; metals need a complex index, which this model does not take).
const NumberRule kIorRule{1.0, 5.0, true, false};

// Keys a material of each model may have: its albedo; a lobe's ρs and roughness (α, or αx, αy
// and the tangent); the index of refraction of a lobe weighted by an ior's Fresnel factor; the
// diffuse term's shape and its roughness.
std::vector<std::string_view> MaterialKeys(BrdfModel model) {
  if (model == BrdfModel::kEmitter) return {"brdf", "radiance"};
  if (model == BrdfModel::kBlack) return {"brdf"};
  std::vector<std::string_view> keys = {"brdf", "rho_d", "rho_d_map", "diffuse", "sigma"};
  if (!HasSpecularLobe(model)) return keys;
  keys.push_back("rho_s");
  if (IsAnisotropic(model)) {
    keys.insert(keys.end(), {"alpha_x", "alpha_y", "tangent"});
  } else {
    keys.push_back("alpha");
  }
  if (HasFresnel(model)) keys.push_back("ior");
  return keys;
}

Material ReadMaterial(const SceneLoader& ld, const JsonCursor& c, const std::string& name) {
  Material m;
  m.name = name;
  if (!c.IsObject()) {
    c.Problem("must be an object");
    return m;
  }
  auto brdf_name = c["brdf"].String();
  auto model = brdf_name ? BrdfModelFromName(*brdf_name) : std::nullopt;
  if (brdf_name && !model) {
    c["brdf"].Problem("unknown brdf (known: " + std::string(BrdfModelNames()) + ")");
  }
  if (!model) return m;
  m.brdf = *model;
  c.ExpectObject(MaterialKeys(m.brdf));
  const NumberRule unit = NumberRule::Between(0, 1);
  const NumberRule roughness{0.0, 1.0, true, false};
  if (c["rho_d"].present()) m.rho_d = c["rho_d"].Rgb(unit);
  if (c["rho_s"].present()) m.rho_s = c["rho_s"].Rgb(unit);
  if (c["alpha"].present()) m.alpha = c["alpha"].Number(roughness);
  if (c["alpha_x"].present()) m.alpha_x = c["alpha_x"].Number(roughness);
  if (c["alpha_y"].present()) m.alpha_y = c["alpha_y"].Number(roughness);
  if (c["tangent"].present()) m.tangent = c["tangent"].Direction();
  if (c["ior"].present()) m.ior = c["ior"].Number(kIorRule);
  bool diffuse_known = true;  // (an unknown name is its own problem, not sigma's)
  if (auto diffuse = c["diffuse"].present() ? c["diffuse"].String() : std::nullopt) {
    if (auto shape = DiffuseShapeFromName(*diffuse)) {
      m.diffuse = *shape;
    } else {
      c["diffuse"].Problem("unknown diffuse (known: " + std::string(DiffuseShapeNames()) + ")");
      diffuse_known = false;
    }
  }
  if (c["sigma"].present()) {
    // Oren–Nayar's σ, the standard deviation of the facets' slope angle in radians: 0 is
    // Lambert's surface; past ~0.8 rad the model's facets are steeper than its V-groove geometry
    // assumes.
    m.sigma = c["sigma"].Number(NumberRule::Between(0, 1));
    if (diffuse_known && !HasSigma(m.diffuse)) {
      c["sigma"].Problem("is read only with \"diffuse\": \"" +
                         std::string(DiffuseShapesWithSigma()) + "\"");
    }
  }
  if (c["radiance"].present() || m.brdf == BrdfModel::kEmitter) {
    m.radiance = c["radiance"].Rgb(NumberRule::NonNegative());
  }
  if (c["rho_d_map"].present()) {
    m.rho_d_map = ld.File(c["rho_d_map"]);
    if (m.rho_d_map) {
      auto info = ld.ImageHeader(c["rho_d_map"], *m.rho_d_map);
      if (info && info->channels != 1 && info->channels < 3) {
        c["rho_d_map"].Problem("texture must have 1, 3 or 4 channels (has " +
                               std::to_string(info->channels) + ")");
      }
    }
  }
  if (ld.options.require_complete_materials) {
    const auto missing = m.MissingForRendering();
    if (!missing.empty()) {
      std::string list;
      for (const auto& k : missing) list += (list.empty() ? "" : ", ") + k;
      c.Problem("missing " + list + " (rendering needs every value of the material)");
    }
  }
  return m;
}

void ReadMaterials(const SceneLoader& ld, const JsonCursor& root, Scene* scene) {
  const JsonCursor materials = root["materials"];
  for (const std::string& name : materials.ObjectKeys()) {
    scene->materials.push_back(ReadMaterial(ld, materials[name], name));
  }
  if (materials.IsObject() && scene->materials.empty()) {
    materials.Problem("must define at least one material");
  }
}

// Maps the mesh's region names onto material indices; every region needs a material.
void BindRegions(const SceneLoader& ld, const JsonCursor& root,
                 const std::set<std::string>& regions_without_uvs, Scene* scene) {
  TriangleMesh& mesh = scene->mesh;
  std::vector<int> to_material(mesh.region_names.size(), -1);
  for (size_t r = 0; r < mesh.region_names.size(); ++r) {
    to_material[r] = scene->FindMaterial(mesh.region_names[r]);  // -1 reported by ReadGeometry
  }
  std::vector<size_t> triangles_per_material(scene->materials.size(), 0);
  for (int& region : mesh.triangle_region) {
    region = to_material[region];
    if (region >= 0) ++triangles_per_material[region];
  }
  mesh.region_names.clear();
  for (const Material& m : scene->materials) mesh.region_names.push_back(m.name);
  for (size_t i = 0; i < scene->materials.size(); ++i) {
    const Material& m = scene->materials[i];
    if (triangles_per_material[i] == 0 && !scene->mesh.triangles.empty()) {
      spdlog::warn("{}: materials.{}: no triangle of the geometry uses this material", ld.file,
                   m.name);
    }
    if (m.rho_d_map && regions_without_uvs.count(m.name) != 0) {
      root["materials"][m.name]["rho_d_map"].Problem(
          "a texture needs UVs, but a mesh of this region has none");
    }
  }
}

}  // namespace

Material ReadMaterialEntry(const Json& entry, const std::string& name, const fs::path& dir,
                           const std::string& file, const SceneLoadOptions& options) {
  ProblemList problems;
  const SceneLoader ld{options, dir, file, &problems};
  Material m = ReadMaterial(ld, JsonCursor(&entry, file, "", &problems), name);
  problems.ThrowIfAny();
  return m;
}

Scene LoadScene(const fs::path& path, const SceneLoadOptions& options) {
  return LoadSceneFromDocument(ReadJsonFile(path), path, options);
}

Scene LoadSceneFromDocument(Json document, const fs::path& path, const SceneLoadOptions& options) {
  Scene scene;
  scene.file = fs::absolute(path).lexically_normal();
  scene.dir = scene.file.parent_path();
  scene.document = std::move(document);
  ProblemList problems;
  const SceneLoader ld{options, scene.dir, path.string(), &problems};
  const JsonCursor root = JsonCursor::Root(scene.document, ld.file, &problems);
  if (!root.ExpectObject({"format", "version", "geometry", "materials", "lights", "lightings",
                          "cameras", "photos"})) {
    problems.ThrowIfAny();
  }
  if (auto format = root["format"].String(); format && *format != "igi-scene") {
    root["format"].Problem("must be \"igi-scene\"");
  }
  if (auto version = root["version"].Integer(); version && *version != 1) {
    root["version"].Problem("unsupported version (this igi reads version 1)");
  }
  ReadMaterials(ld, root, &scene);
  const std::set<std::string> regions_without_uvs = ReadGeometry(ld, root, &scene);
  if (options.load_geometry && !scene.mesh.triangles.empty() && problems.empty()) {
    BindRegions(ld, root, regions_without_uvs, &scene);
  }
  ReadLightsAndLightings(ld, root, &scene);
  ReadCameras(ld, root, &scene);
  ReadPhotos(ld, root, &scene);
  problems.ThrowIfAny();
  return scene;
}

}  // namespace igi::recon
