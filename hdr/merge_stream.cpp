#include "hdr/merge_stream.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include "tools/common/error.h"
#include "tools/common/parallel.h"
#include "tools/common/progress.h"

namespace igi::hdr {
namespace {

// One frame of the bracket, read a band at a time and moved by a PixelShift on the way (out(x, y)
// = in(clamp(x - dx), clamp(y - dy)), as ShiftImage). Unshifted frames are read straight into the
// band; shifted ones row by row through one cached source row, so the rows asked of the file only
// ever go forward (a scanline file read backwards is decoded again from the start).
class FrameBands {
 public:
  FrameBands(const std::filesystem::path& path, const PixelShift& shift)
      : reader_(std::make_unique<ImageRowReader>(path)), shift_(shift) {
    if (shifted()) row_.resize(size_t(info().width) * size_t(info().channels));
  }

  const ImageInfo& info() const { return reader_->info(); }
  bool shifted() const { return shift_.dx != 0 || shift_.dy != 0; }
  size_t row_buffer_bytes() const { return row_.size() * sizeof(float); }

  // Fills rows [y0, y1) of the shifted frame into `out` ((y1 - y0) x width x channels floats).
  void Read(int y0, int y1, float* out) {
    if (!shifted()) {
      reader_->ReadRows(y0, y1, out);
      return;
    }
    const int width = info().width, height = info().height, channels = info().channels;
    for (int y = y0; y < y1; ++y) {
      const int sy = std::clamp(y - shift_.dy, 0, height - 1);
      if (sy != cached_row_) {
        reader_->ReadRows(sy, sy + 1, row_.data());
        cached_row_ = sy;
      }
      float* dst = out + size_t(y - y0) * size_t(width) * size_t(channels);
      for (int x = 0; x < width; ++x) {
        const int sx = std::clamp(x - shift_.dx, 0, width - 1);
        std::copy_n(&row_[size_t(sx) * size_t(channels)], channels, dst + size_t(x) * channels);
      }
    }
  }

