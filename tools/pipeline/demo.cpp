#include "tools/pipeline/demo.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>

#include "recon/mesh_closest_point.h"
#include "recon/scene.h"
#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/pipeline/stage_marker.h"
#include "tools/pipeline/subprocess.h"

namespace igi::pipeline {
namespace fs = std::filesystem;

namespace {

std::vector<double> Rgb(const Json& j) {
  if (j.is_number()) return {j.get<double>(), j.get<double>(), j.get<double>()};
  if (j.is_array() && j.size() == 3) return j.get<std::vector<double>>();
  return {};
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / double(v.size());
}

// Whether the segment from `eye` to `p` (a point on the mesh) is blocked by a triangle before
// it reaches p (p's own triangle is not hit before 1 - kEnd).
bool Occluded(const recon::MeshClosestPoint& bvh, const Eigen::Vector3d& eye,
              const Eigen::Vector3d& p) {
  constexpr double kEnd = 1e-4;
  return bvh.Intersect(eye, p - eye, kEnd, 1 - kEnd).has_value();
}

// Surveyed targets: stickers on the ceiling (a grid every kTargetSpacingM) and on the walls
// kUpperWallM below the ceiling, at known 3D positions (a user sticks them and measures them
// with a tape or a total station), so that cameras looking up see enough control points to be
// posed from them (PnP needs >= 4; COLMAP does not match such views with the downward ones).
std::vector<Eigen::Vector3d> SurveyedTargets(const recon::TriangleMesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
  for (const auto& p : mesh.positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  constexpr double kTargetSpacingM = 1.0, kUpperWallM = 0.4;
  std::vector<Eigen::Vector3d> targets;
  const Eigen::Vector3d size = hi - lo;
  const int nx = std::max(1, int(std::floor(size.x() / kTargetSpacingM)));
  const int ny = std::max(1, int(std::floor(size.y() / kTargetSpacingM)));
  auto along = [](double from, double length, int n, int i) {
    return from + length * (i + 0.5) / n;
  };
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      targets.emplace_back(along(lo.x(), size.x(), nx, i), along(lo.y(), size.y(), ny, j), hi.z());
    }
  }
  const double z = hi.z() - kUpperWallM;
  for (int i = 0; i < nx; ++i) {
    targets.emplace_back(along(lo.x(), size.x(), nx, i), lo.y(), z);
    targets.emplace_back(along(lo.x(), size.x(), nx, i), hi.y(), z);
  }
  for (int j = 0; j < ny; ++j) {
    targets.emplace_back(lo.x(), along(lo.y(), size.y(), ny, j), z);
    targets.emplace_back(hi.x(), along(lo.y(), size.y(), ny, j), z);
  }
  return targets;
}

// Control points for igi-register --markers, at their pixels in each true camera plus Gaussian
// noise of `noise_px` (as a user or a target detector would mark them): the mesh's vertices outside
// the sphere (room and box corners; every photo whose frame holds them, as before) and the surveyed
// targets (SurveyedTargets; only where the camera sees them unoccluded).
Json MarkersOfTruth(const recon::Scene& truth, const std::vector<std::string>& photo_names,
                    double noise_px) {
  std::mt19937_64 rng(2026);
  std::normal_distribution<double> click(0.0, 1.0);
  Json points = Json::object(), pixels = Json::object();
  const int sphere = truth.FindMaterial("glossy_sphere");
  std::vector<Eigen::Vector3d> corners;
  for (size_t t = 0; t < truth.mesh.num_triangles(); ++t) {
    if (truth.mesh.triangle_region[t] == sphere) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = truth.mesh.positions[truth.mesh.triangles[t][k]].cast<double>();
      if (std::none_of(corners.begin(), corners.end(),
                       [&](const Eigen::Vector3d& c) { return (c - p).norm() < 1e-6; })) {
        corners.push_back(p);
      }
    }
  }
  const size_t num_corners = corners.size();
  for (const Eigen::Vector3d& t : SurveyedTargets(truth.mesh)) corners.push_back(t);
  const recon::MeshClosestPoint bvh(truth.mesh);
  for (size_t i = 0; i < corners.size(); ++i) {
    const bool target = i >= num_corners;
    const std::string name =
        target ? "target" + std::to_string(i - num_corners) : "corner" + std::to_string(i);
    points[name] = {corners[i].x(), corners[i].y(), corners[i].z()};
    for (const std::string& photo : photo_names) {
      const std::string cam_name = photo.substr(0, photo.rfind('_'));
      const int c = truth.FindCamera(cam_name);
      if (c < 0) continue;
      const recon::Camera& camera = truth.cameras[c];
      const auto px = camera.ImgFromWorld(corners[i]);
      if (!px || px->x() < 0 || px->y() < 0 || px->x() > camera.width || px->y() > camera.height) {
        continue;
      }
      if (target && Occluded(bvh, camera.CenterInWorld(), corners[i])) continue;
      const double dx = noise_px * click(rng), dy = noise_px * click(rng);
      pixels[photo + ".png"][name] = {px->x() + dx, px->y() + dy};
    }
  }
  return {{"format", "igi-markers"}, {"version", 1}, {"points", points}, {"pixels", pixels}};
}

