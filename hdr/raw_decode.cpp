#include "hdr/raw_decode.h"

#include <fmt/format.h>
#include <libraw/libraw.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <memory>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/strings.h"

namespace igi::hdr {
namespace {

void Check(int code, const std::filesystem::path& path, const char* step) {
  if (code != LIBRAW_SUCCESS) {
    throw InputError(
        DescribeProblem(path.string(), "raw", step,
                        fmt::format("LibRaw cannot decode it: {}", libraw_strerror(code))));
  }
}

void SetLinearParams(LibRaw* raw, const RawDecodeOptions& options) {
  libraw_output_params_t& p = raw->imgdata.params;
  p.output_bps = 16;
  p.gamm[0] = 1.0;  // no gamma
  p.gamm[1] = 1.0;
  p.no_auto_bright = 1;
  p.highlight = 0;              // clip at the white level
  p.adjust_maximum_thr = 0.0f;  // keep the file's white level (no lowering to the data maximum)
  p.use_auto_wb = 0;
  p.use_camera_wb = options.white_balance == RawWhiteBalance::kCamera ? 1 : 0;
  if (options.white_balance == RawWhiteBalance::kNone) {
    for (float& m : p.user_mul) m = 1.0f;
  }
  p.output_color = options.color == RawColor::kRaw ? 0 : 1;
  p.half_size = options.half_size ? 1 : 0;
  p.user_qual = 3;  // AHD demosaicing
}

}  // namespace

constexpr EnumNames<RawWhiteBalance, 2> kRawWhiteBalanceNames{
    {{RawWhiteBalance::kCamera, "camera"}, {RawWhiteBalance::kNone, "none"}}};

std::string_view RawWhiteBalanceName(RawWhiteBalance white_balance) {
  return kRawWhiteBalanceNames.Name(white_balance);
}
std::optional<RawWhiteBalance> RawWhiteBalanceFromName(std::string_view name) {
  return kRawWhiteBalanceNames.FromName(name);
}

constexpr EnumNames<RawColor, 2> kRawColorNames{
    {{RawColor::kSrgb, "srgb"}, {RawColor::kRaw, "raw"}}};

std::string_view RawColorName(RawColor color) { return kRawColorNames.Name(color); }
std::optional<RawColor> RawColorFromName(std::string_view name) {
  return kRawColorNames.FromName(name);
}

void RawDecodeOptions::Validate() const {
  ProblemList problems;
  if (!RawWhiteBalanceFromName(RawWhiteBalanceName(white_balance))) {
    problems.Add("--raw-white-balance", "", std::to_string(int(white_balance)),
                 "must be camera or none");
  }
  if (!RawColorFromName(RawColorName(color))) {
    problems.Add("--raw-color", "", std::to_string(int(color)), "must be srgb or raw");
  }
  problems.ThrowIfAny();
}

bool IsRawFile(const std::filesystem::path& path) {
  static const char* const kExtensions[] = {".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw",
                                            ".arw", ".srf", ".sr2", ".raf", ".orf", ".rw2",
                                            ".pef", ".srw", ".kdc", ".dcr", ".mrw", ".3fr",
                                            ".erf", ".iiq", ".x3f", ".rwl", ".raw", ".mef"};
  const std::string ext = ToLower(path.extension().string());
  for (const char* e : kExtensions) {
    if (ext == e) return true;
  }
  return false;
}

RawImage DecodeRaw(const std::filesystem::path& path, const RawDecodeOptions& options) {
  options.Validate();
  auto raw = std::make_unique<LibRaw>();
  Check(raw->open_file(path.c_str()), path, "open");
  Check(raw->unpack(), path, "unpack");
  RawImage out;
  // Black and white levels as the file gives them (dcraw_process rewrites them).
  out.black_level = int(raw->imgdata.color.black);
  out.white_level = int(raw->imgdata.color.maximum);
  SetLinearParams(raw.get(), options);
  Check(raw->dcraw_process(), path, "process");
  int code = LIBRAW_SUCCESS;
  libraw_processed_image_t* processed = raw->dcraw_make_mem_image(&code);
  Check(code, path, "make image");
  std::unique_ptr<libraw_processed_image_t, void (*)(libraw_processed_image_t*)> guard(
      processed, &LibRaw::dcraw_clear_mem);
  if (processed->type != LIBRAW_IMAGE_BITMAP || processed->bits != 16) {
    throw InputError(DescribeProblem(path.string(), "raw", "not a 16-bit bitmap",
                                     "LibRaw returned an unexpected image"));
  }
  const int w = processed->width, h = processed->height, c = processed->colors;
  out.image = Image(w, h, 3);
  const auto* data = reinterpret_cast<const uint16_t*>(processed->data);
  for (int64_t i = 0; i < int64_t(w) * h; ++i) {
    for (int k = 0; k < 3; ++k) {
      out.image.pixels[size_t(i) * 3 + k] =
          float(data[size_t(i) * c + std::min(k, c - 1)]) / 65535.0f;
    }
  }
  const auto& d = raw->imgdata;
  out.exposure_s = d.other.shutter;
  out.iso = d.other.iso_speed;
  out.aperture = d.other.aperture;
  out.raw_bits = out.white_level > 0 ? int(std::ceil(std::log2(double(out.white_level + 1)))) : 0;
  out.camera = fmt::format("{} {}", d.idata.make, d.idata.model);
  if (out.exposure_s > 0) out.image.metadata["ExposureTime"] = out.exposure_s;
  if (out.iso > 0) out.image.metadata["Exif:ISOSpeedRatings"] = out.iso;
  if (out.aperture > 0) out.image.metadata["FNumber"] = out.aperture;
  out.image.metadata["Make"] = std::string(d.idata.make);
  out.image.metadata["Model"] = std::string(d.idata.model);
  spdlog::debug("{}: {} {}x{}, black {}, white {}, {} s, ISO {}", path.string(), out.camera, w, h,
                out.black_level, out.white_level, out.exposure_s, out.iso);
  return out;
}

}  // namespace igi::hdr
