#include "capture/camera.h"

#include <arv.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <cstring>

#include "tools/common/strings.h"

namespace igi::capture {
namespace {

std::string Str(const char* text) { return text != nullptr ? text : ""; }

std::string FormatNumber(double value) { return fmt::format("{:g}", value); }

// Takes a GError, returns its message and frees it.
std::string TakeMessage(GError* error) {
  if (error == nullptr) return "";
  std::string message = error->message;
  g_error_free(error);
  return message;
}

// Throws `Error(what + ": " + aravis message)` when `error` is set.
void Check(GError* error, const std::string& what, ExitCode code = ExitCode::kFailed) {
  if (error == nullptr) return;
  throw Error(what + ": " + TakeMessage(error), code);
}

bool LooksLikeIpv4(const std::string& text) {
  GInetAddress* address = g_inet_address_new_from_string(text.c_str());
  if (address == nullptr) return false;
  const bool ipv4 = g_inet_address_get_family(address) == G_SOCKET_FAMILY_IPV4;
  g_object_unref(address);
  return ipv4;
}

// The address to open `id_or_address` by: itself when it is an address; the
// discovered address of a GigE camera whose id, serial, physical id or
// "model-serial" matches; else itself (Aravis then matches USB devices by id).
std::string ResolveCamera(const std::string& id_or_address) {
  if (LooksLikeIpv4(id_or_address)) return id_or_address;
  for (const CameraInfo& info : ListCameras()) {
    const bool match = info.id == id_or_address || info.serial == id_or_address ||
                       info.model + "-" + info.serial == id_or_address;
    if (match) return info.address.empty() ? info.id : info.address;
  }
  return id_or_address;
}

std::atomic<bool>* ControlLostFlag(gpointer data) { return static_cast<std::atomic<bool>*>(data); }

void OnControlLost(ArvDevice* /*device*/, gpointer data) { ControlLostFlag(data)->store(true); }

// Runs in Aravis's stream thread: raise its priority so that writing frames in
// the main thread cannot starve packet reception (a frame whose packets come
// too late is lost). Needs CAP_SYS_NICE or rtkit; without them the thread keeps
// its normal priority.
void OnStreamEvent(void* /*data*/, ArvStreamCallbackType type, ArvBuffer* /*buffer*/) {
  if (type != ARV_STREAM_CALLBACK_TYPE_INIT) return;
  if (!arv_make_thread_high_priority(-10)) {
    spdlog::debug("stream thread: could not raise its priority");
  }
}

}  // namespace

std::vector<uint16_t> Frame::Levels() const {
  std::vector<uint16_t> levels(sample_count());
  for (size_t i = 0; i < levels.size(); ++i) levels[i] = level(i);
  return levels;
}

void Frame::SetLevels(const std::vector<uint16_t>& levels) {
  data.resize(levels.size() * size_t(format.bytes_per_sample));
  for (size_t i = 0; i < levels.size(); ++i) {
    if (format.bytes_per_sample == 1) {
      data[i] = static_cast<uint8_t>(levels[i]);
    } else {
      data[2 * i] = static_cast<uint8_t>(levels[i] & 0xff);
      data[2 * i + 1] = static_cast<uint8_t>(levels[i] >> 8);
    }
  }
}

uint64_t HostTimeNs() { return static_cast<uint64_t>(g_get_real_time()) * 1000u; }

std::vector<CameraInfo> ListCameras() {
  arv_update_device_list();
  std::vector<CameraInfo> cameras;
  const unsigned count = arv_get_n_devices();
  for (unsigned i = 0; i < count; ++i) {
    cameras.push_back({Str(arv_get_device_id(i)), Str(arv_get_device_vendor(i)),
                       Str(arv_get_device_model(i)), Str(arv_get_device_serial_nbr(i)),
                       Str(arv_get_device_address(i)), Str(arv_get_device_protocol(i))});
  }
  return cameras;
}

void CameraOptions::Validate() const {
  ProblemList problems;
  if (Trim(id_or_address).empty()) problems.Add("", "--camera", "", "must name a camera");
  if (!pixel_format.empty() && !FindPixelFormat(pixel_format)) {
    problems.Add("", "--pixel-format", pixel_format,
                 "must be one of " + Join(SupportedPixelFormatNames(), ", "));
  }
  if (frame_rate_hz < 0)
    problems.Add("", "--frame-rate", FormatNumber(frame_rate_hz), "must be >= 0");
  if (width < 0) problems.Add("", "--width", std::to_string(width), "must be >= 0");
  if (height < 0) problems.Add("", "--height", std::to_string(height), "must be >= 0");
  if (num_buffers != 0 && num_buffers < 2) {
    problems.Add("", "--buffers", std::to_string(num_buffers), "must be 0 (auto) or >= 2");
  }
  if (frame_retention_ms < 10) {
    problems.Add("", "--frame-retention-ms", std::to_string(frame_retention_ms), "must be >= 10");
  }
  if (frame_timeout_ms < 10) {
    problems.Add("", "--timeout-ms", std::to_string(frame_timeout_ms), "must be >= 10");
  }
  problems.ThrowIfAny();
}

struct Camera::Impl {
  CameraOptions options;
  CameraInfo info;
  PixelFormatInfo format;
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong control_lost_handler = 0;
  std::atomic<bool> control_lost{false};
  double exposure_us = 0.0;
  uint64_t changed_at_ns = 0;  // frames that arrived before this are stale
  int settle_left = 0;         // frames still to drop after the change
  bool streaming = false;

