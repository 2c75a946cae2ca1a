#include "solver/synth/synthesize.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include "recon/scene.h"
#include "solver/render/render.h"
#include "solver/render/sampling.h"
#include "solver/synth/camera_placement.h"
#include "solver/synth/effects.h"
#include "solver/synth/room_builder.h"
#include "solver/synth/sensor.h"
#include "tools/common/atomic_file.h"
#include "tools/common/error.h"
#include "tools/common/json.h"

namespace igi::synth {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct PhotoJob {
  int camera = 0;        // index into the placed cameras
  std::string lighting;  // L0 or L1
  std::string file;      // relative to the folder
};

void CheckOutputFolder(const SynthOptions& options) {
  const fs::path& out = options.out;
  if (!fs::exists(out)) return;
  if (!fs::is_directory(out)) {
    throw InputError(DescribeProblem("--out", "", out.string(), "exists and is not a folder"));
  }
  if (!options.overwrite && !fs::is_empty(out)) {
    throw InputError(
        DescribeProblem("--out", "", out.string(), "folder is not empty (use --overwrite)"));
  }
}

bool Has(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// Leaves the options' unknowns out of every reflective material.
Json DeclaredMaterials(const Json& materials, const std::vector<std::string>& unknowns) {
  Json out = materials;
  for (auto& [name, m] : out.items()) {
    const std::string brdf = m["brdf"].get<std::string>();
    if (brdf == "emitter" || brdf == "black") continue;
    if (Has(unknowns, "rho_d")) m.erase("rho_d"), m.erase("rho_d_map");
    if (Has(unknowns, "rho_s")) m.erase("rho_s");
    if (Has(unknowns, "alpha")) {
      for (const char* k : {"alpha", "alpha_x", "alpha_y", "tangent"}) m.erase(k);
    }
  }
  return out;
}

// The true scene written at truth/scene.json: its paths are relative to truth/.
Json RelocateToTruthFolder(Json doc) {
  auto move = [](Json& path) {
    const std::string p = path.get<std::string>();
    path = p.rfind("truth/", 0) == 0 ? p.substr(6) : "../" + p;
  };
  for (auto& g : doc["geometry"]) move(g["file"]);
  for (auto& [name, m] : doc["materials"].items()) {
    if (m.contains("rho_d_map")) move(m["rho_d_map"]);
  }
  for (auto& [name, l] : doc["lights"].items()) {
    if (l.contains("file")) move(l["file"]);
  }
  return doc;
}

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  WriteFileAtomic(path, text);
}

WriteImageOptions Type(PixelType type, const std::string& compression = "") {
  WriteImageOptions w;
  w.type = type;
  w.compression = compression;
  return w;
}

void WriteExr(const fs::path& path, const Image& image) {
  fs::create_directories(path.parent_path());
  WriteImage(path, image, Type(PixelType::kFloat, "zip"));
}

struct Rendered {
  Json photos = Json::array();
  Json photo_truth = Json::object();
  Json bracket_sets = Json::array();
  Json validation = Json::array();
  int64_t saturated = 0;
  double render_seconds = 0;
};

class Pipeline {
 public:
  Pipeline(const SynthOptions& options, const recon::Scene& true_scene,
           const std::vector<PlacedCamera>& cameras, const PhotoEffects& post,
           const ResponseCurve* response)
      : o_(options), scene_(true_scene), cameras_(cameras), post_(post), response_(response) {}

  Image Render(const PhotoJob& job, uint64_t stream, Rendered* r) {
    const int lighting = scene_.FindLighting(job.lighting);
    auto it = renderers_.find(lighting);
    if (it == renderers_.end()) {
      it = renderers_.emplace(lighting, std::make_unique<render::Renderer>(scene_, lighting)).first;
    }
    render::RenderOptions ro;
    ro.spp = o_.spp;
    ro.seed = render::MixBits(o_.seed * 0x100000001b3ULL + stream);
    ro.num_threads = o_.num_threads;
    const auto start = Clock::now();
    Image image = it->second->Render(TrueCamera(job), ro);
    r->render_seconds += Since(start);
    return image;
  }

