#include "recon/colmap_runner.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <regex>

#include "tools/common/error.h"
#include "tools/common/parallel.h"
#include "tools/common/strings.h"

namespace igi::recon {
namespace {

std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs argv with stdout and stderr appended to `log`; returns the exit status (-1 when it could
// not be started or was killed).
int RunLogged(const std::vector<std::string>& argv, const std::filesystem::path& log) {
  {
    FILE* f = std::fopen(log.c_str(), "a");
    if (f != nullptr) {
      std::fprintf(f, "\n$ %s\n", Join(argv, " ").c_str());
      std::fclose(f);
    }
  }
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void RunStep(const std::string& step, std::vector<std::string> argv,
             const std::filesystem::path& log) {
  spdlog::info("colmap {} …", step);
  const int status = RunLogged(argv, log);
  if (status != 0) {
    throw Error("colmap " + step + " failed (exit status " + std::to_string(status) + "); see " +
                log.string());
  }
}

std::string ParamsList(const std::vector<double>& params) {
  std::vector<std::string> parts;
  for (double p : params) parts.push_back(fmt::format("{:.17g}", p));
  return Join(parts, ",");
}

std::string Threads(int threads) { return std::to_string(threads > 0 ? threads : -1); }

std::vector<std::string> ExtractorArgs(const std::filesystem::path& images_dir,
                                       const std::filesystem::path& db, const ColmapRunOptions& o) {
  std::vector<std::string> a = {o.executable,
                                "feature_extractor",
                                "--database_path",
                                db.string(),
                                "--image_path",
                                images_dir.string(),
                                "--SiftExtraction.use_gpu",
                                "0",
                                "--SiftExtraction.num_threads",
                                Threads(o.threads),
                                "--SiftExtraction.max_image_size",
                                std::to_string(o.max_image_size),
                                "--SiftExtraction.max_num_features",
                                std::to_string(o.max_features),
                                "--ImageReader.single_camera",
                                o.single_camera || o.intrinsics ? "1" : "0"};
  if (o.intrinsics) {
    a.insert(a.end(), {"--ImageReader.camera_model",
                       std::string(calib::ColmapCameraModelName(o.intrinsics->model)),
                       "--ImageReader.camera_params", ParamsList(o.intrinsics->params)});
  } else {
    a.insert(a.end(), {"--ImageReader.camera_model",
                       std::string(calib::ColmapCameraModelName(o.camera_model))});
  }
  return a;
}

std::vector<std::string> MatcherArgs(const std::filesystem::path& db, const ColmapRunOptions& o) {
  return {o.executable,
          "exhaustive_matcher",
          "--database_path",
          db.string(),
          "--SiftMatching.use_gpu",
          "0",
          "--SiftMatching.num_threads",
          Threads(o.threads),
          "--SiftMatching.guided_matching",
          o.guided_matching ? "1" : "0"};
}

std::vector<std::string> MapperArgs(const std::filesystem::path& images_dir,
                                    const std::filesystem::path& db,
                                    const std::filesystem::path& models,
                                    const ColmapRunOptions& o) {
  std::vector<std::string> a = {o.executable,
                                "mapper",
                                "--database_path",
                                db.string(),
                                "--image_path",
                                images_dir.string(),
                                "--output_path",
                                models.string(),
                                "--Mapper.num_threads",
                                Threads(o.threads),
                                "--Mapper.abs_pose_min_num_inliers",
                                std::to_string(o.min_pose_inliers)};
  if (o.intrinsics) {
    a.insert(a.end(), {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point",
                       "0", "--Mapper.ba_refine_extra_params", "0"});
  }
  return a;
}

// The reconstruction with the most registered images under `models` (0/, 1/, …).
std::pair<ColmapModel, int> LargestModel(const std::filesystem::path& models) {
  ColmapModel best;
  int count = 0;
  if (!std::filesystem::is_directory(models)) return {best, 0};
  for (const auto& entry : std::filesystem::directory_iterator(models)) {
    if (!entry.is_directory()) continue;
    ColmapModel model = ReadColmapModel(entry.path());
    ++count;
    if (model.images.size() > best.images.size()) best = std::move(model);
  }
  return {best, count};
}

}  // namespace

const std::vector<std::string> kSelfCalibratedModels = {"SIMPLE_PINHOLE", "PINHOLE",
                                                        "SIMPLE_RADIAL", "RADIAL", "OPENCV"};

void ColmapRunOptions::Validate() const {
  ProblemList problems;
  if (executable.empty()) problems.Add("", "--colmap", "", "must name the colmap executable");
  if (threads < 0) problems.Add("", "--threads", std::to_string(threads), "must be >= 0");
  if (min_pose_inliers < 6) {
    problems.Add("", "--min-pose-inliers", std::to_string(min_pose_inliers), "must be >= 6");
  }
  const std::string model(calib::ColmapCameraModelName(camera_model));
  if (std::find(kSelfCalibratedModels.begin(), kSelfCalibratedModels.end(), model) ==
      kSelfCalibratedModels.end()) {
    problems.Add("", "--camera-model", model,
                 "must be one of " + Join(kSelfCalibratedModels, ", "));
  }
  if (max_image_size < 100) {
    problems.Add("", "--max-image-size", std::to_string(max_image_size), "must be >= 100");
  }
  if (max_features < 100) {
    problems.Add("", "--max-features", std::to_string(max_features), "must be >= 100");
  }
  problems.ThrowIfAny();
}

std::optional<std::string> ParseColmapVersion(const std::string& banner) {
  static const std::regex kVersion(R"(COLMAP\s+([0-9]+\.[0-9]+(\.[0-9]+)?))");
  std::smatch match;
  if (!std::regex_search(banner, match, kVersion)) return std::nullopt;
  return match[1].str();
}

std::string ColmapVersion(const std::string& executable) {
  const std::string command = ShellQuote(executable) + " -h 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw Error("cannot run " + executable);
  std::string output;
  char buffer[4096];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  const int status = ::pclose(pipe);
  const std::optional<std::string> version = ParseColmapVersion(output);
  if (!version) {
    const bool missing = WIFEXITED(status) && WEXITSTATUS(status) == 127;
    throw Error(missing ? executable + ": COLMAP not found (install COLMAP 3.8 or pass --colmap)"
                        : executable + ": not COLMAP (no version in its -h output: \"" +
                              std::string(Trim(output.substr(0, 80))) + "\")");
  }
  return *version;
}

std::vector<std::string> ListColmapImages(const std::filesystem::path& images_dir) {
  static const std::vector<std::string> kExtensions = {".jpg", ".jpeg", ".png",
                                                       ".tif", ".tiff", ".bmp"};
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(images_dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string ext = ToLower(entry.path().extension().string());
    if (std::find(kExtensions.begin(), kExtensions.end(), ext) != kExtensions.end()) {
      names.push_back(entry.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

ColmapRunSummary RunColmap(const std::filesystem::path& images_dir,
                           const std::filesystem::path& work_dir, const ColmapRunOptions& options) {
  options.Validate();
  ColmapRunSummary summary;
  summary.version = ColmapVersion(options.executable);
  if (summary.version != "3.8" && !options.allow_other_version) {
    throw Error(options.executable + ": COLMAP " + summary.version +
                " is not the supported version 3.8");
  }
  summary.images = ListColmapImages(images_dir);
  std::filesystem::create_directories(work_dir);
  const auto db = work_dir / "database.db";
  const auto models = work_dir / "models";
  std::filesystem::remove(db);
  std::filesystem::remove_all(models);
  std::filesystem::create_directories(models);
  summary.log = work_dir / "colmap.log";
  std::filesystem::remove(summary.log);
  RunStep("feature_extractor", ExtractorArgs(images_dir, db, options), summary.log);
  RunStep("exhaustive_matcher", MatcherArgs(db, options), summary.log);
  // COLMAP 3.8's mapper exits 1 when no image pair has enough matches: that, like an empty
  // output, is "reconstructed nothing".
  spdlog::info("colmap mapper …");
  const int mapper_status = RunLogged(MapperArgs(images_dir, db, models, options), summary.log);
  auto [model, count] = LargestModel(models);
  summary.num_models = count;
  if (model.images.empty()) {
    throw Error("COLMAP reconstructed nothing from " + std::to_string(summary.images.size()) +
                " photos in " + images_dir.string() + " (too few matches between them?; mapper " +
                "exit status " + std::to_string(mapper_status) + "); see " + summary.log.string());
  }
  if (mapper_status != 0) {
    spdlog::warn("colmap mapper exited with status {} but wrote a model; see {}", mapper_status,
                 summary.log.string());
  }
  summary.model = std::move(model);
  for (const std::string& name : summary.images) {
    if (summary.model.FindImageByName(name) == nullptr) summary.unregistered.push_back(name);
  }
  spdlog::info("COLMAP registered {} of {} photos ({} model(s))", summary.model.images.size(),
               summary.images.size(), count);
  return summary;
}

ColmapRunSummary LoadColmapRun(const std::filesystem::path& images_dir,
                               const std::filesystem::path& model_dir) {
  ColmapRunSummary summary;
  summary.version = "not run";
  summary.images = ListColmapImages(images_dir);
  summary.model = ReadColmapModel(model_dir);
  summary.num_models = 1;
  for (const std::string& name : summary.images) {
    if (summary.model.FindImageByName(name) == nullptr) summary.unregistered.push_back(name);
  }
  return summary;
}

}  // namespace igi::recon