std::vector<std::string> SynthArgs(const DemoOptions& o, const fs::path& synth) {
  return {"--out",
          synth.string(),
          "--overwrite",
          "--unposed",
          "--textured-walls",
          "--cameras",
          std::to_string(o.cameras + o.ceiling_cameras),
          "--ceiling-cameras",
          std::to_string(o.ceiling_cameras),
          "--width",
          std::to_string(o.width),
          "--height",
          std::to_string(o.height),
          "--spp",
          std::to_string(o.spp),
          "--brackets",
          std::to_string(o.brackets),
          "--stops",
          fmt::format("{}", o.stops),
          "--lamp",
          "point",
          "--validation-lightings",
          "none",
          "--threads",
          std::to_string(o.num_threads)};
}

// The reference of known reflectance: `region`'s true material (its albedo map included) copied
// from truth/scene.json into the capture's scene.json, as if measured beforehand.
void GiveReference(const fs::path& synth, const std::string& region) {
  const Json truth = ReadJsonFile(synth / "truth" / "scene.json");
  if (!truth["materials"].contains(region)) {
    throw InputError(DescribeProblem((synth / "truth" / "scene.json").string(), "materials", region,
                                     "the demo's reference region must exist"));
  }
  Json material = truth["materials"][region];
  if (material.contains("rho_d_map")) {
    material["rho_d_map"] = (fs::path("truth") / material["rho_d_map"].get<std::string>()).string();
  }
  Json scene = ReadJsonFile(synth / "scene.json");
  scene["materials"][region] = material;
  WriteJsonFile(synth / "scene.json", scene);
}

// DIR/00-capture: igi-synth's capture plus camera.json and markers.json in its PHOTOS_DIR.
// Kept when its marker matches the options.
fs::path Capture(const DemoOptions& o, const fs::path& bin, bool* kept) {
  const fs::path dir = o.out / "00-capture";
  const fs::path synth = dir / "synth";
  const std::vector<std::string> args = SynthArgs(o, synth);
  Fingerprint fp;
  for (const std::string& a : args) fp.AddText(a);
  if (o.calibration == DemoCalibration::kReference) fp.AddText("reference " + o.reference_region);
  fp.AddText(fmt::format("marker noise {}", o.marker_noise_px));
  const auto marker = ReadStageMarker(dir);
  *kept = marker && marker->fingerprint == fp.Hex();
  if (*kept) return synth;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto r = RunProcess(bin / "igi-synth", args, dir / "log.txt");
  if (r.exit_code != 0) {
    throw Error("stage 00-capture failed: igi-synth exited " + std::to_string(r.exit_code) + ": " +
                r.last_error + " (log: " + (dir / "log.txt").string() + ")");
  }
  recon::SceneLoadOptions load;
  load.check_images = false;
  const recon::Scene truth = recon::LoadScene(synth / "truth" / "scene.json", load);
  std::vector<std::string> photos;
  for (const auto& e : fs::directory_iterator(synth / "brackets")) {
    if (e.is_directory()) photos.push_back(e.path().filename().string());
  }
  std::sort(photos.begin(), photos.end());  // the markers' noise does not depend on the listing
  const recon::Camera& c0 = truth.cameras.at(0);
  WriteJsonFile(synth / "brackets" / "camera.json", Json{{"format", "igi-camera"},
                                                         {"version", 1},
                                                         {"model", "PINHOLE"},
                                                         {"width", c0.width},
                                                         {"height", c0.height},
                                                         {"params", c0.params}});
  WriteJsonFile(synth / "brackets" / "markers.json",
                MarkersOfTruth(truth, photos, o.marker_noise_px));
  if (o.calibration == DemoCalibration::kReference) GiveReference(synth, o.reference_region);
  WriteStageMarker(dir, StageMarker{"00-capture",
                                    fp.Hex(),
                                    "done",
                                    0,
                                    UtcNow(),
                                    {CommandLine(bin / "igi-synth", args)},
                                    Json::object()});
  return synth;
}

}  // namespace