  void Photo(const PhotoJob& job, int index, Rendered* r) {
    Image linear = Render(job, uint64_t(index), r);
    post_.ApplyBeforeSensor(job.file, TrueCamera(job), &linear);
    Json photo = {{"file", job.file},
                  {"camera", cameras_[job.camera].camera.name},
                  {"lighting", job.lighting},
                  {"mask", nullptr}};
    Json truth = Json::object();
    const double exposure_s = ChooseExposure(linear, o_.sensor);
    Image out = linear;
    if (o_.noise == NoiseModel::kRealistic) {
      SensorResult sr =
          SimulateSensor(linear, o_.sensor, exposure_s,
                         render::MixBits(o_.seed ^ (0x5e0500ULL + index)), o_.num_threads);
      out = std::move(sr.photo);
      truth["exposure_s"] = exposure_s;
      truth["saturated_pixels"] = sr.saturated_pixels;
      r->saturated += sr.saturated_pixels;
      if (sr.saturated_pixels > 0) {
        const std::string mask = job.file.substr(0, job.file.size() - 4) + "_mask.png";
        WriteImage(o_.out / mask, sr.mask, Type(PixelType::kUInt8));
        photo["mask"] = mask;
      }
    }
    post_.ApplyAfterSensor(&out);
    WriteExr(o_.out / job.file, out);
    if (o_.brackets.count > 0) Brackets(job, index, linear, exposure_s, r);
    r->photos.push_back(photo);
    r->photo_truth[job.file] = truth;
  }

  void Brackets(const PhotoJob& job, int index, const Image& linear, double exposure_s,
                Rendered* r) {
    const std::string stem = fs::path(job.file).stem().string();
    const std::string dir = "brackets/" + stem;
    const auto brackets = MakeBrackets(
        linear, o_.sensor, o_.brackets, *response_, exposure_s, o_.noise == NoiseModel::kRealistic,
        render::MixBits(o_.seed ^ (0xb7ac0000ULL + index)), o_.num_threads);
    std::string times = "# exposure time (s) of each image of this folder, in file order\n";
    Json exposures = Json::array();
    for (size_t i = 0; i < brackets.size(); ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%02zu.%s", i,
                    std::string(BracketFormatName(o_.brackets.format)).c_str());
      fs::create_directories(o_.out / dir);
      WriteImage(o_.out / dir / name, brackets[i].encoded,
                 Type(o_.brackets.bits == 8 ? PixelType::kUInt8 : PixelType::kUInt16));
      char line[64];
      std::snprintf(line, sizeof(line), "%.9g\n", brackets[i].exposure_s);
      times += line;
      exposures.push_back(brackets[i].exposure_s);
    }
    WriteText(o_.out / dir / "exposures.txt", times);
    // The noise-free radiance the brackets expose (before shot/read noise, clipping, response
    // and quantisation): the truth an HDR merge of this folder should recover.
    const std::string radiance = "truth/radiance/" + stem + ".exr";
    WriteExr(o_.out / radiance, linear);
    r->bracket_sets.push_back(Json{
        {"photo", job.file}, {"dir", dir}, {"exposures_s", exposures}, {"radiance", radiance}});
  }

  void Validation(const PhotoJob& job, int index, Rendered* r) {
    WriteExr(o_.out / job.file, Render(job, 0x10000ULL + uint64_t(index), r));
    r->validation.push_back(Json{{"file", job.file},
                                 {"camera", cameras_[job.camera].camera.name},
                                 {"lighting", job.lighting}});
  }

 private:
  const recon::Camera& TrueCamera(const PhotoJob& job) const {
    return scene_.cameras[scene_.FindCamera(cameras_[job.camera].camera.name)];
  }
  const SynthOptions& o_;
  const recon::Scene& scene_;
  const std::vector<PlacedCamera>& cameras_;
  const PhotoEffects& post_;
  const ResponseCurve* response_;
  std::map<int, std::unique_ptr<render::Renderer>> renderers_;
};

Json SensorTruth(const SynthOptions& o) {
  if (o.noise == NoiseModel::kNone && o.brackets.count == 0) return nullptr;
  const SensorOptions& s = o.sensor;
  return Json{{"noise", o.noise == NoiseModel::kRealistic ? "realistic" : "none"},
              {"full_well_e", s.full_well_e},
              {"read_noise_e", s.read_noise_e},
              {"adc_bits", s.adc_bits},
              {"black_level_dn", s.black_level_dn},
              {"electrons_per_radiance_s", s.electrons_per_radiance_s},
              {"exposure", s.exposure_s > 0 ? "fixed" : "auto (99th percentile at 80% well)"},
              {"model",
               "e = Poisson(L k t) + N(0, read^2), clipped at full well; "
               "photo = (DN - black) gain / (k t)"}};
}

