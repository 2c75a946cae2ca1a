#include "tools/pipeline/pipeline.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <chrono>
#include <functional>

#include "recon/scene_document.h"
#include "tools/common/error.h"
#include "tools/pipeline/pipeline_internal.h"
#include "tools/pipeline/subprocess.h"

namespace igi::pipeline {
namespace fs = std::filesystem;
using internal::Context;
using internal::StageRun;

namespace internal {

void Context::ApplyLights(Json* scene_json) const {
  for (const auto& [name, entry] : lights.items()) (*scene_json)["lights"][name] = entry;
}

// Reads lights.json's "lights" into ctx and puts them into ctx.scene_json, checked by the scene
// reader's rules: every name must be a light of the scene.
void ReadCalibratedLights(const fs::path& file, Context* ctx) {
  const Json doc = ReadJsonFile(file);
  ProblemList problems;
  if (doc.value("format", "") != "igi-lights" || !doc.contains("lights") ||
      !doc["lights"].is_object()) {
    problems.Add(file.string(), "format", doc.value("format", ""),
                 "must be an igi-lights file with a \"lights\" object (igi-calib lights)");
    problems.ThrowIfAny();
  }
  for (const auto& [name, entry] : doc["lights"].items()) {
    if (!ctx->scene_json.contains("lights") || !ctx->scene_json["lights"].contains(name)) {
      problems.Add(file.string(), "lights." + name, "", "not a light of the scene");
    }
  }
  problems.ThrowIfAny();
  ctx->lights_file = file;
  ctx->lights = doc["lights"];
  ctx->ApplyLights(&ctx->scene_json);
  recon::SceneLoadOptions load;
  load.load_geometry = load.check_images = false;
  recon::SceneDocument(ctx->scene_json).Validate(ctx->options.scene.parent_path(), load);
}

fs::path Context::SolveInput() const {
  return options.hdr_photos ? options.scene : Dir("03-register") / "scene.json";
}

StageRun::StageRun(const Context& ctx, std::string stage)
    : ctx_(ctx), stage_(std::move(stage)), dir_(ctx.Dir(stage_)) {}

void StageRun::Tool(const std::string& tool, const std::vector<std::string>& args,
                    bool partial_ok) {
  const fs::path exe = ctx_.bin / tool;
  commands.push_back(CommandLine(exe, args));
  spdlog::info("{}: {}", stage_, commands.back());
  const ProcessResult r = RunProcess(exe, args, dir_ / "log.txt");
  if (r.exit_code == 0) return;
  if (r.exit_code == 3 && partial_ok) {
    partial_ = true;
    partial_lines.push_back(stage_ + ": " + tool + " finished partly (exit 3): " + r.last_error);
    return;
  }
  throw Error("stage " + stage_ + " failed: " + tool + " exited " + std::to_string(r.exit_code) +
              (r.last_error.empty() ? "" : ": " + r.last_error) +
              " (log: " + (dir_ / "log.txt").string() + ")");
}

std::vector<std::string> ThreadArgs(const Context& ctx) {
  return {"--threads", std::to_string(ctx.options.num_threads)};
}

}  // namespace internal

namespace {

struct Stage {
  std::string name;
  bool applies;
  std::function<void(Fingerprint*)> inputs;
  std::function<void(const Context&, StageRun*)> body;
};

std::vector<std::string> Lightings(const recon::Scene& scene) {
  std::vector<std::string> names;
  for (const recon::Lighting& l : scene.lightings) names.push_back(l.name);
  return names;
}

// Everything checked before anything is written.
Context Validate(const RunOptions& o) {
  o.Validate();
  Context ctx;
  ctx.options = o;
  ctx.bin = o.bin_dir.empty() ? ExecutableDir() : o.bin_dir;
  recon::SceneLoadOptions load;
  load.check_images = o.hdr_photos;
  ctx.scene = recon::LoadScene(o.scene, load);
  ctx.scene_json = ReadJsonFile(o.scene);
  if (o.hdr_photos) {
    if (ctx.scene.photos.empty()) {
      throw InputError(DescribeProblem(o.scene.string(), "photos", "none",
                                       "--hdr-photos needs the scene's photos and cameras"));
    }
  } else {
    ctx.layout = ScanPhotosDir(o.photos_dir, Lightings(ctx.scene));
    if (!o.camera.empty()) ctx.layout.camera = o.camera;
    if (!o.colour.empty()) ctx.layout.colour = o.colour;
    if (!ctx.layout.camera.empty()) ctx.camera = calib::ReadCameraFile(ctx.layout.camera);
    if (!ctx.layout.colour.empty()) ctx.colour = calib::ReadColourFile(ctx.layout.colour);
    if (!o.lights.empty()) ctx.layout.lights = o.lights;
  }
  const fs::path lights = o.hdr_photos ? o.lights : ctx.layout.lights;
  if (!lights.empty()) ReadCalibratedLights(lights, &ctx);
  std::vector<std::string> tools = {"igi-solve", "igi-render", "igi-export"};
  if (!o.hdr_photos) tools.insert(tools.end(), {"igi-calib", "igi-hdr", "igi-register"});
  if (!o.skip_diagnose) tools.push_back("igi-diagnose");
  for (const std::string& t : tools) {
    if (!fs::exists(ctx.bin / t)) {
      throw Error(t + " not found in " + ctx.bin.string() +
                  (t == "igi-diagnose" ? " (build it, or pass --skip-diagnose)"
                                       : " (build every executable, or give --bin-dir)"));
    }
  }
  return ctx;
}

void AddSceneFiles(const Context& ctx, Fingerprint* fp, bool photos) {
  fp->AddFile(ctx.options.scene);
  for (const fs::path& g : ctx.scene.geometry_files) fp->AddFile(g);
  for (const recon::Material& m : ctx.scene.materials) {
    if (m.rho_d_map) fp->AddFile(ctx.scene.dir / *m.rho_d_map);
  }
  if (!photos) return;
  for (const recon::Photo& p : ctx.scene.photos) {
    fp->AddFile(ctx.scene.dir / p.file);
    if (p.mask) fp->AddFile(ctx.scene.dir / *p.mask);
  }
}

std::vector<Stage> Stages(const Context& ctx) {
  using namespace internal;
  const RunOptions& o = ctx.options;
  const bool ldr = !o.hdr_photos && ctx.layout.ResponseSource() >= 0;
  return {
      {"01-response", ldr,
       [&](Fingerprint* fp) {
         const PhotoSource& p = ctx.layout.photos[ctx.layout.ResponseSource()];
         for (const fs::path& f : p.images) fp->AddFile(f);
         fp->AddFile(p.exposure_file);
       },
       ResponseStage},
      {"02-hdr", !o.hdr_photos,
       [&](Fingerprint* fp) {
         fp->AddFile(o.photos_dir);
         if (ctx.camera) fp->AddFile(ctx.layout.camera);
         if (ctx.colour) fp->AddFile(ctx.layout.colour);
       },
       HdrStage},
      {"03-register", !o.hdr_photos,
       [&](Fingerprint* fp) {
         AddSceneFiles(ctx, fp, false);
         if (!ctx.lights_file.empty()) fp->AddFile(ctx.lights_file);
         for (const std::string& a : o.register_args) fp->AddText(a);
       },
       RegisterStage},
      {"04-solve", true,
       [&](Fingerprint* fp) {
         if (o.hdr_photos) AddSceneFiles(ctx, fp, true);
         if (!ctx.lights_file.empty()) fp->AddFile(ctx.lights_file);
         for (const std::string& a : o.solve_args) fp->AddText(a);
         fp->AddText(fmt::format("radiance_scale {:.17g}", o.radiance_scale));
       },
       SolveStage},
      {"05-diagnose", !o.skip_diagnose,
       [&](Fingerprint* fp) {
         fp->AddText("input: the solve's input, solved exposure_scale");
         fp->AddText(std::to_string(o.diagnose_spp));
         for (const std::string& a : o.diagnose_args) fp->AddText(a);
       },
       DiagnoseStage},
      {"06-report", true,
       [&](Fingerprint* fp) {
         fp->AddText(std::to_string(o.report_spp) + "/" + std::to_string(o.report_photos) + "/" +
                     std::to_string(o.report_lightings));
         fp->AddText(fmt::format("report_megapixels {:.17g}", o.report_megapixels));
       },
       ReportStage},
  };
}

double Since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

double ProcessCpuSeconds() {
  auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  double total = 0;
  for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage u{};
    if (::getrusage(who, &u) == 0) total += seconds(u.ru_utime) + seconds(u.ru_stime);
  }
  return total;
}

const std::vector<std::string>& StageNames() {
  static const std::vector<std::string> names = {"01-response", "02-hdr",      "03-register",
                                                 "04-solve",    "05-diagnose", "06-report"};
  return names;
}

RunSummary RunPipeline(const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Context ctx = Validate(options);
  fs::create_directories(options.out);
  RunSummary summary;
  std::string previous;
  bool redo = false;
  for (const Stage& stage : Stages(ctx)) {
    Fingerprint fp;
    fp.AddText(stage.name);
    fp.AddText(previous);
    if (stage.applies) stage.inputs(&fp);
    const std::string hex = stage.applies ? fp.Hex() : "skipped:" + fp.Hex();
    previous = hex;
    const fs::path dir = ctx.Dir(stage.name);
    const auto marker = ReadStageMarker(dir);
    if (!redo && marker && marker->fingerprint == hex) {
      spdlog::info("{}: kept (finished {}, inputs unchanged)", stage.name, marker->finished_utc);
      summary.stages.push_back({stage.name, "kept", 0});
      if (marker->status == "partial") {
        summary.partial = true;
        summary.partial_lines.push_back(stage.name +
                                        ": kept; it finished partly (see its log.txt)");
      }
      if (stage.name == options.stop_after) break;
      continue;
    }
    redo = true;  // every later stage is redone
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = ProcessCpuSeconds();
    StageRun run(ctx, stage.name);
    if (stage.applies) stage.body(ctx, &run);
    const double cpu_seconds = ProcessCpuSeconds() - cpu0;
    run.details["cpu_seconds"] = cpu_seconds;
    StageMarker m{
        stage.name, hex,      !stage.applies ? "skipped" : run.partial() ? "partial" : "done",
        Since(t0),  UtcNow(), run.commands,
        run.details};
    WriteStageMarker(dir, m);
    spdlog::info("{}: {} in {:.1f} s ({:.1f} s CPU)", stage.name, m.status, m.seconds, cpu_seconds);
    summary.stages.push_back({stage.name, m.status, m.seconds, cpu_seconds});
    summary.partial = summary.partial || run.partial();
    for (const std::string& l : run.partial_lines) summary.partial_lines.push_back(l);
    if (stage.name == options.stop_after) break;
  }
  summary.report = options.out / "report.html";
  summary.solved_scene = ctx.Dir("04-solve") / "scene.json";
  summary.seconds = Since(start);
  return summary;
}

}  // namespace igi::pipeline