  bool abandoned = false;  // the camera stopped answering: see ~Impl

  ~Impl() {
    if (camera != nullptr && control_lost_handler != 0) {
      g_signal_handler_disconnect(arv_camera_get_device(camera), control_lost_handler);
    }
    // Finalising the stream and the device of a camera that is gone blocks for
    // about 5 s each (Aravis 0.8 retries every GVCP command 5 times with a 500
    // ms timeout, with no public setting to shorten it). An abandoned camera's
    // objects are left to the end of the process instead: igi-capture exits
    // right after.
    if (abandoned) return;
    if (streaming) arv_camera_stop_acquisition(camera, nullptr);
    if (stream != nullptr) g_object_unref(stream);
    if (camera != nullptr) g_object_unref(camera);
  }

  void Open();
  void Configure();
  void CreateStream();
  Frame CopyFrame(ArvBuffer* buffer) const;

  // Drops every frame that comes out of the stream until it has been quiet for
  // a while (30 ms + twice the exposure), at most 2 s.
  void Drain() {
    const uint64_t quiet_us = 30000u + uint64_t(2.0 * exposure_us);
    const int64_t deadline_us = g_get_monotonic_time() + 2000000;
    int dropped = 0;
    while (g_get_monotonic_time() < deadline_us) {
      ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream, quiet_us);
      if (buffer == nullptr) break;
      arv_stream_push_buffer(stream, buffer);
      ++dropped;
    }
    spdlog::debug("{}: drained {} frames after stopping", Name(), dropped);
  }
  std::string Name() const { return "camera " + options.id_or_address; }
};

void Camera::Impl::Open() {
  const std::string target = ResolveCamera(options.id_or_address);
  GError* error = nullptr;
  camera = arv_camera_new(target.c_str(), &error);
  if (camera == nullptr) {
    throw Error(Name() + ": does not answer (" + TakeMessage(error) +
                    "); check the cable, the address and `igi-capture --list`",
                ExitCode::kFailed);
  }
  info.vendor = Str(arv_camera_get_vendor_name(camera, nullptr));
  info.model = Str(arv_camera_get_model_name(camera, nullptr));
  info.serial = Str(arv_camera_get_device_serial_number(camera, nullptr));
  info.id = info.vendor + "-" + info.model + "-" + info.serial;
  info.address = LooksLikeIpv4(target) ? target : "";
  info.protocol = arv_camera_is_gv_device(camera) ? "GigEVision" : "USB3Vision";
  control_lost_handler = g_signal_connect(arv_camera_get_device(camera), "control-lost",
                                          G_CALLBACK(OnControlLost), &control_lost);
}

void Camera::Impl::Configure() {
  GError* error = nullptr;
  arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  Check(error, Name() + ": cannot set continuous acquisition");
  if (options.width > 0 || options.height > 0) {
    gint x = 0, y = 0, w = 0, h = 0;
    arv_camera_get_region(camera, &x, &y, &w, &h, &error);
    Check(error, Name() + ": cannot read the region");
    arv_camera_set_region(camera, 0, 0, options.width > 0 ? options.width : w,
                          options.height > 0 ? options.height : h, &error);
    Check(error, Name() + ": --width/--height rejected", ExitCode::kBadInput);
  }
  if (!options.pixel_format.empty()) {
    arv_camera_set_pixel_format_from_string(camera, options.pixel_format.c_str(), &error);
    Check(error, Name() + ": --pixel-format " + options.pixel_format + " rejected",
          ExitCode::kBadInput);
  }
  const std::string current = Str(arv_camera_get_pixel_format_as_string(camera, &error));
  Check(error, Name() + ": cannot read the pixel format");
  const auto found = FindPixelFormat(current);
  if (!found) {
    throw InputError(DescribeProblem("", "--pixel-format", current,
                                     "the camera's format is not storable; choose one of " +
                                         Join(SupportedPixelFormatNames(), ", ")));
  }
  format = *found;
  if (options.gain >= 0) {
    arv_camera_set_gain(camera, options.gain, &error);
    Check(error, Name() + ": --gain rejected", ExitCode::kBadInput);
  }
  if (options.frame_rate_hz > 0) {
    arv_camera_set_frame_rate(camera, options.frame_rate_hz, &error);
    Check(error, Name() + ": --frame-rate rejected", ExitCode::kBadInput);
  }
  exposure_us = arv_camera_get_exposure_time(camera, &error);
  Check(error, Name() + ": cannot read the exposure time");
}