Json CameraTruth(const std::vector<PlacedCamera>& cameras) {
  Json out = Json::object();
  for (const PlacedCamera& c : cameras) {
    Json j = {{"target", c.target_region.empty() ? "overview" : "highlight"}};
    if (!c.target_region.empty()) {
      j["highlight_region"] = c.target_region;
      j["highlight_point"] =
          Json::array({c.highlight_point.x(), c.highlight_point.y(), c.highlight_point.z()});
      j["highlight_pixel"] = Json::array({c.highlight_pixel.x(), c.highlight_pixel.y()});
    }
    out[c.camera.name] = j;
  }
  return out;
}

// Photos (in scene.json) and validation renders (in truth.json) for every camera.
void PlanJobs(const SynthOptions& options, const std::vector<PlacedCamera>& cameras,
              std::vector<PhotoJob>* photos, std::vector<PhotoJob>* validation) {
  for (const std::string& lighting : {std::string("L0"), std::string("L1")}) {
    for (size_t c = 0; c < cameras.size(); ++c) {
      const std::string base = cameras[c].camera.name + "_" + lighting + ".exr";
      if (Has(options.photo_lightings, lighting)) {
        photos->push_back({int(c), lighting, "photos/" + base});
      } else if (Has(options.validation_lightings, lighting)) {
        validation->push_back({int(c), lighting, "validation/" + base});
      }
    }
  }
}

Json BaseScene(const SynthRoom& room, const std::vector<PlacedCamera>& cameras) {
  Json base = {{"format", "igi-scene"},
               {"version", 1},
               {"geometry", Json::array({Json{{"file", "geometry/room.obj"}}})},
               {"materials", room.materials},
               {"lights", room.LightsJson()},
               {"lightings", room.LightingsJson()},
               {"cameras", Json::object()}};
  for (const PlacedCamera& c : cameras)
    base["cameras"][c.camera.name] = recon::CameraJson(c.camera);
  return base;
}

Json TruthJson(const SynthOptions& options, const SynthScenes& scenes, const Json& effects,
               const std::vector<PlacedCamera>& cameras, const Rendered& r,
               const ResponseCurve* response) {
  Json truth = {{"format", "igi-truth"},
                {"version", 1},
                {"materials", scenes.true_scene["materials"]},
                {"effects", effects},
                {"validation", r.validation},
                {"scene", "truth/scene.json"},
                {"unknowns", options.unknowns},
                {"floor_texture", std::string(FloorTextureName(options.floor_texture))},
                {"satin", options.satin},
                {"poster", options.poster},
                {"cameras", CameraTruth(cameras)},
                {"photos", r.photo_truth},
                {"sensor", SensorTruth(options)},
                {"render",
                 {{"renderer", "igi Renderer (path tracer)"},
                  {"spp", options.spp},
                  {"seed", options.seed},
                  {"validation",
                   "clean renders of truth/scene.json from the true poses: "
                   "no sensor noise, no camera effects"}}}};
  if (response) {
    truth["brackets"] = {{"response", response->Describe()},
                         {"response_file", "truth/response.json"},
                         {"bits", options.brackets.bits},
                         {"stops", options.brackets.stops},
                         {"radiance_per_relative_exposure",
                          options.sensor.full_well_e / options.sensor.electrons_per_radiance_s},
                         {"note",
                          "x = electrons / full well; radiance = (x / exposure_s) * "
                          "radiance_per_relative_exposure; sets[].radiance: the noise-free "
                          "radiance of the set (float EXR)"},
                         {"sets", r.bracket_sets}};
  }
  return truth;
}

