#include "solver/synth/camera_placement.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "solver/render/sampling.h"
#include "tools/common/error.h"

namespace igi::synth {
namespace {

using Eigen::Vector3d;

bool InsideRoom(const SynthRoom& room, const Vector3d& p, double margin) {
  for (int i = 0; i < 3; ++i) {
    if (p[i] < margin || p[i] > room.size[i] - margin) return false;
  }
  return true;
}

// Area-weighted random point on the region's triangles: (point, triangle).
std::pair<Vector3d, int> SampleRegionPoint(const SynthMesh& mesh, int region, render::Pcg32* rng) {
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.triangle_region[t] == region) total += mesh.TriangleArea(int(t));
  }
  double pick = rng->UniformDouble() * total;
  int chosen = -1;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.triangle_region[t] != region) continue;
    chosen = int(t);
    pick -= mesh.TriangleArea(int(t));
    if (pick <= 0) break;
  }
  const Vector3d w = render::SampleUniformTriangle(rng->Uniform2D());
  const Eigen::Vector3i& tri = mesh.triangles[chosen];
  return {
      w[0] * mesh.positions[tri[0]] + w[1] * mesh.positions[tri[1]] + w[2] * mesh.positions[tri[2]],
      chosen};
}

struct Candidate {
  double score = -1;
  Vector3d point, eye;
};

// The incidence (cosine from the normal) a highlight view accepts and prefers.
struct Incidence {
  double min_cos = 0.25, max_cos = 1.0, preferred_cos = 0.7;
};

// The best mirror viewpoint of the lamp's highlight on `region` over 96 sampled points (384 for
// a narrow incidence window).
Candidate BestHighlightView(const SynthRoom& room, const std::string& region, render::Pcg32* rng,
                            const std::vector<Vector3d>& taken, const Incidence& incidence = {}) {
  const SynthMesh& mesh = room.mesh;
  const int region_index = mesh.FindRegion(region);
  const Vector3d lamp = room.lamps[0].position;
  Candidate best;
  const int attempts = incidence.max_cos < 1 ? 384 : 96;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const auto [p, tri] = SampleRegionPoint(mesh, region_index, rng);
    const Vector3d n = mesh.FaceNormal(tri);
    const Vector3d l = (lamp - p).normalized();
    const double cos_l = n.dot(l);
    if (cos_l < incidence.min_cos || cos_l > incidence.max_cos ||
        !SegmentVisible(mesh, p + 1e-3 * n, lamp, 0.06)) {
      continue;
    }
    const Vector3d r = 2 * cos_l * n - l;
    for (double d = 3.0; d >= 0.9; d -= 0.1) {
      const Vector3d eye = p + d * r;
      if (!InsideRoom(room, eye, 0.2) || (eye - lamp).norm() < 0.5) continue;
      if (!SegmentVisible(mesh, p + 1e-3 * n, eye)) continue;
      double spread = 1.0;
      for (const Vector3d& other : taken) spread = std::min(spread, (other - eye).norm());
      const double score = d + spread - std::abs(cos_l - incidence.preferred_cos);
      if (score > best.score) best = {score, p, eye};
      break;
    }
  }
  return best;
}

}  // namespace

recon::Camera LookAtCamera(const std::string& name, const Vector3d& eye, const Vector3d& target,
                           int width, int height, double fov_deg) {
  const Vector3d forward = (target - eye).normalized();
  const Vector3d up = std::abs(forward.z()) > 0.95 ? Vector3d::UnitY() : Vector3d::UnitZ();
  const Vector3d right = forward.cross(up).normalized();
  const Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;  // rows: camera axes in world coordinates
  r.row(0) = right.transpose();
  r.row(1) = down.transpose();
  r.row(2) = forward.transpose();
  recon::Camera cam;
  cam.name = name;
  cam.model = recon::CameraModel::kPinhole;
  cam.width = width;
  cam.height = height;
  const double f = 0.5 * width / std::tan(0.5 * fov_deg * std::numbers::pi / 180.0);
  cam.params = {f, f, 0.5 * width, 0.5 * height};
  cam.cam_from_world.rotation = Eigen::Quaterniond(r).normalized();
  cam.cam_from_world.translation = -(r * eye);
  return cam;
}