double MeasureRadianceScale(const fs::path& hdr_dir, const fs::path& synth_dir) {
  const Json sets = ReadJsonFile(synth_dir / "truth.json").at("brackets").at("sets");
  std::vector<double> ratios;
  for (const Json& set : sets) {
    const std::string name = fs::path(set.at("dir").get<std::string>()).filename().string();
    const fs::path hdr = hdr_dir / (name + ".exr");
    if (!fs::exists(hdr)) continue;
    const Image measured = ReadImage(hdr, 3);
    const Image truth = ReadImage(synth_dir / set.at("radiance").get<std::string>(), 3);
    if (measured.pixels.size() != truth.pixels.size()) continue;
    for (size_t i = 0; i < truth.pixels.size(); i += 7) {
      const double t = truth.pixels[i], m = measured.pixels[i];
      if (t > 0 && m > 0 && std::isfinite(m)) ratios.push_back(m / t);
    }
  }
  if (ratios.empty()) throw Error("demo: no HDR pixel to calibrate against in " + hdr_dir.string());
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  return ratios[ratios.size() / 2];
}

Json ComparePoses(const fs::path& registered_scene, const fs::path& truth_scene) {
  recon::SceneLoadOptions load;
  load.check_images = false;
  load.load_geometry = false;
  const recon::Scene truth = recon::LoadScene(truth_scene, load);
  const recon::Scene solved = recon::LoadScene(registered_scene, load);
  Json cameras = Json::array();
  double max_rotation_deg = 0, max_position_m = 0;
  for (const recon::Camera& got : solved.cameras) {
    const int c = truth.FindCamera(got.name.substr(0, got.name.rfind('_')));
    if (c < 0) continue;
    const recon::Camera& want = truth.cameras[c];
    const double rotation_deg =
        want.cam_from_world.rotation.angularDistance(got.cam_from_world.rotation) * 180 /
        std::numbers::pi;
    const double position_m = (want.CenterInWorld() - got.CenterInWorld()).norm();
    const Eigen::Vector3d forward =
        want.cam_from_world.rotation.inverse() * Eigen::Vector3d::UnitZ();
    max_rotation_deg = std::max(max_rotation_deg, rotation_deg);
    max_position_m = std::max(max_position_m, position_m);
    cameras.push_back({{"photo", got.name},
                       {"looks_up", forward.z() > 0},
                       {"rotation_error_deg", rotation_deg},
                       {"position_error_m", position_m}});
  }
  return {{"registered", cameras.size()},
          {"max_rotation_error_deg", max_rotation_deg},
          {"max_position_error_m", max_position_m},
          {"cameras", cameras}};
}

namespace {

// Every problem of `o`; with `typed`, each choice is judged by its flag's text.
ProblemList DemoProblems(const DemoOptions& o, const DemoChoiceFlags* typed) {
  ProblemList p;
  if (typed ? !DemoCalibrationFromName(typed->calibration)
            : !DemoCalibrationFromName(DemoCalibrationName(o.calibration))) {
    p.Add("", "--demo-calibration", typed ? typed->calibration : std::to_string(int(o.calibration)),
          "must be reference, measured or none");
  }
  if (o.out.empty()) p.Add("", "--out", "", "is required");
  if (o.cameras < 3) p.Add("", "--demo-cameras", std::to_string(o.cameras), "must be >= 3");
  if (o.ceiling_cameras < 0) {
    p.Add("", "--demo-ceiling-cameras", std::to_string(o.ceiling_cameras), "must be >= 0");
  }
  if (o.width < 64 || o.height < 48) {
    p.Add("", "--demo-size", fmt::format("{}x{}", o.width, o.height), "must be at least 64x48");
  }
  if (o.spp < 1) p.Add("", "--demo-spp", std::to_string(o.spp), "must be >= 1");
  if (!(o.marker_noise_px >= 0 && o.marker_noise_px <= 10)) {
    p.Add("", "--demo-marker-noise", fmt::format("{}", o.marker_noise_px), "must be in [0, 10] px");
  }
  return p;
}

}  // namespace

