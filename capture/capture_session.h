#pragma once
// One capture run of igi-capture: opens the camera, makes (or, with --resume,
// reloads) the bracket plan, and writes every frame as it arrives: first the
// frame's file (atomically), then its line in DIR/manifest.jsonl (flushed).
// Layout of DIR:
//   plan.json        the plan, written before the first frame
//   frames/…         one 16-bit PNG/TIFF per frame (see frame_writer.h)
//   manifest.jsonl   one line per finished frame (see manifest.h)
//
// Frames are received on the calling thread and written on writer threads
// (frame_pipeline.h), so writing never holds up reception; a frame that cannot
// be written ends the run like a stream failure (partial, exit 3).
//
// Nothing lost: everything that can be checked is checked before the first file
// is written (bad values: InputError, exit 2). A stream failure (timeout, lost
// packets, disconnect) or a stop request ends the run early with the frames so
// far intact and listed; the summary says so (the executable exits 3), and a
// run with `resume` takes only the frames the manifest lacks.

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "capture/auto_meter.h"
#include "capture/bracket_plan.h"
#include "capture/camera.h"
#include "capture/frame_pipeline.h"

namespace igi::capture {

struct CaptureOptions {
  std::filesystem::path out_dir;              // DIR
  CameraOptions camera;                       // which camera and its settings
  std::vector<double> exposures_us;           // explicit bracket (µs); empty with auto_expose
  bool auto_expose = false;                   // meter the scene and choose the bracket
  AutoMeterOptions auto_meter;                // how --auto chooses
  std::optional<int> frames;                  // frames per exposure (default 1; resume: the plan's)
  int settle_frames = 1;                      // frames dropped after each exposure change
  std::optional<PlanFileFormat> file_format;  // kPng (default) or kTiff
  bool resume = false;                        // finish the plan in DIR
  // true: each frame file and manifest line is fsynced as it is written
  // (survives a power cut; the disk's flush time then caps the sustained rate).
  // false (--no-fsync): written and renamed/appended at once (survive a crash of
  // igi-capture or a pulled cable), flushed to disk together at the end of the
  // run.
  bool fsync_each_frame = true;
  // Writer threads and the memory for frames waiting for them (manifest_path
  // and durable are set by the run).
  FramePipelineOptions writing;
  const std::atomic<bool>* stop_requested = nullptr;  // set by a signal handler: stop cleanly

  // InputError when the combination is unusable (both or neither of exposures
  // and auto, …).
  void Validate() const;
};

struct CaptureSummary {
  BracketPlan plan;
  CameraInfo camera;
  std::optional<AutoMeterReport> meter;  // with --auto on a fresh run
  int frames_planned = 0;
  int frames_already_done = 0;  // listed in the manifest before this run (resume)
  int frames_written = 0;       // by this run
  // Frames the camera sent but igi-capture never saw within a bracket (gaps in
  // frame_id while streaming one exposure: no free buffer, or lost on the way).
  // The frames written are still consecutive in time; a sustained-rate
  // measurement needs this to be 0.
  int64_t frames_skipped = 0;
  double seconds = 0.0;         // from the first frame requested to the last written
  StreamStatistics stream;      // the camera stream's own counts (underruns, lost packets)
  bool complete = false;        // every planned frame is on disk and listed
  std::string stopped_because;  // why not complete
};

// Runs the capture; throws igi::Error only before the first frame (or when the
// plan cannot be written); stream failures and frames that cannot be written
// end up in the summary (not complete, stopped_because says why).
CaptureSummary RunCapture(const CaptureOptions& options);

}  // namespace igi::capture