void Camera::Impl::CreateStream() {
  GError* error = nullptr;
  stream = arv_camera_create_stream(camera, OnStreamEvent, nullptr, &error);
  Check(error, Name() + ": cannot open a stream");
  if (ARV_IS_GV_STREAM(stream)) {
    g_object_set(stream, "packet-resend",
                 options.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS
                                       : ARV_GV_STREAM_PACKET_RESEND_NEVER,
                 nullptr);
    // Frames whose packets are still incomplete after this long are given up
    // (lost).
    g_object_set(stream, "frame-retention", guint(options.frame_retention_ms) * 1000u, nullptr);
  }
  const guint payload = arv_camera_get_payload(camera, &error);
  Check(error, Name() + ": cannot read the payload size");
  int buffers = options.num_buffers;
  if (buffers == 0) {
    constexpr size_t kAutoBufferBytes = size_t(64) << 20;
    buffers = int(std::clamp<size_t>(kAutoBufferBytes / std::max<guint>(payload, 1), 64, 1024));
  }
  for (int i = 0; i < buffers; ++i) {
    arv_stream_push_buffer(stream, arv_buffer_new(payload, nullptr));
  }
  spdlog::debug(
      "{}: {} stream buffers of {} bytes, packets of {} bytes", Name(), buffers, payload,
      arv_camera_is_gv_device(camera) ? arv_camera_gv_get_packet_size(camera, nullptr) : 0u);
}

Frame Camera::Impl::CopyFrame(ArvBuffer* buffer) const {
  Frame frame;
  frame.width = arv_buffer_get_image_width(buffer);
  frame.height = arv_buffer_get_image_height(buffer);
  frame.format = format;
  frame.frame_id = arv_buffer_get_frame_id(buffer);
  frame.camera_timestamp_ns = arv_buffer_get_timestamp(buffer);
  frame.system_timestamp_ns = arv_buffer_get_system_timestamp(buffer);
  size_t size = 0;
  const auto* data = static_cast<const uint8_t*>(arv_buffer_get_image_data(buffer, &size));
  const size_t samples = size_t(frame.width) * frame.height * format.channels;
  if (data == nullptr || size < samples * format.bytes_per_sample) {
    throw CameraStreamError(Name() + ": frame " + std::to_string(frame.frame_id) + " holds " +
                                std::to_string(size) + " bytes, too few for " +
                                std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                                " " + format.name,
                            false);
  }
  frame.data.assign(data, data + samples * size_t(format.bytes_per_sample));
  return frame;
}

Camera::Camera(const CameraOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Validate();
  impl_->options = options;
  impl_->Open();
  impl_->Configure();
  impl_->CreateStream();
}

Camera::~Camera() = default;

const CameraInfo& Camera::info() const { return impl_->info; }
const PixelFormatInfo& Camera::pixel_format() const { return impl_->format; }

double Camera::gain() const {
  if (!arv_camera_is_gain_available(impl_->camera, nullptr)) return 0.0;
  return arv_camera_get_gain(impl_->camera, nullptr);
}

void Camera::ExposureBoundsUs(double* min_us, double* max_us) const {
  GError* error = nullptr;
  arv_camera_get_exposure_time_bounds(impl_->camera, min_us, max_us, &error);
  Check(error, impl_->Name() + ": cannot read the exposure range");
}

double Camera::SetExposureUs(double exposure_us, int settle_frames) {
  // The stream is stopped and drained around the change. Changing the exposure
  // while streaming leaves frames exposed at the old setting queued or in
  // flight, and Aravis stamps a frame's system time when its stream thread
  // handles it, not when it arrived: with that thread behind (1000 frames/s on
  // a busy host), old frames come out after the change with later stamps than
  // it. Stopped, no new frame starts; every frame still on its way is drained
  // and dropped; after the restart, `settle_frames` more are dropped for
  // cameras that apply a setting one frame late.
  const bool was_streaming = impl_->streaming;
  if (was_streaming) {
    GError* error = nullptr;
    arv_camera_stop_acquisition(impl_->camera, &error);
    impl_->streaming = false;
    if (error != nullptr) {
      throw CameraStreamError(impl_->Name() + ": cannot stop: " + TakeMessage(error), true);
    }
    impl_->Drain();
  }
  GError* error = nullptr;
  arv_camera_set_exposure_time(impl_->camera, exposure_us, &error);
  if (error != nullptr) {
    const std::string message = TakeMessage(error);
    if (impl_->control_lost.load()) throw CameraStreamError(impl_->Name() + ": " + message, true);
    throw Error(impl_->Name() + ": cannot set exposure " + FormatNumber(exposure_us) +
                " us: " + message);
  }
  impl_->exposure_us = arv_camera_get_exposure_time(impl_->camera, &error);
  if (error != nullptr) throw CameraStreamError(impl_->Name() + ": " + TakeMessage(error), true);
  if (was_streaming) Start();
  impl_->changed_at_ns = HostTimeNs();
  impl_->settle_left = was_streaming ? settle_frames : 0;
  return impl_->exposure_us;
}

