// igi-capture: exposure brackets from GigE Vision / USB3 Vision cameras through
// Aravis, or a folder of raw files imported into the same layout
// (docs/file-formats.md).
//   igi-capture --list
//   igi-capture --camera ID_OR_ADDRESS --out DIR [--exposures-us LIST | --auto]
//   [--frames N]
//               [--resume]
//   igi-capture --from-raw DIR --out DIR
// Exit codes: 0 ok, 1 failed, 2 bad usage or input (nothing written), 3 partial
// (timeout, lost packets or disconnect: the frames written are intact and
// listed; --resume finishes the plan).

#include <fmt/format.h>
#include <malloc.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <cstdio>

#include "capture/capture_session.h"
#include "capture/raw_import.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"

namespace {

std::atomic<bool> g_stop{false};

void OnSignal(int /*signal*/) { g_stop.store(true); }

struct Flags {
  bool list = false;
  std::string camera;
  std::string out;
  std::string exposures;
  bool auto_expose = false;
  int frames = 0;
  bool resume = false;
  std::string from_raw;
  std::string format;
};

int List() {
  const auto cameras = igi::capture::ListCameras();
  for (const auto& camera : cameras) {
    std::printf("%s\t%s %s\t%s\t%s\n", camera.id.c_str(), camera.vendor.c_str(),
                camera.model.c_str(), camera.address.empty() ? "-" : camera.address.c_str(),
                camera.protocol.c_str());
  }
  if (cameras.empty()) spdlog::info("no camera found");
  return 0;
}

int ImportRaw(const Flags& flags) {
  igi::capture::RawImportOptions options;
  options.raw_dir = flags.from_raw;
  options.out_dir = flags.out;
  options.resume = flags.resume;
  const auto summary = igi::capture::ImportRaw(options);
  std::printf(
      "imported %d raw files into %s (%d already there, %zu other files "
      "ignored)\n",
      summary.files_imported, flags.out.c_str(), summary.files_already_done,
      summary.ignored.size());
  return 0;
}

int Capture(const Flags& flags, igi::capture::CaptureOptions options) {
  options.out_dir = flags.out;
  options.camera.id_or_address = flags.camera;
  if (!flags.exposures.empty()) {
    options.exposures_us = igi::capture::ParseExposureList(flags.exposures);
  }
  options.auto_expose = flags.auto_expose;
  if (flags.frames != 0) options.frames = flags.frames;
  // --format is checked against png|tiff when parsed.
  if (!flags.format.empty()) {
    options.file_format = igi::capture::PlanFileFormatFromName(flags.format).value();
  }
  options.resume = flags.resume;
  options.stop_requested = &g_stop;
  // Frames (up to a few MiB each) are allocated on reception and freed by the
  // writers hundreds of times a second: keep them on the heap and the freed
  // memory in the process, so that each frame does not map fresh pages (page
  // faults and zeroing cost about as much as copying the frame).
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  const auto summary = igi::capture::RunCapture(options);
  const double fps = summary.seconds > 0 ? summary.frames_written / summary.seconds : 0.0;
  std::printf(
      "%s: %d of %d frames written by this run (%d already done), %.1f "
      "frames/s, %lld frames "
      "skipped\n",
      summary.camera.id.c_str(), summary.frames_written, summary.frames_planned,
      summary.frames_already_done, fps, static_cast<long long>(summary.frames_skipped));
  // Aravis's own counts: frames it dropped for want of a buffer (underruns) or
  // gave up on (failures) are lost frames too.
  std::printf(
      "stream: %llu frames received, %llu failed, %llu underruns, %llu packets missing, "
      "%llu resent\n",
      static_cast<unsigned long long>(summary.stream.completed),
      static_cast<unsigned long long>(summary.stream.failures),
      static_cast<unsigned long long>(summary.stream.underruns),
      static_cast<unsigned long long>(summary.stream.missing_packets),
      static_cast<unsigned long long>(summary.stream.resent_packets));
  if (summary.meter) {
    std::printf("--auto: %zu exposures from %g to %g us; highlights %s, shadows %s\n",
                summary.meter->exposures_us.size(), summary.meter->shortest_us,
                summary.meter->longest_us,
                summary.meter->highlights_covered ? "covered" : "NOT covered",
                summary.meter->shadows_covered ? "covered" : "NOT covered");
  }
  if (summary.complete) return 0;
  std::fprintf(stderr, "igi-capture: error: %s\n", summary.stopped_because.c_str());
  if (summary.frames_planned == 0) return 1;  // failed before the plan: nothing written
  std::fprintf(stderr,
               "igi-capture: %d of %d frames are on disk and listed in "
               "%s/manifest.jsonl; "
               "run again with --resume to finish\n",
               summary.frames_already_done + summary.frames_written, summary.frames_planned,
               flags.out.c_str());
  return 3;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Acquire exposure brackets from a GigE Vision camera, or import raw "
      "files",
      "igi-capture"};
  // A flag given twice takes its last value (scripts append overrides).
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  igi::CommonFlags common;
  igi::AddCommonFlags(app, &common, /*computes=*/false);
  Flags flags;
  igi::capture::CaptureOptions options;
  auto* list =
      app.add_flag("--list", flags.list, "List the cameras Aravis finds (id, model, address)");
  auto* camera = app.add_option("--camera", flags.camera, "Camera id, serial or IPv4 address");
  auto* raw = app.add_option("--from-raw", flags.from_raw, "Import a folder of raw files");
  app.add_option("--out", flags.out, "Output folder (frames/, manifest.jsonl, plan.json)");
  auto* exposures =
      app.add_option("--exposures-us", flags.exposures, "Exposures in µs: 1000,4000,16000");
  auto* auto_flag =
      app.add_flag("--auto", flags.auto_expose, "Meter the scene and choose the bracket");
  app.add_option("--frames", flags.frames, "Frames per exposure (default 1)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--resume", flags.resume,
               "Finish the plan in --out, skipping frames already listed");
  app.add_option("--format", flags.format, "Frame files: png (default) or tiff, 16-bit lossless")
      ->check(CLI::IsMember({"png", "tiff"}));
  app.add_option("--pixel-format", options.camera.pixel_format,
                 "Camera pixel format (Mono16, Mono8, …)");
  app.add_option("--gain", options.camera.gain, "Camera gain (camera units, usually dB)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--settle-frames", options.settle_frames,
                 "Frames dropped after each exposure change (default 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--stop-spacing", options.auto_meter.stop_spacing,
                 "--auto: stops between exposures (default 2)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-exposure-us", options.auto_meter.max_exposure_us,
                 "--auto: longest exposure (default 2e6)")
      ->check(CLI::PositiveNumber);
  app.add_option("--frame-rate", options.camera.frame_rate_hz,
                 "Camera frame rate in Hz (default: keep)");
  app.add_option("--width", options.camera.width,
                 "Region of interest width in pixels (default: keep)");
  app.add_option("--height", options.camera.height,
                 "Region of interest height in pixels (default: keep)");
  app.add_option("--buffers", options.camera.num_buffers,
                 "Camera stream buffers (default 0: 64 MiB worth, 64 to 1024)");
  app.add_option("--writer-threads", options.writing.writer_threads,
                 "Threads writing frame files while frames are received (default 2)")
      ->check(CLI::Range(1, 64));
  app.add_option_function<double>(
         "--queue-mib",
         [&](double mib) { options.writing.queue_bytes = size_t(mib * double(1 << 20)); },
         "Memory for received frames waiting to be written, MiB (default 256)")
      ->check(CLI::PositiveNumber);
  app.add_option("--timeout-ms", options.camera.frame_timeout_ms,
                 "A frame later than this ends the run (default 3000)");
  app.add_option("--frame-retention-ms", options.camera.frame_retention_ms,
                 "A frame still missing packets after this long is lost (default 500)");
  app.add_flag("!--no-packet-resend", options.camera.packet_resend,
               "Do not ask for lost packets again");
  app.add_flag("!--no-fsync", options.fsync_each_frame,
               "Flush to disk once at the end, not after every frame (high "
               "frame rates)");
  list->excludes(camera)->excludes(raw);
  camera->excludes(raw);
  exposures->excludes(auto_flag);
  return igi::RunMain(app, common, argc, argv, [&]() -> int {
    if (flags.list) return List();
    if (flags.out.empty()) throw igi::InputError("--out: must name the output folder");
    if (!flags.from_raw.empty()) return ImportRaw(flags);
    if (flags.camera.empty()) {
      throw igi::InputError("give --list, --camera ID_OR_ADDRESS or --from-raw DIR (see --help)");
    }
    return Capture(flags, options);
  });
}
