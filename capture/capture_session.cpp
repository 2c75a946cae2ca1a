#include "capture/capture_session.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <set>

#include "capture/frame_pipeline.h"
#include "capture/manifest.h"
#include "tools/common/error.h"
#include "tools/common/progress.h"

namespace igi::capture {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPlanFile = "plan.json";
constexpr const char* kManifestFile = "manifest.jsonl";

// The settings a fresh run asks for, checked against the camera before anything
// is written.
BracketPlan MakePlan(const CaptureOptions& options, Camera& camera, CaptureSummary* summary) {
  BracketPlan plan;
  plan.camera = camera.info().id;
  plan.frames = options.frames.value_or(1);
  plan.settle_frames = options.settle_frames;
  plan.pixel_format = camera.pixel_format().name;
  plan.gain = camera.gain();
  plan.file_format = options.file_format.value_or(PlanFileFormat::kPng);
  double min_us = 0, max_us = 0;
  camera.ExposureBoundsUs(&min_us, &max_us);
  if (options.auto_expose) {
    auto measure = [&](double exposure_us) {
      camera.SetExposureUs(exposure_us, options.settle_frames);
      return ReadMeter(camera.NextFrame(), options.auto_meter);
    };
    summary->meter =
        ChooseExposures(measure, min_us, max_us, camera.exposure_us(), options.auto_meter);
    for (const std::string& note : summary->meter->notes) spdlog::warn("--auto: {}", note);
    plan.exposures_us = summary->meter->exposures_us;
    plan.auto_metered = true;
  } else {
    ProblemList problems;
    for (double exposure : options.exposures_us) {
      if (exposure < min_us || exposure > max_us) {
        problems.Add("", "--exposures-us", fmt::format("{:g}", exposure),
                     fmt::format("outside the camera's range [{:g}, {:g}] us", min_us, max_us));
      }
    }
    problems.ThrowIfAny();
    plan.exposures_us = options.exposures_us;
  }
  plan.Validate("--exposures-us");
  return plan;
}

// On resume: the flags given must agree with the stored plan (they may be left
// out).
void CheckResumeFlags(const CaptureOptions& options, const BracketPlan& plan,
                      const std::string& source) {
  ProblemList problems;
  if (!options.exposures_us.empty() && options.exposures_us != plan.exposures_us) {
    problems.Add(source, "exposures_us", "", "--exposures-us differs from the plan being resumed");
  }
  if (options.frames && *options.frames != plan.frames) {
    problems.Add(source, "frames", std::to_string(plan.frames),
                 "--frames " + std::to_string(*options.frames) + " differs from the plan");
  }
  if (options.file_format && *options.file_format != plan.file_format) {
    problems.Add(source, "file_format", std::string(PlanFileFormatName(plan.file_format)),
                 "--format differs from the plan");
  }
  problems.ThrowIfAny();
}

// Slots the manifest lists whose file is on disk; warns about listed files that
// vanished.
std::set<PlanSlot> DoneSlots(const fs::path& out_dir, const BracketPlan& plan) {
  std::set<PlanSlot> done;
  const fs::path manifest = out_dir / kManifestFile;
  if (!fs::exists(manifest)) return done;
  const ManifestContents contents = ReadManifest(manifest);
  if (contents.truncated_last_line)
    spdlog::warn("{}: last line cut short; ignored", manifest.string());
  for (const ManifestEntry& entry : contents.entries) {
    const PlanSlot slot{entry.bracket, entry.frame};
    if (slot.bracket >= int(plan.exposures_us.size()) || slot.frame >= plan.frames) continue;
    if (entry.file != SlotFileName(plan, slot) || !fs::exists(out_dir / entry.file)) {
      spdlog::warn("{}: {} is listed but missing; it will be taken again", manifest.string(),
                   entry.file);
      continue;
    }
    done.insert(slot);
  }
  return done;
}

// Temporary files left by a run that was killed while writing a frame.
void RemoveStaleTemporaries(const fs::path& frames_dir) {
  std::error_code ec;
  for (const auto& item : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = item.path().filename().string();
    if (name.size() > 1 && name[0] == '.' && name.find(".tmp") != std::string::npos) {
      fs::remove(item.path(), ec);
    }
  }
}

ManifestEntry MakeEntry(const BracketPlan& plan, const PlanSlot& slot, const Camera& camera,
                        const Frame& frame) {
  ManifestEntry entry;
  entry.file = SlotFileName(plan, slot);
  entry.camera = camera.info().id;
  entry.exposure_us = camera.exposure_us();
  entry.gain = plan.gain;
  entry.pixel_format = frame.format.name;
  entry.timestamp = FormatTimestamp(frame.system_timestamp_ns);
  entry.bracket = slot.bracket;
  entry.frame = slot.frame;
  entry.extra["requested_exposure_us"] = plan.exposures_us[size_t(slot.bracket)];
  entry.extra["frame_id"] = frame.frame_id;
  entry.extra["camera_timestamp_ns"] = frame.camera_timestamp_ns;
  entry.extra["width"] = frame.width;
  entry.extra["height"] = frame.height;
  entry.extra["significant_bits"] = frame.format.significant_bits;
  entry.extra["camera_model"] = camera.info().vendor + " " + camera.info().model;
  entry.extra["camera_serial"] = camera.info().serial;
  if (!camera.info().address.empty()) entry.extra["camera_address"] = camera.info().address;
  return entry;
}

bool StopRequested(const CaptureOptions& options) {
  return options.stop_requested != nullptr && options.stop_requested->load();
}

// Receives every slot not in `done`, bracket by bracket, and hands each frame
// to the writers. Returns normally when finished, stopped, or the writers
// failed; CameraStreamError escapes.
void ReceiveFrames(const CaptureOptions& options, const BracketPlan& plan,
                   const std::set<PlanSlot>& done, Camera& camera, FramePipeline* pipeline,
                   CaptureSummary* summary) {
  for (int bracket = 0; bracket < int(plan.exposures_us.size()); ++bracket) {
    std::vector<PlanSlot> todo;
    for (int frame = 0; frame < plan.frames; ++frame) {
      if (!done.count({bracket, frame})) todo.push_back({bracket, frame});
    }
    if (todo.empty()) continue;
    camera.SetExposureUs(plan.exposures_us[size_t(bracket)], plan.settle_frames);
    std::optional<uint64_t> previous_id;
    for (const PlanSlot& slot : todo) {
      if (StopRequested(options)) {
        summary->stopped_because = "stopped on request (signal)";
        return;
      }
      FrameJob job;
      job.frame = camera.NextFrame();
      if (previous_id && job.frame.frame_id > *previous_id + 1) {
        summary->frames_skipped += int64_t(job.frame.frame_id - *previous_id - 1);
      }
      previous_id = job.frame.frame_id;
      job.file = options.out_dir / SlotFileName(plan, slot);
      job.entry = MakeEntry(plan, slot, camera, job.frame);
      if (!pipeline->Push(std::move(job))) return;  // a write failed: see pipeline->error()
    }
  }
}

// Receives on this thread while the pipeline's threads write (see
// frame_pipeline.h). Every frame received before a stream failure is written
// and listed before the failure propagates.
void TakeFrames(const CaptureOptions& options, const BracketPlan& plan,
                const std::set<PlanSlot>& done, Camera& camera, CaptureSummary* summary) {
  Progress progress("capture", summary->frames_planned - summary->frames_already_done);
  FramePipelineOptions pipeline_options = options.writing;
  pipeline_options.manifest_path = options.out_dir / kManifestFile;
  pipeline_options.durable = options.fsync_each_frame;
  FramePipeline pipeline(pipeline_options, [&](int) { progress.Add(); });
  std::exception_ptr failure;
  try {
    ReceiveFrames(options, plan, done, camera, &pipeline, summary);
    // Every frame is in hand: stop the camera now rather than after the
    // writers finish, or its frames pile up meanwhile as underruns.
    summary->stream = camera.Statistics();
    camera.Stop();
  } catch (...) {
    failure = std::current_exception();
    summary->stream = camera.Statistics();
  }
  pipeline.Finish();
  summary->frames_written = pipeline.frames_listed();
  summary->seconds = pipeline.seconds_to_last_listed();
  if (const auto error = pipeline.error()) {
    summary->stopped_because = "a frame could not be written: " + *error;
  }
  if (failure) std::rethrow_exception(failure);
  progress.Finish();
}

}  // namespace

