#pragma once
// The camera pixel formats igi-capture can store losslessly, by their GenICam
// (PFNC) names. Every supported format is unpacked: one 8-bit or one
// little-endian 16-bit container per sample.

#include <optional>
#include <string>
#include <vector>

namespace igi::capture {

struct PixelFormatInfo {
  std::string name;          // GenICam name: "Mono8", "Mono12", "RGB8", "BayerRG16", …
  int channels = 1;          // 1 (mono or a Bayer mosaic) or 3 (RGB)
  int significant_bits = 8;  // levels run from 0 to 2^significant_bits - 1
  int bytes_per_sample = 1;  // 1 or 2 (little-endian)
  bool bayer = false;        // a colour filter mosaic, stored undemosaiced
};

// The format named `name`, or nullopt when igi-capture cannot store it (packed
// formats, YUV, …).
std::optional<PixelFormatInfo> FindPixelFormat(const std::string& name);

// Names of every supported format, for messages.
std::vector<std::string> SupportedPixelFormatNames();

}  // namespace igi::capture