constexpr EnumNames<DemoCalibration, 3> kDemoCalibrationNames{
    {{DemoCalibration::kReference, "reference"},
     {DemoCalibration::kMeasured, "measured"},
     {DemoCalibration::kNone, "none"}}};

std::string_view DemoCalibrationName(DemoCalibration calibration) {
  return kDemoCalibrationNames.Name(calibration);
}
std::optional<DemoCalibration> DemoCalibrationFromName(std::string_view name) {
  return kDemoCalibrationNames.FromName(name);
}

void DemoOptions::Validate() const { DemoProblems(*this, nullptr).ThrowIfAny(); }

void DemoOptions::SetChoices(const DemoChoiceFlags& flags) {
  if (const auto c = DemoCalibrationFromName(flags.calibration)) calibration = *c;
  DemoProblems(*this, &flags).ThrowIfAny();
}

namespace {

// Bilinear lookup of a linear RGB texture at `uv` (u right, v up, clamped at the borders; texel
// centres at (i + 0.5) / size, as the renderer reads its textures).
Eigen::Vector3d TextureAt(const Image& texture, const Eigen::Vector2f& uv) {
  const double x = std::clamp(double(uv.x()), 0.0, 1.0) * texture.width - 0.5;
  const double y = (1 - std::clamp(double(uv.y()), 0.0, 1.0)) * texture.height - 0.5;
  const int x0 = std::clamp(int(std::floor(x)), 0, texture.width - 1);
  const int y0 = std::clamp(int(std::floor(y)), 0, texture.height - 1);
  const int x1 = std::min(x0 + 1, texture.width - 1), y1 = std::min(y0 + 1, texture.height - 1);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  Eigen::Vector3d out;
  for (int c = 0; c < 3; ++c) {
    const int ch = std::min(c, texture.channels - 1);
    out[c] = (1 - fy) * ((1 - fx) * texture.at(x0, y0, ch) + fx * texture.at(x1, y0, ch)) +
             fy * ((1 - fx) * texture.at(x0, y1, ch) + fx * texture.at(x1, y1, ch));
  }
  return out;
}

}  // namespace

std::map<std::string, Eigen::Vector3d> SeenTrueAlbedo(const fs::path& truth_scene, int samples,
                                                      uint64_t seed) {
  recon::SceneLoadOptions load;
  load.check_images = false;
  const recon::Scene truth = recon::LoadScene(truth_scene, load);
  std::map<std::string, Eigen::Vector3d> out;
  if (!truth.mesh.has_uvs()) return out;
  std::vector<std::optional<Image>> textures(truth.materials.size());
  for (size_t r = 0; r < truth.materials.size(); ++r) {
    if (truth.materials[r].rho_d_map) textures[r] = ReadImage(*truth.materials[r].rho_d_map, 3);
  }
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < truth.mesh.num_triangles(); ++t) {
    const int r = truth.mesh.triangle_region[t];
    cdf.push_back(total += r >= 0 && textures[r] ? truth.mesh.TriangleArea(t) : 0.0);
  }
  if (!(total > 0)) return out;
  const recon::MeshClosestPoint bvh(truth.mesh);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> sum(truth.materials.size(), Eigen::Vector3d::Zero());
  std::vector<int> count(truth.materials.size(), 0);
  for (int i = 0; i < samples; ++i) {
    const size_t t =
        std::min(size_t(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin()),
                 cdf.size() - 1);
    double b1 = u(rng), b2 = u(rng);
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    const Eigen::Vector3i& tri = truth.mesh.triangles[t];
    const Eigen::Vector3d p = (1 - b1 - b2) * truth.mesh.positions[tri[0]].cast<double>() +
                              b1 * truth.mesh.positions[tri[1]].cast<double>() +
                              b2 * truth.mesh.positions[tri[2]].cast<double>();
    const bool seen =
        std::any_of(truth.cameras.begin(), truth.cameras.end(), [&](const recon::Camera& c) {
          const auto px = c.ImgFromWorld(p);
          return px && px->x() >= 0 && px->y() >= 0 && px->x() < c.width && px->y() < c.height &&
                 !Occluded(bvh, c.CenterInWorld(), p);
        });
    if (!seen) continue;
    const Eigen::Vector2f uv = float(1 - b1 - b2) * truth.mesh.uvs[tri[0]] +
                               float(b1) * truth.mesh.uvs[tri[1]] +
                               float(b2) * truth.mesh.uvs[tri[2]];
    const int r = truth.mesh.triangle_region[t];
    sum[r] += TextureAt(*textures[r], uv);
    ++count[r];
  }
  for (size_t r = 0; r < truth.materials.size(); ++r) {
    if (count[r] > 0) out[truth.materials[r].name] = sum[r] / count[r];
  }
  return out;
}