void CaptureOptions::Validate() const {
  ProblemList problems;
  if (out_dir.empty()) problems.Add("", "--out", "", "must name the output folder");
  if (!resume && exposures_us.empty() && !auto_expose) {
    problems.Add("", "--exposures-us", "", "give --exposures-us LIST or --auto");
  }
  if (!exposures_us.empty() && auto_expose) {
    problems.Add("", "--auto", "", "give --exposures-us or --auto, not both");
  }
  if (frames && *frames < 1) problems.Add("", "--frames", std::to_string(*frames), "must be >= 1");
  if (settle_frames < 0) {
    problems.Add("", "--settle-frames", std::to_string(settle_frames), "must be >= 0");
  }
  if (file_format && !PlanFileFormatFromName(PlanFileFormatName(*file_format))) {
    problems.Add("", "--format", std::to_string(int(*file_format)), "must be png or tiff");
  }
  problems.ThrowIfAny();
  writing.Validate();
  if (auto_expose) auto_meter.Validate();
  camera.Validate();
}

CaptureSummary RunCapture(const CaptureOptions& options) {
  options.Validate();
  const fs::path plan_path = options.out_dir / kPlanFile;
  const bool started = fs::exists(plan_path) || fs::exists(options.out_dir / kManifestFile);
  if (started && !options.resume) {
    throw InputError(DescribeProblem(options.out_dir.string(), "", "",
                                     "already holds a capture; pass --resume to finish it or "
                                     "choose another --out"));
  }
  if (options.resume && !fs::exists(plan_path)) {
    throw InputError(
        DescribeProblem(plan_path.string(), "", "", "no capture to resume (plan.json is missing)"));
  }
  CaptureSummary summary;
  std::optional<BracketPlan> stored;
  CameraOptions camera_options = options.camera;
  if (options.resume) {
    stored = ReadPlan(plan_path);
    CheckResumeFlags(options, *stored, plan_path.string());
    camera_options.pixel_format = stored->pixel_format;
    camera_options.gain = stored->gain;
  }
  Camera camera(camera_options);
  summary.camera = camera.info();
  if (stored && stored->camera != camera.info().id) {
    throw InputError(
        DescribeProblem(plan_path.string(), "camera", stored->camera,
                        "the plan was made for another camera than " + camera.info().id));
  }
  camera.Start();
  try {
    summary.plan = stored ? *stored : MakePlan(options, camera, &summary);
    summary.frames_planned = summary.plan.total_frames();
    const std::set<PlanSlot> done = DoneSlots(options.out_dir, summary.plan);
    summary.frames_already_done = int(done.size());
    fs::create_directories(options.out_dir / "frames");
    RemoveStaleTemporaries(options.out_dir / "frames");
    if (!stored) WritePlan(plan_path, summary.plan);
    TakeFrames(options, summary.plan, done, camera, &summary);
  } catch (const CameraStreamError& e) {
    // A write failure, if any, stays first (it came first or at the same time).
    summary.stopped_because +=
        (summary.stopped_because.empty() ? "" : "; then ") + std::string(e.what());
    if (e.camera_may_be_gone()) camera.Abandon();
  }
  camera.Stop();
  if (!options.fsync_each_frame) SyncFileSystem(options.out_dir);  // all frames at once
  summary.complete = summary.frames_already_done + summary.frames_written == summary.frames_planned;
  return summary;
}

}  // namespace igi::capture
