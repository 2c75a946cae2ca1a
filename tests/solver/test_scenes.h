#pragma once
// Small scenes with closed-form answers, written to a temporary folder and loaded with
// LoadScene, for the renderer's tests.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "recon/scene.h"
#include "tests/temp_dir.h"
#include "tools/common/json.h"

namespace igi::test {

inline std::filesystem::path TempSceneDir(const std::string& name) {
  return UniqueTempDir("igi_render_" + name);
}

// A square of half-size `half` in the plane z = `z`, centred on (center_x, 0), facing +z (or -z),
// region `region`, with UVs (v = 1 at +y).
inline std::string SquareObj(const std::string& region, double half, double z = 0,
                             bool face_down = false, double center_x = 0) {
  std::string s = "usemtl " + region + "\n";
  const double h = half, c = center_x;
  auto vertex = [&](double x, double y) {
    return "v " + std::to_string(c + x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
  };
  s += vertex(-h, -h) + vertex(h, -h) + vertex(h, h) + vertex(-h, h);
  s += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  s += face_down ? "f 1/1 3/3 2/2\nf 1/1 4/4 3/3\n" : "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  return s;
}

inline void WriteText(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// A camera at `center` looking straight down -z (image x = world x, image y = world -y).
inline Json DownCamera(double cx, double cy, double cz, int w, int h, double f) {
  // R maps world -z to camera +z and world -y to camera +y: diag(1, -1, -1), q = [0, 1, 0, 0].
  return Json{{"model", "PINHOLE"}, {"width", w}, {"height", h},
              {"params", {f, f, w / 2.0, h / 2.0}}, {"qvec", {0, 1, 0, 0}},
              {"tvec", {-cx, cy, cz}}};
}

inline recon::Scene LoadTestScene(const std::filesystem::path& dir, const Json& doc) {
  WriteJsonFile(dir / "scene.json", doc);
  recon::SceneLoadOptions options;
  options.require_complete_materials = true;
  return recon::LoadScene(dir / "scene.json", options);
}

}  // namespace igi::test
