#pragma once
// SceneDocument: the one writer of scene.json documents (docs/scene-format.md). It holds a
// document as JSON and makes the edits igi's stages make to it — material values, lights,
// cameras, photos, paths — as typed operations, so that the file's layout is written in one
// place. Objects keep the order of their keys: an edit of a key keeps its place, a new key goes
// last. Validate checks the document by LoadScene's rules (the reader is the one source of them).
//
// Names (a region, a light, a camera) need not exist: a setter of a missing one creates it. A
// photo index out of range is a programmer error (Json::out_of_range).

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "recon/brdf_model.h"
#include "recon/camera.h"
#include "recon/scene.h"
#include "tools/common/geometry.h"
#include "tools/common/json.h"

namespace igi::recon {

// A photo entry as written: paths relative to the document's folder, or absolute.
struct ScenePhotoEntry {
  std::string file;
  std::string camera;
  std::string lighting;
  std::optional<std::string> mask;
};

class SceneDocument {
 public:
  // Wraps `document` (an igi-scene document, e.g. a loaded Scene's `document`).
  explicit SceneDocument(Json document);

  // The document.
  const Json& json() const& { return doc_; }
  // The document, moved out.
  Json json() && { return std::move(doc_); }

  // Validates the document as LoadScene would read it from `dir`/scene.json (paths relative to
  // `dir`); throws LoadScene's InputError, one line per problem, naming that file.
  void Validate(const std::filesystem::path& dir, const SceneLoadOptions& options = {}) const;

  // Rewrites every relative path (relative to `from_dir`) as the same file relative to `to_dir`
  // (symlinks resolved, generic form; absolute where it has no relative form); absolute paths
  // are left as they are.
  void RebasePaths(const std::filesystem::path& from_dir, const std::filesystem::path& to_dir);
  // Makes every path absolute (a relative one taken from `dir`) and normal (AbsoluteScenePaths).
  void AbsolutePaths(const std::filesystem::path& dir);
  // Makes every absolute path relative to `base` (RelativeScenePaths).
  void RelativePaths(const std::filesystem::path& base);

  // Replaces the geometry with these mesh files.
  void SetGeometryFiles(const std::vector<std::filesystem::path>& files);

  // The material entry of `region`, or null when it has none.
  const Json& Material(const std::string& region) const;
  // Replaces the material entry of `region` with `entry`.
  void SetMaterial(const std::string& region, Json entry);
  // Sets the value `key` of `region`'s material (rho_d, rho_s, alpha, tangent, ior, …).
  void SetMaterialValue(const std::string& region, const std::string& key, Json value);
  // Removes the value `key` of `region`'s material, if it has one.
  void EraseMaterialValue(const std::string& region, const std::string& key);
  // Sets the BRDF model of `region`'s material.
  void SetMaterialBrdf(const std::string& region, BrdfModel brdf);
  // Multiplies the value `key` of `region`'s material (a number, or each number of an array) by
  // `factor`; nothing when absent.
  void ScaleMaterialValue(const std::string& region, const std::string& key, double factor);

  // Replaces the light `name` with `light` (a light entry).
  void SetLight(const std::string& name, Json light);
  // Adds `light` under a name not yet taken (`name_hint`, with "_" appended until it is new) to
  // the lights and to every lighting; returns the name.
  std::string AddLightToEveryLighting(const std::string& name_hint, Json light);
  // Multiplies the light's emission (intensity, radiance and irradiance, whichever it has) by
  // `factor`.
  void ScaleLightEmission(const std::string& name, double factor);

  // The names of the cameras entry's keys, in order.
  std::vector<std::string> CameraNames() const;
  // Whether the cameras entry has `name`.
  bool HasCamera(const std::string& name) const;
  // Replaces the cameras entry with `cameras` (camera entries by name, or {"colmap": dir}).
  void SetCameras(Json cameras);
  // Sets the entry of camera `name` to `camera` (CameraJson: intrinsics, pose, vignetting).
  void SetCamera(const std::string& name, const Camera& camera);
  // Sets the intrinsics (model, width, height, params) of camera `name` to `camera`'s, keeping
  // its pose and vignetting.
  void SetCameraIntrinsics(const std::string& name, const Camera& camera);
  // The pose cam_from_world of camera `name` (qvec w, x, y, z normalised; tvec).
  Rigid3d CameraPose(const std::string& name) const;
  // Sets the qvec (w, x, y, z, as given) and tvec of camera `name` to `cam_from_world`.
  void SetCameraPose(const std::string& name, const Rigid3d& cam_from_world);
  // The vignetting (k1, k2) of camera `name`; zero where absent.
  Eigen::Vector2d CameraVignetting(const std::string& name) const;
  // Sets the vignetting of camera `name`.
  void SetCameraVignetting(const std::string& name, double k1, double k2);

  // The number of photos.
  size_t NumPhotos() const;
  // Replaces the photos with `photos`.
  void SetPhotos(const std::vector<ScenePhotoEntry>& photos);
  // The file of photo `index` as written ("" when it has none).
  std::string PhotoFile(size_t index) const;
  // Sets the file of photo `index`.
  void SetPhotoFile(size_t index, const std::filesystem::path& file);
  // Sets the camera of photo `index`.
  void SetPhotoCamera(size_t index, const std::string& camera);
  // Sets the mask of photo `index`, or removes it when `mask` is none.
  void SetPhotoMask(size_t index, const std::optional<std::filesystem::path>& mask);
  // The exposure_scale of photo `index`, or none when it has none (1).
  std::optional<double> PhotoExposure(size_t index) const;
  // Sets the exposure_scale of photo `index`.
  void SetPhotoExposure(size_t index, double scale);
  // The response exponent of photo `index`, or none when it has none (linear) or it is not a
  // number.
  std::optional<double> PhotoResponseExponent(size_t index) const;
  // Sets the response of photo `index`: recorded v = reference·(u/reference)^exponent.
  void SetPhotoResponse(size_t index, double exponent, double reference);

 private:
  Json doc_;
};

}  // namespace igi::recon