std::map<std::string, Eigen::Vector3d> TrueAlbedoOverSolvedTexels(const fs::path& solved_scene,
                                                                  const fs::path& truth_json) {
  std::map<std::string, Eigen::Vector3d> out;
  const Json solved = ReadJsonFile(solved_scene).value("materials", Json::object());
  const Json truth = ReadJsonFile(truth_json).value("materials", Json::object());
  const fs::path report_file = solved_scene.parent_path() / "report.json";
  const Json report = fs::exists(report_file) ? ReadJsonFile(report_file) : Json::object();
  for (const auto& [name, t] : truth.items()) {
    if (!t.contains("rho_d_map") || !t["rho_d_map"].is_string() || !solved.contains(name) ||
        !solved[name].contains("rho_d_map") || !solved[name]["rho_d_map"].is_string()) {
      continue;
    }
    // A map on charts igi-solve generated has other UVs than the true texture's.
    bool generated = false;
    for (const Json& r : report.value("regions", Json::array())) {
      if (r.value("name", "") == name && r.contains("albedo_map")) {
        generated = r["albedo_map"].value("generated_uvs", false);
      }
    }
    if (generated) continue;
    const fs::path map = solved_scene.parent_path() / solved[name]["rho_d_map"].get<std::string>();
    const fs::path seen_file = map.parent_path() / (map.stem().string() + "_seen.png");
    if (!fs::exists(seen_file)) continue;
    const Image texture =
        ReadImage(truth_json.parent_path() / t["rho_d_map"].get<std::string>(), 3);
    const Image seen = ReadImage(seen_file, 1);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (int y = 0; y < seen.height; ++y) {
      for (int x = 0; x < seen.width; ++x) {
        if (!(seen.at(x, y, 0) > 0.5f)) continue;
        // Texel centres, v up (row 0 at the top of the UV square), as the renderer reads maps.
        const Eigen::Vector2f uv(float((x + 0.5) / seen.width), float(1 - (y + 0.5) / seen.height));
        sum += TextureAt(texture, uv);
        ++count;
      }
    }
    if (count > 0) out[name] = sum / count;
  }
  return out;
}

