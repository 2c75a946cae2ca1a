#pragma once
// A GigE Vision (or USB3 Vision) camera through Aravis. Aravis and GLib types
// stay in camera.cpp. A Camera streams continuously once Start()ed; NextFrame()
// hands out one frame at a time, copied out of Aravis's buffer, which goes
// straight back to the stream.
//
// Failures are errors, never silent: a camera that does not answer when opened
// throws igi::Error (exit 1); a bad setting (unknown pixel format, exposure out
// of range) throws igi::InputError (exit 2); a frame that does not come in
// time, arrives with lost packets, or a camera that stops answering throws
// CameraStreamError, which the capture turns into a partial result (exit 3).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "capture/pixel_format.h"
#include "tools/common/error.h"

namespace igi::capture {

struct CameraInfo {
  std::string id;        // Aravis's device id ("Aravis-Fake-GV01")
  std::string vendor;    // "Aravis"
  std::string model;     // "Fake"
  std::string serial;    // "GV01"
  std::string address;   // "127.0.0.1" for GigE Vision; empty for USB
  std::string protocol;  // "GigEVision", "USB3Vision"
};

// Every camera Aravis finds on every interface (GigE discovery broadcast, USB
// enumeration).
std::vector<CameraInfo> ListCameras();

// The stream broke: timeout, lost packets, or the camera stopped answering.
class CameraStreamError : public Error {
 public:
  CameraStreamError(std::string message, bool camera_may_be_gone)
      : Error(std::move(message), ExitCode::kPartial), camera_may_be_gone_(camera_may_be_gone) {}
  // True after a timeout or a failed command: talking to the camera again (to
  // stop it) would only wait for GVCP timeouts (Aravis retries each command for
  // seconds).
  bool camera_may_be_gone() const { return camera_may_be_gone_; }

 private:
  bool camera_may_be_gone_;
};

struct CameraOptions {
  // An IPv4 address, or an id/serial/model-serial as ListCameras() shows. GigE
  // cameras found by id are opened through their address (Aravis streams over
  // loopback only when opened so).
  std::string id_or_address;
  std::string pixel_format;    // GenICam name; empty = keep the camera's current format
  double gain = -1.0;          // camera gain units (dB on most cameras); < 0 = keep
  double frame_rate_hz = 0.0;  // > 0 sets AcquisitionFrameRate; 0 = keep
  int width = 0;               // > 0 sets the region of interest width (pixels), from x = 0
  int height = 0;              // > 0 sets the region height (pixels), from y = 0
  // Stream buffers queued in Aravis; 0 = enough for 64 MiB of frames (at least
  // 64, at most 1024). They hold frames the receiving thread has not taken yet.
  int num_buffers = 0;
  int frame_timeout_ms = 3000;   // a frame later than this (+ exposure) ends the run
  bool packet_resend = true;     // GigE: ask the camera to resend lost packets
  int frame_retention_ms = 500;  // GigE: a frame still missing packets this long is lost

  // InputError naming the flag when a value is out of range.
  void Validate() const;
};

// The stream's own counts since the camera was opened (Aravis's statistics).
struct StreamStatistics {
  uint64_t completed = 0;        // frames received whole
  uint64_t failures = 0;         // frames given up (missing packets, timeout)
  uint64_t underruns = 0;        // frames dropped for want of a free buffer
  uint64_t missing_packets = 0;  // GigE: packets never received
  uint64_t resent_packets = 0;   // GigE: packets received after a resend request
};

// One frame as delivered: the samples exactly as the camera sent them, so
// receiving costs one copy and no conversion (levels are unscaled, 0 …
// 2^significant_bits - 1).
struct Frame {
  int width = 0;
  int height = 0;
  PixelFormatInfo format;
  // width * height * channels samples, interleaved, top row first, of
  // format.bytes_per_sample bytes each (2: little-endian).
  std::vector<uint8_t> data;
  uint64_t frame_id = 0;             // the camera's block id
  uint64_t camera_timestamp_ns = 0;  // the camera's clock
  uint64_t system_timestamp_ns = 0;  // host clock at arrival, ns since the Unix epoch

  size_t sample_count() const { return data.size() / size_t(format.bytes_per_sample); }
  uint16_t level(size_t i) const {
    return format.bytes_per_sample == 1 ? data[i]
                                        : static_cast<uint16_t>(data[2 * i] | data[2 * i + 1] << 8);
  }
  std::vector<uint16_t> Levels() const;
  // Stores `levels` in this frame's format (for frames made by hand).
  void SetLevels(const std::vector<uint16_t>& levels);
};

class Camera {
 public:
  // Opens and configures the camera. Throws (see above).
  explicit Camera(const CameraOptions& options);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  const CameraInfo& info() const;
  const PixelFormatInfo& pixel_format() const;
  double gain() const;  // as read back from the camera
  void ExposureBoundsUs(double* min_us, double* max_us) const;

  // Sets the exposure time and returns the value the camera reports back
  // (cameras round). While streaming, the stream is stopped for the change and
  // restarted; NextFrame then drops frames that arrived before the restart was
  // acknowledged, and `settle_frames` more.
  double SetExposureUs(double exposure_us, int settle_frames);
  double exposure_us() const;

  void Start();
  void Stop();
  // Forgets the stream without sending AcquisitionStop, for a camera that
  // stopped answering (a GigE camera stops streaming by itself when its control
  // heartbeat lapses). The Aravis objects are then not finalised (that would
  // wait ~10 s for acks) but left to process exit.
  void Abandon();
  // The next frame exposed at the current setting. Throws CameraStreamError.
  Frame NextFrame();
  StreamStatistics Statistics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Host wall clock in ns since the Unix epoch (the clock of
// Frame::system_timestamp_ns).
uint64_t HostTimeNs();

}  // namespace igi::capture