std::vector<PlacedCamera> PlaceCameras(const SynthRoom& room, const SynthOptions& options) {
  std::vector<PlacedCamera> cameras;
  std::vector<Vector3d> eyes;
  render::Pcg32 rng(options.seed, 0xca3e7a);
  auto name = [&] { return "cam" + std::to_string(cameras.size()); };
  for (const std::string& region : room.glossy_regions) {
    if (int(cameras.size()) >= options.cameras) break;
    const Candidate c = BestHighlightView(room, region, &rng, eyes);
    if (c.score < 0) throw Error("igi-synth: no viewpoint sees the highlight on " + region);
    PlacedCamera pc;
    pc.camera =
        LookAtCamera(name(), c.eye, c.point, options.width, options.height, options.fov_deg);
    pc.target_region = region;
    pc.highlight_point = c.point;
    pc.highlight_pixel = *pc.camera.ImgFromWorld(c.point);
    eyes.push_back(c.eye);
    cameras.push_back(pc);
  }
  // With a poster, the first two overview cameras face it from 1.8 m, 25° to either side of its
  // normal (−x), at its height.
  for (int side = -1; room.poster_center && side <= 1 && int(cameras.size()) < options.cameras;
       side += 2) {
    constexpr double kAngle = 25.0 * std::numbers::pi / 180.0, kDistance = 1.8;
    const Vector3d eye =
        *room.poster_center + kDistance * Vector3d(-std::cos(kAngle), side * std::sin(kAngle), 0);
    PlacedCamera pc;
    pc.camera = LookAtCamera(name(), eye, *room.poster_center, options.width, options.height,
                             options.fov_deg);
    eyes.push_back(eye);
    cameras.push_back(pc);
  }
  const Vector3d center = 0.5 * room.size - Vector3d(0, 0, 0.8);
  for (int k = 0; int(cameras.size()) < options.cameras; ++k) {
    const double angle = 2 * std::numbers::pi * (0.125 + 0.618034 * k) + 0.3 * rng.UniformDouble();
    const double reach = 0.5 * room.size.x() - 0.35;
    const Vector3d eye(0.5 * room.size.x() + reach * std::cos(angle),
                       0.5 * room.size.y() + reach * std::sin(angle),
                       1.6 + 0.6 * rng.UniformDouble());
    bool near_lamp = false;
    for (const SynthLamp& lamp : room.lamps) near_lamp |= (lamp.position - eye).norm() < 0.5;
    if (near_lamp) continue;
    // A ceiling camera looks at the far edge of the ceiling: the ceiling fills the top of its
    // frame, the far wall the rest.
    const bool up = options.cameras - int(cameras.size()) <= options.ceiling_cameras;
    const Vector3d target =
        up ? Vector3d(room.size.x() - eye.x(), room.size.y() - eye.y(), room.size.z() - 0.1)
           : center;
    PlacedCamera pc;
    pc.camera = LookAtCamera(name(), eye, target, options.width, options.height, options.fov_deg);
    eyes.push_back(eye);
    cameras.push_back(pc);
  }
  // Grazing views of the floor's highlight (60–80° from the normal, 70° preferred).
  for (int k = 0; k < options.grazing_cameras; ++k) {
    const Candidate c = BestHighlightView(room, "floor", &rng, eyes, {0.17, 0.5, 0.34});
    if (c.score < 0) {
      throw InputError(
          "igi-synth: --grazing-cameras: no viewpoint in the room sees the floor's highlight at "
          "60-80 deg incidence under this lamp (lower it: --lamp-position x,y,z with z below "
          "about 0.8 m, 1.5 m or more from the walls)");
    }
    PlacedCamera pc;
    pc.camera =
        LookAtCamera(name(), c.eye, c.point, options.width, options.height, options.fov_deg);
    pc.target_region = "floor";
    pc.highlight_point = c.point;
    pc.highlight_pixel = *pc.camera.ImgFromWorld(c.point);
    eyes.push_back(c.eye);
    cameras.push_back(pc);
  }
  return cameras;
}

}  // namespace igi::synth
