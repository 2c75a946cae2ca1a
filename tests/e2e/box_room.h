#pragma once
// A 2 m cube room for end-to-end tests of igi-solve and igi-run (tests/e2e): its mesh, two
// cameras, one point lamp, the true Lambertian materials and the scene.json around them.

#include <filesystem>
#include <fstream>
#include <string>

#include "tools/common/json.h"

namespace igi::test::box_room {

inline constexpr int kWidth = 64, kHeight = 48;
// A 2 m cube room [0,2]^3 (regions floor, ceiling, walls; faces wound and normals pointing
// inward), and optionally a quad "hidden" outside the wall x = 2, facing the room: no camera
// inside can see it.
inline std::string RoomObj(bool hidden) {
  std::string s =
      "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\n"
      "vn 0 0 1\nvn 0 0 -1\nvn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\n"
      "usemtl floor\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"
      "usemtl ceiling\nf 5//2 8//2 7//2\nf 5//2 7//2 6//2\n"
      "usemtl walls\n"
      "f 1//3 4//3 8//3\nf 1//3 8//3 5//3\nf 2//4 6//4 7//4\nf 2//4 7//4 3//4\n"
      "f 1//5 5//5 6//5\nf 1//5 6//5 2//5\nf 4//6 3//6 7//6\nf 4//6 7//6 8//6\n";
  if (hidden) {
    // x = 2.5, y in [0.5, 1.5], z in [0.5, 1.5], facing -x.
    s += "v 2.5 0.5 0.5\nv 2.5 1.5 0.5\nv 2.5 1.5 1.5\nv 2.5 0.5 1.5\n"
         "usemtl hidden\nf 9//4 12//4 11//4\nf 9//4 11//4 10//4\n";
  }
  return s;
}

// cam0 near the ceiling looking straight down (sees the floor and the walls), cam1 near the
// floor looking straight up (sees the ceiling and the walls). COLMAP convention: t = -R c.
inline Json Cameras() {
  const double f = 20;  // wide: half-angle atan(32 / 20) = 58 deg
  auto cam = [&](Json q, Json t) {
    return Json{{"model", "PINHOLE"}, {"width", kWidth},
                {"height", kHeight},  {"params", {f, f, kWidth / 2.0, kHeight / 2.0}},
                {"qvec", q},          {"tvec", t}};
  };
  // Down: R = diag(1, -1, -1), c = (1, 1, 1.9). Up: R = I, c = (1, 1, 0.1).
  return Json{{"cam0", cam({0, 1, 0, 0}, {-1, 1, 1.9})},
              {"cam1", cam({1, 0, 0, 0}, {-1, -1, -0.1})}};
}

// The truth of the room's materials.
inline Json TrueMaterials(bool hidden) {
  Json m = {{"floor", {{"brdf", "lambert"}, {"rho_d", {0.4, 0.4, 0.4}}}},
            {"ceiling", {{"brdf", "lambert"}, {"rho_d", {0.7, 0.7, 0.7}}}},
            {"walls", {{"brdf", "lambert"}, {"rho_d", {0.6, 0.5, 0.3}}}}};
  if (hidden) m["hidden"] = {{"brdf", "lambert"}, {"rho_d", {0.5, 0.5, 0.5}}};
  return m;
}

inline Json SceneDoc(const Json& materials, const Json& photos) {
  return Json{
      {"format", "igi-scene"},
      {"version", 1},
      {"geometry", Json::array({Json{{"file", "geometry/room.obj"}}})},
      {"materials", materials},
      {"lights",
       {{"lamp",
         {{"type", "point"}, {"position", {0.7, 1.3, 1.2}}, {"intensity", {3.0, 3.0, 3.0}}}}}},
      {"lightings", {{"L0", Json::array({"lamp"})}, {"dark", Json::array()}}},
      {"cameras", Cameras()},
      {"photos", photos}};
}

inline Json PhotoEntry(const std::string& file, const std::string& camera,
                       const std::string& lighting, const Json& mask = nullptr) {
  return Json{{"file", file}, {"camera", camera}, {"lighting", lighting}, {"mask", mask}};
}

// A scene folder's skeleton: dir/geometry/room.obj (RoomObj(false)) and an empty dir/photos.
inline void WriteRoomFolder(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "geometry");
  std::filesystem::create_directories(dir / "photos");
  std::ofstream(dir / "geometry" / "room.obj") << RoomObj(false);
}

}  // namespace igi::test::box_room