 private:
  std::unique_ptr<ImageRowReader> reader_;
  PixelShift shift_;
  std::vector<float> row_;  // source row `cached_row_` (shifted frames only)
  int cached_row_ = -1;
};

// Opens every frame; frames of another size or channel count than the first are InputErrors
// (all of them reported), as calib::CheckSameShape.
std::vector<FrameBands> OpenFrames(const std::vector<std::filesystem::path>& frames,
                                   const std::vector<PixelShift>& shifts) {
  if (frames.empty()) {
    throw InputError(DescribeProblem("bracket", "images", "0", "need at least one image"));
  }
  if (!shifts.empty() && shifts.size() != frames.size()) {
    throw InputError(DescribeProblem("bracket", "shifts", fmt::format("{}", shifts.size()),
                                     fmt::format("need one shift per image ({})", frames.size())));
  }
  ProblemList problems;
  std::vector<FrameBands> opened;
  for (size_t j = 0; j < frames.size(); ++j) {
    try {
      opened.emplace_back(frames[j], shifts.empty() ? PixelShift{} : shifts[j]);
    } catch (const Error& e) {
      problems.Append(e);
    }
  }
  problems.ThrowIfAny();
  const ImageInfo& first = opened[0].info();
  for (size_t j = 1; j < opened.size(); ++j) {
    const ImageInfo& info = opened[j].info();
    if (info.width != first.width || info.height != first.height ||
        info.channels != first.channels) {
      problems.Add(frames[j].string(), "size",
                   fmt::format("{}x{}x{}", info.width, info.height, info.channels),
                   fmt::format("every image of a bracket must have the size of {} ({}x{}x{})",
                               frames[0].string(), first.width, first.height, first.channels));
    }
  }
  problems.ThrowIfAny();
  return opened;
}

}  // namespace

void HdrStreamOptions::Validate() const {
  if (band_rows < 1 || band_rows > 65536) {
    throw InputError(
        DescribeProblem("--band-rows", "", fmt::format("{}", band_rows), "must be 1 .. 65536"));
  }
}

StreamMergeSummary MergeBracketStreamed(const std::vector<std::filesystem::path>& frames,
                                        const std::vector<double>& exposures_s,
                                        const std::vector<PixelShift>& shifts,
                                        const calib::ResponseCurve& response,
                                        const MergeOptions& merge, const HdrStreamOptions& options,
                                        const StreamOutputs& outputs) {
  options.Validate();
  merge.Validate();
  const auto start = std::chrono::steady_clock::now();
  if (frames.size() != exposures_s.size()) {
    throw InputError(DescribeProblem(
        "bracket", "images", fmt::format("{}", frames.size()),
        fmt::format("need one exposure time per image ({} given)", exposures_s.size())));
  }
  std::vector<FrameBands> opened = OpenFrames(frames, shifts);
  StreamMergeSummary summary;
  summary.width = opened[0].info().width;
  summary.height = opened[0].info().height;
  summary.channels = opened[0].info().channels;
  const int width = summary.width, height = summary.height, channels = summary.channels;
  const BandMerger merger(channels, exposures_s, response, merge);

  const int band_rows = std::min(options.band_rows, height);
  const size_t band_values = size_t(band_rows) * size_t(width) * size_t(channels);
  const size_t mask_values = size_t(band_rows) * size_t(width);
  // What the merge holds: a band of every frame, the merged band, its mask, and a source row of
  // each shifted frame (already allocated when the frames were opened).
  summary.peak_buffer_bytes = ((frames.size() + 1) * band_values + mask_values) * sizeof(float);
  for (const FrameBands& frame : opened) summary.peak_buffer_bytes += frame.row_buffer_bytes();
  spdlog::debug("streamed merge: {} frames of {}x{}x{} in bands of {} rows: {:.1f} MB of buffers",
                frames.size(), width, height, channels, band_rows,
                double(summary.peak_buffer_bytes) / 1e6);
  std::vector<std::vector<float>> bands(frames.size(), std::vector<float>(band_values));
  std::vector<float> radiance(band_values), mask(mask_values);
  std::vector<const float*> band_pointers;
  for (std::vector<float>& band : bands) band_pointers.push_back(band.data());

  std::optional<ImageRowWriter> radiance_out, mask_out;
  Progress progress("merge rows", height);  // on a terminal, for merges longer than ~2 s
  for (int y0 = 0; y0 < height; y0 += band_rows) {
    const int y1 = std::min(y0 + band_rows, height);
    // The frames decode independently: one task each.
    ParallelFor(
        0, int64_t(opened.size()),
        [&](int64_t j) { opened[size_t(j)].Read(y0, y1, bands[size_t(j)].data()); },
        merge.num_threads);
    if (y0 == 0) {
      // Every check is done and the first band read: only now are the outputs created (as
      // temporary files, removed if a later band fails).
      radiance_out.emplace(outputs.radiance, width, height, channels, outputs.radiance_metadata);
      if (!outputs.mask.empty()) {
        WriteImageOptions mask_options;
        mask_options.type = PixelType::kUInt8;
        mask_out.emplace(outputs.mask, width, height, 1, ImageMetadata{}, mask_options);
      }
    }
    const BandMerger::Counts counts =
        merger.Merge(band_pointers, width, y1 - y0, radiance.data(), mask.data(), &progress);
    summary.saturated_pixels += counts.saturated_pixels;
    summary.black_pixels += counts.black_pixels;
    outputs.correction.Apply(radiance.data(), y0, y1, width, channels);
    radiance_out->WriteRows(y0, y1, radiance.data());
    if (mask_out) mask_out->WriteRows(y0, y1, mask.data());
    ++summary.bands;
  }
  progress.Finish();
  radiance_out->Commit();
  if (mask_out) mask_out->Commit();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::debug(
      "streamed merge: {}x{}x{}, {} images, {} bands of {} rows, {} buffer bytes, {:.3f} s", width,
      height, channels, frames.size(), summary.bands, band_rows, summary.peak_buffer_bytes,
      summary.seconds);
  return summary;
}

std::vector<GreyImage> ReadGreyFrames(const std::vector<std::filesystem::path>& frames,
                                      const HdrStreamOptions& options) {
  options.Validate();
  std::vector<FrameBands> opened = OpenFrames(frames, {});
  const int width = opened[0].info().width, height = opened[0].info().height;
  const int channels = opened[0].info().channels;
  const int band_rows = std::min(options.band_rows, height);
  std::vector<GreyImage> grey(frames.size());
  ParallelFor(0, int64_t(opened.size()), [&](int64_t j) {
    GreyImage& g = grey[size_t(j)];
    g.width = width;
    g.height = height;
    g.levels.resize(size_t(width) * size_t(height));
    std::vector<float> band(size_t(band_rows) * size_t(width) * size_t(channels));
    for (int y0 = 0; y0 < height; y0 += band_rows) {
      const int y1 = std::min(y0 + band_rows, height);
      opened[size_t(j)].Read(y0, y1, band.data());
      ToGreyLevels(band.data(), size_t(y1 - y0) * size_t(width), channels,
                   &g.levels[size_t(y0) * size_t(width)]);
    }
  });
  return grey;
}

}  // namespace igi::hdr