Json CompareWithTruth(const fs::path& solved_scene, const fs::path& truth_json,
                      const std::vector<std::string>& given) {
  const Json solved = ReadJsonFile(solved_scene)["materials"];
  Json truth = ReadJsonFile(truth_json)["materials"];
  for (const std::string& name : given) truth.erase(name);
  // A textured region's truth is its texture's mean over the part the photos show (what the
  // solver can recover): over the texels of the solved map that observations cover when the
  // solve wrote its seen mask, else over the surface the true cameras see (when the true scene is
  // there to say which part that is).
  const fs::path truth_scene = truth_json.parent_path() / "truth" / "scene.json";
  const std::map<std::string, Eigen::Vector3d> seen =
      fs::exists(truth_scene) ? SeenTrueAlbedo(truth_scene)
                              : std::map<std::string, Eigen::Vector3d>{};
  const std::map<std::string, Eigen::Vector3d> texels =
      TrueAlbedoOverSolvedTexels(solved_scene, truth_json);
  auto true_rho_d = [&](const std::string& name, const Json& t) {
    if (const auto it = texels.find(name); it != texels.end()) return it->second.mean();
    const auto it = seen.find(name);
    return it != seen.end() ? it->second.mean() : Mean(Rgb(t["rho_d"]));
  };
  std::vector<double> ratios;
  for (const auto& [name, t] : truth.items()) {
    if (!solved.contains(name) || !t.contains("rho_d") || !solved[name].contains("rho_d")) continue;
    const double m = true_rho_d(name, t);
    if (m > 0) ratios.push_back(Mean(Rgb(solved[name]["rho_d"])) / m);
  }
  std::sort(ratios.begin(), ratios.end());
  const double k = ratios.empty() ? 1.0 : ratios[ratios.size() / 2];
  Json regions = Json::array();
  for (const auto& [name, t] : truth.items()) {
    if (!solved.contains(name)) continue;
    Json r = {{"region", name}, {"brdf", t.contains("brdf") ? t["brdf"] : Json("")}};
    for (const char* key : {"rho_d", "rho_s", "alpha"}) {
      if (!t.contains(key) || !solved[name].contains(key)) continue;
      const std::vector<double> tv = Rgb(t[key]), sv = Rgb(solved[name][key]);
      const bool rho_d = std::string(key) == "rho_d";
      const double scale = std::string(key) == "alpha" ? 1.0 : k;
      const double truth_mean = rho_d ? true_rho_d(name, t) : Mean(tv), got = Mean(sv) / scale;
      r[key] = {{"truth", truth_mean},
                {"recovered", Mean(sv)},
                {"recovered_over_k", got},
                {"relative_error", truth_mean > 0 ? got / truth_mean - 1 : 0.0}};
      if (rho_d && (seen.count(name) || texels.count(name))) {
        r[key]["truth_whole_texture"] = Mean(tv);
        if (seen.count(name)) r[key]["truth_seen_by_the_cameras"] = seen.at(name).mean();
        r[key]["truth_is"] =
            texels.count(name)
                ? "the true texture's mean over the texels of the solved map that observations "
                  "cover (its _seen.png)"
                : "the true texture's mean over the surface the photos see";
      }
    }
    regions.push_back(r);
  }
  return {{"format", "igi-demo-summary"},
          {"version", 1},
          {"photometric_scale_k", k},
          {"note",
           "k = median over regions of recovered/true mean rho_d: the HDR maps' free constant "
           "(the response is recovered up to a factor); rho_d and rho_s errors are after "
           "dividing by k, alpha needs no k. A textured region's true rho_d is its texture's "
           "mean over the texels of the solved map that observations cover, or without a map "
           "over the surface some photo sees (truth_seen_by_the_cameras; truth_whole_texture: "
           "over the whole texture)"},
          {"regions", regions}};
}