// --from: the capture of options.from with its photos given the photo effects.
SynthSummary HideInCapture(const SynthOptions& options, Clock::time_point start) {
  const recon::Scene source = recon::LoadScene(options.from);
  const Json source_doc = recon::AbsoluteScenePaths(source.document, source.dir);
  // Each photo is written as photos/NAME.exr (NAME: its file's stem, with its index when two
  // photos share one).
  std::vector<std::string> photo_files;
  std::map<std::string, int> stems;
  for (const recon::Photo& p : source.photos) ++stems[p.file.stem().string()];
  for (size_t i = 0; i < source.photos.size(); ++i) {
    const std::string stem = source.photos[i].file.stem().string();
    photo_files.push_back("photos/" + (stems[stem] > 1 ? std::to_string(i) + "_" : "") + stem +
                          ".exr");
  }
  SynthScenes scenes;
  scenes.true_scene = scenes.declared_scene = source_doc;
  PhotoEffects post;
  const Json effects =
      ApplyPhotoEffects(options.effects, source.cameras, photo_files, options.seed, &scenes, &post);
  scenes.declared_scene["materials"] =
      DeclaredMaterials(scenes.declared_scene["materials"], options.unknowns);
  const fs::path& out = options.out;
  fs::create_directories(out / "photos");
  fs::create_directories(out / "truth");
  SynthSummary summary;
  for (size_t i = 0; i < source.photos.size(); ++i) {
    const recon::Photo& p = source.photos[i];
    Image image = ReadImage(p.file, 3);
    post.ApplyBeforeSensor(photo_files[i], source.cameras[p.camera], &image);
    post.ApplyAfterSensor(&image);
    WriteImage(out / photo_files[i], image);
    scenes.declared_scene["photos"][i]["file"] = photo_files[i];
    summary.photos.push_back(photo_files[i]);
  }
  WriteJsonFile(out / "truth/scene.json", scenes.true_scene);
  WriteJsonFile(out / "scene.json", scenes.declared_scene);
  WriteJsonFile(
      out / "truth.json",
      Json{{"format", "igi-truth"},
           {"version", 1},
           {"materials", scenes.true_scene["materials"]},
           {"effects", effects},
           {"scene", "truth/scene.json"},
           {"unknowns", options.unknowns},
           {"source", fs::absolute(options.from).lexically_normal().string()},
           {"render", {{"renderer", "the source capture's (its photos given the effects)"}}}});
  summary.seconds = Since(start);
  return summary;
}

}  // namespace

SynthSummary Synthesize(const SynthOptions& options) {
  const auto start = Clock::now();
  options.Validate();
  CheckOutputFolder(options);
  if (!options.from.empty()) return HideInCapture(options, start);
  std::optional<ResponseCurve> response;
  if (options.brackets.count > 0) response = ResponseCurve::FromOptions(options.brackets);

  const SynthRoom room = BuildRoom(options);
  const std::vector<PlacedCamera> cameras = PlaceCameras(room, options);
  std::vector<PhotoJob> photos, validation;
  PlanJobs(options, cameras, &photos, &validation);
  std::vector<std::string> photo_files;
  for (const PhotoJob& p : photos) photo_files.push_back(p.file);
  SynthScenes scenes;
  scenes.true_scene = scenes.declared_scene = BaseScene(room, cameras);
  PhotoEffects post;
  const Json effects =
      ApplyEffects(options.effects, room, cameras, photo_files, options.seed, &scenes, &post);
  scenes.declared_scene["materials"] =
      DeclaredMaterials(scenes.declared_scene["materials"], options.unknowns);

  // Everything is known and valid: write.
  const fs::path& out = options.out;
  fs::create_directories(out / "truth");
  WriteText(out / "geometry/room.obj", room.mesh.ToObj("igi-synth room: regions by usemtl"));
  for (const auto& [file, text] : scenes.extra_files) WriteText(out / file, text);
  WriteExr(out / room.floor_albedo_file, room.floor_albedo);
  for (const auto& [file, image] : room.region_textures) WriteExr(out / file, image);
  WriteJsonFile(out / "truth/scene.json", RelocateToTruthFolder(scenes.true_scene));
  recon::SceneLoadOptions load;
  load.require_complete_materials = true;
  const recon::Scene true_scene = recon::LoadScene(out / "truth/scene.json", load);

  Rendered r;
  Pipeline pipeline(options, true_scene, cameras, post, response ? &*response : nullptr);
  for (size_t i = 0; i < photos.size(); ++i) pipeline.Photo(photos[i], int(i), &r);
  for (size_t i = 0; i < validation.size(); ++i) pipeline.Validation(validation[i], int(i), &r);

  scenes.declared_scene["photos"] = r.photos;
  if (options.unposed) {
    scenes.declared_scene.erase("cameras");
    scenes.declared_scene.erase("photos");
  }
  WriteJsonFile(out / "scene.json", scenes.declared_scene);
  if (response) {
    const int levels = options.brackets.bits == 8 ? 256 : 65536;
    WriteJsonFile(out / "truth/response.json", response->ToResponseJson(levels));
  }
  WriteJsonFile(out / "truth.json",
                TruthJson(options, scenes, effects, cameras, r, response ? &*response : nullptr));
  SynthSummary summary;
  summary.photos = photo_files;
  for (const PhotoJob& p : validation) summary.validation.push_back(p.file);
  summary.saturated_pixels = r.saturated;
  summary.render_seconds = r.render_seconds;
  summary.seconds = Since(start);
  return summary;
}

}  // namespace igi::synth
