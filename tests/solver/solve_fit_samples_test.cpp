// The solver's fit samples (SolverState::SelectFitSamples): where a region has more observations
// than SolveOptions::max_fit_samples (or max_highlight_samples near a highlight), a share is drawn
// by a hash. The draw must be a property of each photo's own pixels: keyed by the observation's
// index, a change to one photo's observations (its pose, its mask, a pixel passing an edge test)
// shifted every later photo's indices and redrew them all, and the demo floor's faint lobe (ρs
// 0.04) moved by up to 11 points with the draw alone (bench/RESULTS.md).
//
// Scene: tests/e2e/box_room.h's 2 m room, cam0 looking down, cam1 up, photos path-traced at 16
// paths. The second solve's cam0 photo has its floor pixels invalid (NaN): cam1 sees no floor,
// so every other region keeps its observations and its drawn share, while all of cam1's
// observation indices move.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <utility>

#include "recon/scene.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_internal.h"
#include "tests/e2e/box_room.h"
#include "tests/solver/box_room_photos.h"
#include "tests/temp_dir.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi::solver {
namespace {
namespace fs = std::filesystem;
namespace room = test::box_room;

struct Draw {
  std::set<std::pair<int, int>> cam1_walls;  // cam1's drawn pixels on the walls
  int walls_observations = 0, walls_drawn = 0;
  int cam1_first_index = -1;  // cam1's first observation
  int floor_observations = 0;
};

Draw Prepare(const fs::path& scene_path) {
  const recon::Scene scene = recon::LoadScene(scene_path);
  SolveOptions o;
  o.pixel_stride = 1;
  o.max_fit_samples = 300;
  o.max_highlight_samples = 100;
  o.num_threads = 2;
  o.show_progress = false;
  SolverState s(scene, o);
  s.Prepare();
  const int walls = scene.FindMaterial("walls"), floor = scene.FindMaterial("floor");
  Draw d;
  for (size_t i = 0; i < s.obs.size(); ++i) {
    const Observation& ob = s.obs[i];
    if (ob.photo == 1 && d.cam1_first_index < 0) d.cam1_first_index = int(i);
    if (ob.region == floor) ++d.floor_observations;
    if (ob.region != walls) continue;
    ++d.walls_observations;
    if (!s.obs.in_fit[i]) continue;
    ++d.walls_drawn;
    if (ob.photo == 1) d.cam1_walls.insert({ob.x, ob.y});
  }
  return d;
}

TEST(SolveFitSamples, APhotosDrawDoesNotMoveWithAnotherPhotosPixels) {
  const fs::path dir = test::UniqueTempDir("solve_fit_samples");
  room::WriteRoomFolder(dir);
  Json photos = Json::array();
  for (const char* cam : {"cam0", "cam1"}) {
    photos.push_back(room::PhotoEntry(std::string("photos/") + cam + ".exr", cam, "L0"));
  }
  Json unknown = room::TrueMaterials(false);
  for (auto& [name, m] : unknown.items()) m.erase("rho_d");
  WriteJsonFile(dir / "truth.json", room::SceneDoc(room::TrueMaterials(false), Json::array()));
  WriteJsonFile(dir / "scene.json", room::SceneDoc(unknown, photos));
  room::RenderTruthPhotos(dir, {"cam0", "cam1"}, 16, 5);
  const Draw before = Prepare(dir / "scene.json");

  // cam0's floor pixels made invalid: the pixels whose centre ray meets the floor (z = 0).
  const recon::Scene scene = recon::LoadScene(dir / "scene.json");
  const recon::Camera& cam0 = scene.cameras[scene.FindCamera("cam0")];
  Image photo = ReadImage(dir / "photos" / "cam0.exr");
  const Eigen::Vector3d c = cam0.CenterInWorld();
  int cleared = 0;
  for (int y = 0; y < photo.height; ++y) {
    for (int x = 0; x < photo.width; ++x) {
      const Eigen::Vector3d d = cam0.WorldRayFromImg(Eigen::Vector2d(x + 0.5, y + 0.5));
      if (!(d.z() < 0)) continue;
      const Eigen::Vector3d p = c - d * (c.z() / d.z());
      if (p.x() > 0.05 && p.x() < 1.95 && p.y() > 0.05 && p.y() < 1.95) {
        for (int ch = 0; ch < photo.channels; ++ch) photo.at(x, y, ch) = NAN;
        ++cleared;
      }
    }
  }
  ASSERT_GT(cleared, 100);
  WriteImage(dir / "photos" / "cam0.exr", photo);
  const Draw after = Prepare(dir / "scene.json");

  // The change: cam0 lost floor observations, so cam1's indices moved; the walls kept theirs.
  EXPECT_LT(after.floor_observations, before.floor_observations - 100);
  EXPECT_GT(after.cam1_first_index, 0);
  EXPECT_LT(after.cam1_first_index, before.cam1_first_index - 100);
  EXPECT_EQ(after.walls_observations, before.walls_observations);
  // A share was drawn (not every observation), and the same share of the same pixels.
  EXPECT_LT(before.walls_drawn, before.walls_observations / 2);
  EXPECT_GT(before.cam1_walls.size(), 20u);
  EXPECT_EQ(after.walls_drawn, before.walls_drawn);
  EXPECT_EQ(after.cam1_walls, before.cam1_walls);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace igi::solver
