#include "pipeline/demo.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "pipeline/stage_marker.h"
#include "pipeline/subprocess.h"
#include "recon/scene.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"

namespace igi {
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

// Control points: the mesh's vertices outside the sphere (room and box corners) at their exact
// pixels in each true camera (as a user would mark them), for igi-register --markers.
Json MarkersOfTruth(const Scene& truth, const std::vector<std::string>& photo_names) {
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
  for (size_t i = 0; i < corners.size(); ++i) {
    const std::string name = "corner" + std::to_string(i);
    points[name] = {corners[i].x(), corners[i].y(), corners[i].z()};
    for (const std::string& photo : photo_names) {
      const std::string cam_name = photo.substr(0, photo.rfind('_'));
      const int c = truth.FindCamera(cam_name);
      if (c < 0) continue;
      const Camera& camera = truth.cameras[c];
      const auto px = camera.ImgFromWorld(corners[i]);
      if (!px || px->x() < 0 || px->y() < 0 || px->x() > camera.width || px->y() > camera.height) {
        continue;
      }
      pixels[photo + ".png"][name] = {px->x(), px->y()};
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
          std::to_string(o.cameras),
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
    throw InputError(DescribeProblem((synth / "truth" / "scene.json").string(), "materials",
                                     region, "the demo's reference region must exist"));
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
fs::path Capture(const DemoOptions& o, const fs::path& bin) {
  const fs::path dir = o.out / "00-capture";
  const fs::path synth = dir / "synth";
  const std::vector<std::string> args = SynthArgs(o, synth);
  Fingerprint fp;
  for (const std::string& a : args) fp.AddText(a);
  if (o.calibration == "reference") fp.AddText("reference " + o.reference_region);
  const auto marker = ReadStageMarker(dir);
  if (marker && marker->fingerprint == fp.Hex()) return synth;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto r = RunProcess(bin / "igi-synth", args, dir / "log.txt");
  if (r.exit_code != 0) {
    throw Error("stage 00-capture failed: igi-synth exited " + std::to_string(r.exit_code) + ": " +
                r.last_error + " (log: " + (dir / "log.txt").string() + ")");
  }
  SceneLoadOptions load;
  load.check_images = false;
  const Scene truth = LoadScene(synth / "truth" / "scene.json", load);
  std::vector<std::string> photos;
  for (const auto& e : fs::directory_iterator(synth / "brackets")) {
    if (e.is_directory()) photos.push_back(e.path().filename().string());
  }
  const Camera& c0 = truth.cameras.at(0);
  WriteJsonFile(synth / "brackets" / "camera.json", Json{{"format", "igi-camera"},
                                                         {"version", 1},
                                                         {"model", "PINHOLE"},
                                                         {"width", c0.width},
                                                         {"height", c0.height},
                                                         {"params", c0.params}});
  WriteJsonFile(synth / "brackets" / "markers.json", MarkersOfTruth(truth, photos));
  if (o.calibration == "reference") GiveReference(synth, o.reference_region);
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

void DemoOptions::Validate() const {
  ProblemList p;
  if (calibration != "reference" && calibration != "measured" && calibration != "none") {
    p.Add("", "--demo-calibration", calibration, "must be reference, measured or none");
  }
  if (out.empty()) p.Add("", "--out", "", "is required");
  if (cameras < 3) p.Add("", "--demo-cameras", std::to_string(cameras), "must be >= 3");
  if (width < 64 || height < 48) {
    p.Add("", "--demo-size", fmt::format("{}x{}", width, height), "must be at least 64x48");
  }
  if (spp < 1) p.Add("", "--demo-spp", std::to_string(spp), "must be >= 1");
  p.ThrowIfAny();
}

Json CompareWithTruth(const fs::path& solved_scene, const fs::path& truth_json,
                      const std::vector<std::string>& given) {
  const Json solved = ReadJsonFile(solved_scene)["materials"];
  Json truth = ReadJsonFile(truth_json)["materials"];
  for (const std::string& name : given) truth.erase(name);
  std::vector<double> ratios;
  for (const auto& [name, t] : truth.items()) {
    if (!solved.contains(name) || !t.contains("rho_d") || !solved[name].contains("rho_d")) continue;
    const double m = Mean(Rgb(t["rho_d"]));
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
      const double scale = std::string(key) == "alpha" ? 1.0 : k;
      const double truth_mean = Mean(tv), got = Mean(sv) / scale;
      r[key] = {{"truth", truth_mean},
                {"recovered", Mean(sv)},
                {"recovered_over_k", got},
                {"relative_error", truth_mean > 0 ? got / truth_mean - 1 : 0.0}};
    }
    regions.push_back(r);
  }
  return {{"format", "igi-demo-summary"},
          {"version", 1},
          {"photometric_scale_k", k},
          {"note",
           "k = median over regions of recovered/true mean rho_d: the HDR maps' free constant "
           "(the response is recovered up to a factor); rho_d and rho_s errors are after "
           "dividing by k, alpha needs no k"},
          {"regions", regions}};
}

DemoSummary RunDemo(const DemoOptions& o) {
  o.Validate();
  const fs::path bin = o.bin_dir.empty() ? ExecutableDir() : o.bin_dir;
  fs::create_directories(o.out);
  const fs::path synth = Capture(o, bin);
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
  run.radiance_scale = o.calibration == "measured" ? true_scale : 1.0;
  if (o.calibration == "reference") {
    run.solve_args.insert(run.solve_args.end(), {"--photo-scale", "solve"});
  }
  DemoSummary d;
  d.run = RunPipeline(run);
  d.run.seconds += first.seconds;
  d.summary = CompareWithTruth(
      d.run.solved_scene, synth / "truth.json",
      o.calibration == "reference" ? std::vector<std::string>{o.reference_region}
                                   : std::vector<std::string>{});
  d.summary["calibration"] = o.calibration;
  d.summary["radiance_scale"] = run.radiance_scale;
  d.summary["true_radiance_scale"] = true_scale;
  const fs::path solve_report = o.out / "04-solve" / "report.json";
  if (o.calibration == "reference" && fs::exists(solve_report)) {
    const Json k = ReadJsonFile(solve_report).value("photo_scale", Json());
    if (k.is_object()) {
      d.summary["solved_radiance_scale"] = k;
      d.summary["solved_radiance_scale_error"] = k["scale"].get<double>() / true_scale - 1;
    }
  }
  d.summary["seconds"] = d.run.seconds;
  d.summary["capture"] = {{"cameras", o.cameras}, {"width", o.width},       {"height", o.height},
                          {"spp", o.spp},         {"brackets", o.brackets}, {"stops", o.stops}};
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
    d.table.push_back(fmt::format(
        "HDR scale solved from the reference {}: {:.4f} (true {:.4f}, {:+.1f}%)",
        o.reference_region, d.summary["solved_radiance_scale"]["scale"].get<double>(), true_scale,
        100 * d.summary["solved_radiance_scale_error"].get<double>()));
  }
  d.table.push_back(fmt::format("photometric scale k = {:.4f} (see demo_summary.json)",
                                d.summary["photometric_scale_k"].get<double>()));
  return d;
}

}  // namespace igi
