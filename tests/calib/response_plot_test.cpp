#include "calib/response_plot.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tools/common/atomic_file.h"

namespace igi::calib {
namespace {

TEST(ResponsePlot, OnePolylinePerChannelInItsColour) {
  const ResponseCurve curve = LinearResponse(256, 3);
  const std::string svg = ResponsePlotSvg(curve);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  size_t count = 0;
  for (size_t at = svg.find("<polyline"); at != std::string::npos;
       at = svg.find("<polyline", at + 1)) {
    ++count;
  }
  EXPECT_EQ(count, 3u);
  EXPECT_NE(svg.find("#d62728"), std::string::npos);
  const auto path = std::filesystem::temp_directory_path() / "igi_plot_test.svg";
  WriteResponsePlot(path, curve);
  EXPECT_EQ(ReadFileToString(path), svg);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace igi::calib