double Camera::exposure_us() const { return impl_->exposure_us; }

void Camera::Start() {
  GError* error = nullptr;
  arv_camera_start_acquisition(impl_->camera, &error);
  if (error != nullptr) {
    throw CameraStreamError(impl_->Name() + ": cannot start: " + TakeMessage(error), true);
  }
  impl_->streaming = true;
  impl_->settle_left = 0;
}

void Camera::Stop() {
  if (!impl_->streaming) return;
  impl_->streaming = false;
  GError* error = nullptr;
  arv_camera_stop_acquisition(impl_->camera, &error);
  if (error != nullptr) spdlog::warn("{}: stopping: {}", impl_->Name(), TakeMessage(error));
}

void Camera::Abandon() {
  impl_->streaming = false;
  impl_->abandoned = true;
}

Frame Camera::NextFrame() {
  Impl& impl = *impl_;
  const uint64_t timeout_us =
      uint64_t(impl.options.frame_timeout_ms) * 1000u + uint64_t(2.0 * impl.exposure_us);
  for (;;) {
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(impl.stream, timeout_us);
    if (buffer == nullptr) {
      throw CameraStreamError(
          impl.Name() + ": no frame within " + std::to_string(timeout_us / 1000) + " ms" +
              (impl.control_lost.load() ? " and the camera stopped answering (disconnected?)"
                                        : " (disconnected, or not streaming?)"),
          true);
    }
    const ArvBufferStatus status = arv_buffer_get_status(buffer);
    const uint64_t arrived_ns = arv_buffer_get_system_timestamp(buffer);
    const uint64_t frame_id = arv_buffer_get_frame_id(buffer);
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      arv_stream_push_buffer(impl.stream, buffer);
      const char* why = status == ARV_BUFFER_STATUS_MISSING_PACKETS ? "lost packets"
                        : status == ARV_BUFFER_STATUS_TIMEOUT       ? "timed out"
                        : status == ARV_BUFFER_STATUS_SIZE_MISMATCH ? "had the wrong size"
                                                                    : "failed";
      guint64 completed = 0, failures = 0, underruns = 0;
      arv_stream_get_statistics(impl.stream, &completed, &failures, &underruns);
      // Without a free buffer Aravis drops a frame's packets: the writers fell
      // behind the camera and frames were lost on the way (reported as such).
      const std::string cause =
          underruns > 0 ? "; the stream ran out of buffers before (" + std::to_string(underruns) +
                              " underruns): frames arrive faster than they are written"
                        : "";
      throw CameraStreamError(impl.Name() + ": frame " + std::to_string(frame_id) + " " + why +
                                  " (buffer status " + std::to_string(int(status)) + ")" + cause,
                              false);
    }
    if (arrived_ns < impl.changed_at_ns) {
      arv_stream_push_buffer(impl.stream, buffer);
      spdlog::debug("dropped frame {}: arrived before the exposure change", frame_id);
      continue;
    }
    if (impl.settle_left > 0) {
      --impl.settle_left;
      arv_stream_push_buffer(impl.stream, buffer);
      spdlog::debug("dropped frame {}: settling after the exposure change", frame_id);
      continue;
    }
    try {
      Frame frame = impl.CopyFrame(buffer);
      arv_stream_push_buffer(impl.stream, buffer);
      return frame;
    } catch (...) {
      arv_stream_push_buffer(impl.stream, buffer);
      throw;
    }
  }
}

StreamStatistics Camera::Statistics() const {
  StreamStatistics statistics;
  if (impl_->stream == nullptr) return statistics;
  guint64 completed = 0, failures = 0, underruns = 0;
  arv_stream_get_statistics(impl_->stream, &completed, &failures, &underruns);
  statistics.completed = completed;
  statistics.failures = failures;
  statistics.underruns = underruns;
  if (ARV_IS_GV_STREAM(impl_->stream)) {
    guint64 resent = 0, missing = 0;
    arv_gv_stream_get_statistics(ARV_GV_STREAM(impl_->stream), &resent, &missing);
    statistics.resent_packets = resent;
    statistics.missing_packets = missing;
  }
  return statistics;
}

}  // namespace igi::capture
