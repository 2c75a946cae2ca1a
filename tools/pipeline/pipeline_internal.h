#pragma once
// Shared by pipeline.cpp and pipeline_stages.cpp: the run's context and a stage's runner.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calib/camera_file.h"
#include "calib/colour_chart.h"
#include "recon/scene.h"
#include "tools/common/json.h"
#include "tools/pipeline/photo_layout.h"
#include "tools/pipeline/pipeline.h"
#include "tools/pipeline/stage_marker.h"

namespace igi::pipeline::internal {

struct Context {
  RunOptions options;
  std::filesystem::path bin;
  PhotoLayout layout;                       // empty with hdr_photos
  std::optional<calib::CameraFile> camera;  // layout.camera read, when there is one
  std::optional<calib::ColourFile> colour;  // layout.colour read, when there is one
  std::filesystem::path lights_file;        // lights.json, empty = none
  Json lights = Json::object();             // its "lights": name -> scene.json light object
  // Replaces the lights of `scene_json` named in `lights` by their calibrated entries.
  void ApplyLights(Json* scene_json) const;
  recon::Scene scene;  // the input scene (geometry loaded)
  Json scene_json;
  std::filesystem::path Dir(const std::string& stage) const { return options.out / stage; }
  std::filesystem::path SolveInput() const;  // the scene.json given to igi-solve
};

// One stage's run: its folder, its log, the commands it ran, whether a tool exited 3.
class StageRun {
 public:
  StageRun(const Context& ctx, std::string stage);
  const std::filesystem::path& dir() const { return dir_; }
  // Runs bin/tool with args (logged to dir/log.txt). Exit 0 is fine; exit 3 is fine when
  // `partial_ok` (recorded); anything else throws Error "stage S: TOOL exited N: ..." (exit 1).
  void Tool(const std::string& tool, const std::vector<std::string>& args, bool partial_ok = false);
  bool partial() const { return partial_; }
  std::vector<std::string> partial_lines;
  std::vector<std::string> commands;
  Json details = Json::object();

 private:
  const Context& ctx_;
  std::string stage_;
  std::filesystem::path dir_;
  bool partial_ = false;
};

// Stage bodies (pipeline_stages.cpp). Each writes only under run->dir().
void ResponseStage(const Context& ctx, StageRun* run);
void HdrStage(const Context& ctx, StageRun* run);
void RegisterStage(const Context& ctx, StageRun* run);
void SolveStage(const Context& ctx, StageRun* run);
void DiagnoseStage(const Context& ctx, StageRun* run);
void ReportStage(const Context& ctx, StageRun* run);

std::vector<std::string> ThreadArgs(const Context& ctx);

}  // namespace igi::pipeline::internal
