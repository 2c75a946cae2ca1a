#include "capture/frame_writer.h"

#include <OpenImageIO/imageio.h>

#include <bit>
#include <vector>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi::capture {

uint16_t WidenTo16Bits(uint16_t level, int significant_bits) {
  if (significant_bits >= 16) return level;
  const int shift = 16 - significant_bits;
  uint32_t wide = uint32_t(level) << shift;
  // Repeat the top bits into the freed low bits until they are filled.
  for (int filled = significant_bits; filled < 16; filled += significant_bits) {
    wide |= uint32_t(level) << shift >> filled;
  }
  return static_cast<uint16_t>(wide);
}

namespace {

// The 16-bit samples to store, in one pass over the camera's data into a
// buffer reused by the calling thread (no allocation per frame); the data
// itself when it is already 16-bit little-endian on a little-endian host.
const uint16_t* WideSamples(const Frame& frame) {
  const int bits = frame.format.significant_bits;
  const size_t count = frame.sample_count();
  const uint8_t* in = frame.data.data();
  if (frame.format.bytes_per_sample == 2 && bits >= 16 &&
      std::endian::native == std::endian::little) {
    return reinterpret_cast<const uint16_t*>(in);  // operator new's alignment suffices
  }
  thread_local std::vector<uint16_t> wide;
  wide.resize(count);
  uint16_t* out = wide.data();
  if (frame.format.bytes_per_sample == 1) {
    if (bits == 8) {
      // v * 257 = v << 8 | v (vectorised).
      for (size_t i = 0; i < count; ++i) out[i] = static_cast<uint16_t>(in[i] * 257u);
    } else {
      for (size_t i = 0; i < count; ++i) out[i] = WidenTo16Bits(in[i], bits);
    }
    return out;
  }
  for (size_t i = 0; i < count; ++i) out[i] = frame.level(i);
  if (bits < 16) {
    // One copy of the top bits fills the low ones (same result as
    // WidenTo16Bits when bits >= 8).
    const unsigned shift = 16u - unsigned(bits);
    const unsigned down = 2u * unsigned(bits) - 16u;
    for (size_t i = 0; i < count; ++i) {
      out[i] = static_cast<uint16_t>(uint16_t(out[i] << shift) | uint16_t(out[i] >> down));
    }
  }
  return out;
}

}  // namespace

void WriteFrame(const std::filesystem::path& path, const Frame& frame, bool durable) {
  const int channels = frame.format.channels;
  const uint16_t* samples = WideSamples(frame);
  AtomicOutput output(path);
  auto out = OIIO::ImageOutput::create(output.temp_path().string());
  if (!out) {
    throw Error(path.string() + ": cannot write: " + OIIO::geterror());
  }
  OIIO::ImageSpec spec(frame.width, frame.height, channels, OIIO::TypeDesc::UINT16);
  const std::string extension = path.extension().string();
  if (extension == ".png") {
    spec.attribute("png:compressionLevel", 1);
  } else {
    spec.attribute("compression", "none");
  }
  spec.attribute("igi:pixel_format", frame.format.name);
  spec.attribute("igi:significant_bits", frame.format.significant_bits);
  if (!out->open(output.temp_path().string(), spec) ||
      !out->write_image(OIIO::TypeDesc::UINT16, samples) || !out->close()) {
    throw Error(path.string() + ": cannot write: " + out->geterror());
  }
  if (durable) {
    output.Commit();
    return;
  }
  std::error_code error;
  std::filesystem::rename(output.temp_path(), path, error);
  if (error) throw Error(path.string() + ": cannot write: " + error.message());
}

}  // namespace igi::capture
