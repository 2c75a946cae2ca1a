// The stage bodies of igi-run (pipeline.h): response, HDR, registration, solve, diagnose.
// The report stage is in run_report.cpp.
#include <spdlog/spdlog.h>

#include <optional>

#include "hdr/correction.h"
#include "recon/scene_document.h"
#include "tools/common/error.h"
#include "tools/common/image.h"
#include "tools/common/json.h"
#include "tools/pipeline/pipeline_internal.h"
#include "tools/pipeline/scene_assembly.h"

namespace igi::pipeline::internal {
namespace fs = std::filesystem;

namespace {

std::vector<std::string> Paths(const std::vector<fs::path>& files) {
  std::vector<std::string> out;
  for (const fs::path& f : files) out.push_back(f.string());
  return out;
}

void Append(std::vector<std::string>* args, const std::vector<std::string>& more) {
  args->insert(args->end(), more.begin(), more.end());
}

}  // namespace

void ResponseStage(const Context& ctx, StageRun* run) {
  const PhotoSource& p = ctx.layout.photos[ctx.layout.ResponseSource()];
  std::vector<std::string> args = ThreadArgs(ctx);
  args.push_back("response");
  Append(&args, Paths(p.images));
  if (!p.exposure_file.empty()) Append(&args, {"--exposure-file", p.exposure_file.string()});
  Append(&args, {"--out", (run->dir() / "response.json").string()});
  run->Tool("igi-calib", args);
  run->details["bracket"] = p.name;
  run->details["images"] = p.images.size();
}

void HdrStage(const Context& ctx, StageRun* run) {
  const fs::path response = ctx.Dir("01-response") / "response.json";
  // The camera's vignetting divided out of every photo and its colour matrix applied (igi-hdr
  // --camera, --colour; a radiance map given as it is, here).
  const bool vignetting = ctx.camera && ctx.camera->vignetting;
  const hdr::RadianceCorrection correction(vignetting ? ctx.layout.camera : fs::path(),
                                           ctx.layout.colour);
  if (vignetting) {
    const calib::CameraVignetting& v = *ctx.camera->vignetting;
    run->details["vignetting"] = {{"file", ctx.layout.camera.string()},
                                  {"k1", v.model.k1},
                                  {"k2", v.model.k2},
                                  {"method", v.method},
                                  {"rms_ln", v.rms_ln}};
  }
  if (ctx.colour) {
    std::vector<std::vector<double>> rows;
    for (int r = 0; r < 3; ++r) {
      rows.push_back(
          {ctx.colour->matrix(r, 0), ctx.colour->matrix(r, 1), ctx.colour->matrix(r, 2)});
    }
    run->details["colour"] = {{"file", ctx.layout.colour.string()},
                              {"matrix", rows},
                              {"input", std::string(calib::ColourInputName(ctx.colour->input))},
                              {"delta_e2000_mean", ctx.colour->delta_e2000.mean},
                              {"delta_e2000_max", ctx.colour->delta_e2000.max}};
  }
  Json photos = Json::array();
  for (const PhotoSource& p : ctx.layout.photos) {
    const fs::path out = run->dir() / (p.name + ".exr");
    photos.push_back({{"name", p.name}, {"kind", KindName(p.kind)}, {"lighting", p.lighting}});
    if (p.kind == PhotoSourceKind::kRadiance) {
      WriteImageOptions wo;
      wo.type = PixelType::kFloat;
      Image radiance = ReadImage(p.images[0], 3);
      correction.Check(p.images[0].string(), radiance.width, radiance.height, 3, false);
      correction.Apply(radiance.pixels.data(), 0, radiance.height, radiance.width, 3);
      WriteImage(out, radiance, wo);
      continue;
    }
    std::vector<std::string> args = ThreadArgs(ctx);
    if (p.kind == PhotoSourceKind::kCapture) {
      Append(&args, {"--manifest", p.manifest.string()});
    } else {
      Append(&args, Paths(p.images));
      if (p.kind == PhotoSourceKind::kBracket) Append(&args, {"--response", response.string()});
      if (!p.exposure_file.empty()) Append(&args, {"--exposure-file", p.exposure_file.string()});
    }
    if (vignetting) Append(&args, {"--camera", ctx.layout.camera.string()});
    if (ctx.colour) Append(&args, {"--colour", ctx.layout.colour.string()});
    Append(&args, {"--out", out.string()});
    run->Tool("igi-hdr", args);
  }
  run->details["photos"] = photos;
}

void RegisterStage(const Context& ctx, StageRun* run) {
  const fs::path images = run->dir() / "images";
  for (const PhotoSource& p : ctx.layout.photos) {
    TonemapForRegistration(ctx.Dir("02-hdr") / (p.name + ".exr"), images / (p.name + ".png"));
  }
  const fs::path out = run->dir() / "register";
  std::vector<std::string> args = ThreadArgs(ctx);
  Append(&args, {"--images", images.string(), "--scene", ctx.options.scene.string(), "--out",
                 out.string()});
  if (ctx.camera && ctx.camera->HasIntrinsics()) {
    Append(&args, {"--camera", ctx.layout.camera.string()});
  }
  if (!ctx.layout.markers.empty()) Append(&args, {"--markers", ctx.layout.markers.string()});
  Append(&args, ctx.options.register_args);
  run->Tool("igi-register", args, /*partial_ok=*/true);

  SolvableSceneInputs in;
  in.input_scene = ctx.scene_json;
  in.input_dir = ctx.scene.dir;
  in.registered_scene = ReadJsonFile(out / "scene.json");
  in.photos = ctx.layout.photos;
  in.hdr_dir = ctx.Dir("02-hdr");
  in.out_dir = run->dir();
  std::vector<std::string> unregistered;
  const Json scene = SolvableScene(in, &unregistered);
  if (scene["photos"].empty()) {
    throw Error("stage 03-register failed: no photo registered (see " +
                (out / "report.json").string() + ")");
  }
  WriteJsonFile(run->dir() / "scene.json", scene);
  run->details["registered"] = scene["photos"].size();
  run->details["unregistered"] = unregistered;
}

// The scene igi-solve gets: the solvable scene as it is, or with --radiance-scale written as
// every photo's exposure_scale and the calibrated lights in place (a copy in
// DIR/04-solve/input/, its paths rebased).
fs::path SolveScene(const Context& ctx, const fs::path& stage_dir) {
  if (ctx.options.radiance_scale == 1.0 && ctx.lights.empty()) return ctx.SolveInput();
  const fs::path input = ctx.SolveInput();
  const fs::path dir = stage_dir / "input";
  fs::create_directories(dir);
  Json doc = ReadJsonFile(input);
  ctx.ApplyLights(&doc);
  recon::SceneDocument scene(std::move(doc));
  scene.RebasePaths(input.parent_path(), dir);
  for (size_t i = 0; i < scene.NumPhotos(); ++i) {
    scene.SetPhotoExposure(i, scene.PhotoExposure(i).value_or(1.0) * ctx.options.radiance_scale);
  }
  WriteJsonFile(dir / "scene.json", scene.json());
  return dir / "scene.json";
}

void SolveStage(const Context& ctx, StageRun* run) {
  std::vector<std::string> args = {SolveScene(ctx, run->dir()).string(), "--out",
                                   run->dir().string()};
  Append(&args, ThreadArgs(ctx));
  Append(&args, ctx.options.solve_args);
  run->Tool("igi-solve", args, /*partial_ok=*/true);
  run->details["radiance_scale"] = ctx.options.radiance_scale;
  if (!ctx.lights.empty()) {
    Json names = Json::array();
    for (const auto& [name, entry] : ctx.lights.items()) names.push_back(name);
    run->details["lights"] = {{"file", ctx.lights_file.string()}, {"names", names}};
  }
}

// The scene igi-diagnose gets: the one igi-solve got (materials unknown where they were, so
// that igi-diagnose solves them itself with its held-out pixels left out, and re-solves them
// with every candidate model), each photo's exposure_scale taken from the solved scene (which
// carries --radiance-scale and a scale igi-solve solved from a reference). The solved scene
// itself would make its refits hold every albedo fixed and let the held-out pixels into the fit.
fs::path DiagnoseScene(const Context& ctx, const fs::path& stage_dir) {
  const fs::path input = ctx.SolveInput();
  const recon::SceneDocument solved(ReadJsonFile(ctx.Dir("04-solve") / "scene.json"));
  const fs::path dir = stage_dir / "input";
  fs::create_directories(dir);
  Json doc = ReadJsonFile(input);
  ctx.ApplyLights(&doc);
  recon::SceneDocument scene(std::move(doc));
  scene.RebasePaths(input.parent_path(), dir);
  if (scene.NumPhotos() != solved.NumPhotos()) {
    throw Error("stage 05-diagnose: " + (ctx.Dir("04-solve") / "scene.json").string() + " has " +
                std::to_string(solved.NumPhotos()) + " photos, its input " +
                std::to_string(scene.NumPhotos()));
  }
  for (size_t i = 0; i < scene.NumPhotos(); ++i) {
    if (const std::optional<double> scale = solved.PhotoExposure(i)) {
      scene.SetPhotoExposure(i, *scale);
    }
  }
  WriteJsonFile(dir / "scene.json", scene.json());
  return dir / "scene.json";
}

void DiagnoseStage(const Context& ctx, StageRun* run) {
  std::vector<std::string> args = {DiagnoseScene(ctx, run->dir()).string(), "--out",
                                   run->dir().string()};
  Append(&args, ThreadArgs(ctx));
  if (ctx.options.diagnose_spp > 0) {
    Append(&args, {"--spp", std::to_string(ctx.options.diagnose_spp)});
  }
  Append(&args, ctx.options.diagnose_args);
  run->Tool("igi-diagnose", args, /*partial_ok=*/true);
}

}  // namespace igi::pipeline::internal