DemoSummary RunDemo(const DemoOptions& o) {
  o.Validate();
  const fs::path bin = o.bin_dir.empty() ? ExecutableDir() : o.bin_dir;
  fs::create_directories(o.out);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = ProcessCpuSeconds();
  bool kept = false;
  const fs::path synth = Capture(o, bin, &kept);
  const StageOutcome capture{
      "00-capture", kept ? "kept" : "done",
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
      ProcessCpuSeconds() - cpu0};
  RunOptions run;
  run.photos_dir = synth / "brackets";
  run.scene = synth / "scene.json";
  run.out = o.out;
  run.bin_dir = bin;
  run.skip_diagnose = o.skip_diagnose;
  run.solve_args = o.solve_args;
  run.register_args = o.register_args;
  run.diagnose_args = o.diagnose_args;
  run.report_spp = o.report_spp;
  run.num_threads = o.num_threads;
  // Response and HDR first; then the camera's absolute calibration, then the rest of the chain.
  run.stop_after = "02-hdr";
  const RunSummary first = RunPipeline(run);
  run.stop_after.clear();
  // The HDR maps' true scale (what an absolute calibration measures): given to the chain with
  // "measured", only compared with the solved scale with "reference".
  const double true_scale = MeasureRadianceScale(o.out / "02-hdr", synth);
  run.radiance_scale = o.calibration == DemoCalibration::kMeasured ? true_scale : 1.0;
  if (o.calibration == DemoCalibration::kReference) {
    run.solve_args.insert(run.solve_args.end(), {"--photo-scale", "solve"});
  }
  DemoSummary d;
  d.run = RunPipeline(run);
  d.run.seconds += first.seconds + capture.seconds;
  // The stages the first call ran (response, HDR) replace their "kept" entries of the second.
  for (StageOutcome& s : d.run.stages) {
    for (const StageOutcome& f : first.stages) {
      if (f.stage == s.stage && s.status == "kept") s = f;
    }
  }
  d.run.stages.insert(d.run.stages.begin(), capture);
  d.summary = CompareWithTruth(d.run.solved_scene, synth / "truth.json",
                               o.calibration == DemoCalibration::kReference
                                   ? std::vector<std::string>{o.reference_region}
                                   : std::vector<std::string>{});
  d.summary["calibration"] = std::string(DemoCalibrationName(o.calibration));
  d.summary["radiance_scale"] = run.radiance_scale;
  d.summary["true_radiance_scale"] = true_scale;
  const fs::path solve_report = o.out / "04-solve" / "report.json";
  if (o.calibration == DemoCalibration::kReference && fs::exists(solve_report)) {
    const Json k = ReadJsonFile(solve_report).value("photo_scale", Json());
    if (k.is_object()) {
      d.summary["solved_radiance_scale"] = k;
      d.summary["solved_radiance_scale_error"] = k["scale"].get<double>() / true_scale - 1;
    }
  }
  const fs::path registered = o.out / "03-register" / "scene.json";
  if (fs::exists(registered)) {
    d.summary["poses"] = ComparePoses(registered, synth / "truth" / "scene.json");
    int photos = 0;
    for (const auto& e : fs::directory_iterator(synth / "brackets")) photos += e.is_directory();
    d.summary["poses"]["photos"] = photos;
  }
  d.summary["seconds"] = d.run.seconds;
  Json stages = Json::array();
  for (const StageOutcome& s : d.run.stages) {
    stages.push_back({{"stage", s.stage},
                      {"status", s.status},
                      {"seconds", s.seconds},
                      {"cpu_seconds", s.cpu_seconds}});
  }
  d.summary["stages"] = stages;
  d.summary["capture"] = {{"cameras", o.cameras}, {"ceiling_cameras", o.ceiling_cameras},
                          {"width", o.width},     {"height", o.height},
                          {"spp", o.spp},         {"brackets", o.brackets},
                          {"stops", o.stops}};
  WriteJsonFile(o.out / "demo_summary.json", d.summary);
  d.table.push_back(fmt::format("{:<14} {:<6} {:>9} {:>9} {:>8}", "region", "param", "truth",
                                "solved/k", "error"));
  for (const Json& r : d.summary["regions"]) {
    for (const char* key : {"rho_d", "rho_s", "alpha"}) {
      if (!r.contains(key)) continue;
      d.table.push_back(
          fmt::format("{:<14} {:<6} {:>9.4f} {:>9.4f} {:>+7.1f}%", r["region"].get<std::string>(),
                      key, r[key]["truth"].get<double>(), r[key]["recovered_over_k"].get<double>(),
                      100 * r[key]["relative_error"].get<double>()));
    }
  }
  if (d.summary.contains("solved_radiance_scale_error")) {
    d.table.push_back(
        fmt::format("HDR scale solved from the reference {}: {:.4f} (true {:.4f}, {:+.1f}%)",
                    o.reference_region, d.summary["solved_radiance_scale"]["scale"].get<double>(),
                    true_scale, 100 * d.summary["solved_radiance_scale_error"].get<double>()));
  }
  if (d.summary.contains("poses")) {
    const Json& p = d.summary["poses"];
    d.table.push_back(fmt::format(
        "registered {} of {} photos; pose errors up to {:.3f} deg, {:.1f} mm (see "
        "demo_summary.json)",
        p["registered"].get<int>(), p["photos"].get<int>(),
        p["max_rotation_error_deg"].get<double>(), 1000 * p["max_position_error_m"].get<double>()));
  }
  d.table.push_back(fmt::format("photometric scale k = {:.4f} (see demo_summary.json)",
                                d.summary["photometric_scale_k"].get<double>()));
  return d;
}

}  // namespace igi::pipeline
