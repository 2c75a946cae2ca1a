#include "capture/pixel_format.h"

#include <array>

namespace igi::capture {
namespace {

const std::vector<PixelFormatInfo>& Table() {
  static const std::vector<PixelFormatInfo> table = [] {
    std::vector<PixelFormatInfo> formats = {
        {"Mono8", 1, 8, 1, false},   {"Mono10", 1, 10, 2, false}, {"Mono12", 1, 12, 2, false},
        {"Mono14", 1, 14, 2, false}, {"Mono16", 1, 16, 2, false}, {"RGB8", 3, 8, 1, false},
    };
    const std::array<const char*, 4> mosaics = {"BayerGR", "BayerRG", "BayerGB", "BayerBG"};
    for (const char* mosaic : mosaics) {
      for (int bits : {8, 10, 12, 16}) {
        formats.push_back(
            {std::string(mosaic) + std::to_string(bits), 1, bits, bits > 8 ? 2 : 1, true});
      }
    }
    return formats;
  }();
  return table;
}

}  // namespace

std::optional<PixelFormatInfo> FindPixelFormat(const std::string& name) {
  for (const PixelFormatInfo& info : Table()) {
    if (info.name == name) return info;
  }
  return std::nullopt;
}

std::vector<std::string> SupportedPixelFormatNames() {
  std::vector<std::string> names;
  for (const PixelFormatInfo& info : Table()) names.push_back(info.name);
  return names;
}

}  // namespace igi::capture
