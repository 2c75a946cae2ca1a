#pragma once
// Internal to recon: the state shared by the parts of LoadScene (recon/scene_io*.cpp). Not public
// API.

#include <filesystem>
#include <optional>

#include "recon/scene.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::recon {

struct SceneLoader {
  const SceneLoadOptions& options;
  std::filesystem::path dir;  // paths in the file are relative to it
  std::string file;           // the scene file as the user named it (for messages)
  ProblemList* problems;

  // Resolves a path key against the scene folder; reports a missing file at `c`.
  std::optional<std::filesystem::path> File(const JsonCursor& c) const;
  // Reads an image header when options.check_images; reports an unreadable image at `c`.
  std::optional<ImageInfo> ImageHeader(const JsonCursor& c, const std::filesystem::path& p) const;
  // Reports the problems of a nested reader (IES, COLMAP) under the key that named its file.
  void Nested(const JsonCursor& c, const Error& e) const;
};

// The parts of LoadScene, in scene_io_lights.cpp and scene_io_cameras.cpp.
void ReadLightsAndLightings(const SceneLoader& ld, const JsonCursor& root, Scene* scene);
void ReadCameras(const SceneLoader& ld, const JsonCursor& root, Scene* scene);
void ReadPhotos(const SceneLoader& ld, const JsonCursor& root, Scene* scene);

}  // namespace igi::recon
