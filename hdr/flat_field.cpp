#include "hdr/flat_field.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hdr/raw_decode.h"
#include "tools/common/error.h"
#include "tools/common/image.h"

namespace igi::hdr {
namespace {

// Feeds rows of recorded values to `reducer`: luminance is the mean of the channels made linear
// by `linear(channel, value)`; `recorded` says whether the levels are bounded by black and
// saturated (raw and 8/16-bit) or are linear floats.
template <typename Linear>
void AddRows(const float* values, int y0, int y1, int width, int channels, bool recorded,
             const FlatFieldReadOptions& options, const Linear& linear,
             calib::FlatFieldReducer* reducer) {
  std::vector<float> luminance(static_cast<size_t>(width));
  std::vector<uint8_t> usable(static_cast<size_t>(width));
  for (int y = y0; y < y1; ++y) {
    const float* row = values + size_t(y - y0) * size_t(width) * size_t(channels);
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      bool ok = true;
      for (int c = 0; c < channels; ++c) {
        const float v = row[size_t(x) * size_t(channels) + size_t(c)];
        if (recorded ? (v <= options.black || v >= options.saturated) : !(v > 0)) ok = false;
        sum += linear(c, v);
      }
      usable[size_t(x)] = ok ? 1 : 0;
      luminance[size_t(x)] = float(sum / channels);
    }
    reducer->AddRow(y, luminance.data(), usable.data());
  }
}

}  // namespace

calib::FlatField ReadFlatField(const std::filesystem::path& path,
                               const FlatFieldReadOptions& options) {
  const std::string name = path.string();
  if (IsRawFile(path)) {
    RawDecodeOptions raw;
    raw.white_balance = RawWhiteBalance::kNone;
    raw.color = RawColor::kRaw;
    const Image image = DecodeRaw(path, raw).image;
    calib::FlatFieldReducer reducer(name, image.width, image.height,
                                    options.block_px > 0
                                        ? options.block_px
                                        : calib::FlatFieldBlockSize(image.width, image.height));
    AddRows(
        image.pixels.data(), 0, image.height, image.width, image.channels, true, options,
        [](int, float v) { return double(v); }, &reducer);
    return reducer.Finish();
  }
  ImageRowReader reader(path);
  const ImageInfo& info = reader.info();
  const bool integer = info.type == PixelType::kUInt8 || info.type == PixelType::kUInt16;
  const int channels = std::min(info.channels, 3);
  if (integer) {
    if (!options.response) {
      throw InputError(DescribeProblem(name, "--response", "absent",
                                       "an 8/16-bit flat field needs its response (response.json "
                                       "or --linear)"));
    }
    const int curves = options.response->num_channels();
    if (curves != 1 && curves < channels) {
      throw InputError(DescribeProblem(name, "--response", fmt::format("{} channels", curves),
                                       fmt::format("the image has {}", channels)));
    }
  }
  const int block =
      options.block_px > 0 ? options.block_px : calib::FlatFieldBlockSize(info.width, info.height);
  calib::FlatFieldReducer reducer(name, info.width, info.height, block);
  constexpr int kBandRows = 64;
  std::vector<float> band(size_t(kBandRows) * size_t(info.width) * size_t(info.channels));
  std::vector<float> rgb(size_t(kBandRows) * size_t(info.width) * size_t(channels));
  for (int y0 = 0; y0 < info.height; y0 += kBandRows) {
    const int y1 = std::min(y0 + kBandRows, info.height);
    reader.ReadRows(y0, y1, band.data());
    // The first (up to) three channels: alpha and extra channels are not light.
    for (size_t p = 0; p < size_t(y1 - y0) * size_t(info.width); ++p) {
      for (int c = 0; c < channels; ++c) {
        rgb[p * size_t(channels) + size_t(c)] = band[p * size_t(info.channels) + size_t(c)];
      }
    }
    if (integer) {
      const calib::ResponseCurve& response = *options.response;
      AddRows(
          rgb.data(), y0, y1, info.width, channels, true, options,
          [&](int c, float v) {
            return std::exp(response.LnExposure(response.num_channels() == 1 ? 0 : c, v));
          },
          &reducer);
    } else {
      AddRows(
          rgb.data(), y0, y1, info.width, channels, false, options,
          [](int, float v) { return double(v); }, &reducer);
    }
  }
  return reducer.Finish();
}

}  // namespace igi::hdr
