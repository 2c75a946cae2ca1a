#include "calib/response_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "tools/common/atomic_file.h"

namespace igi::calib {
namespace {

std::string ChannelColour(const std::string& name) {
  if (name == "R") return "#d62728";
  if (name == "G") return "#2ca02c";
  if (name == "B") return "#1f77b4";
  return "#333333";
}

}  // namespace

std::string ResponsePlotSvg(const ResponseCurve& curve, int width, int height) {
  double lo = 1e30, hi = -1e30;
  for (const auto& g : curve.g) {
    // The lowest levels can sit far below the rest (ln of ~0); clip the axis at level 1.
    lo = std::min(lo, g.size() > 1 ? g[1] : g[0]);
    hi = std::max(hi, g.back());
  }
  if (!(hi > lo)) hi = lo + 1.0;
  const double margin = 50.0;
  const double pw = width - 2 * margin, ph = height - 2 * margin;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<rect x=\"{2}\" y=\"{2}\" width=\"{3}\" height=\"{4}\" fill=\"none\" stroke=\"black\"/>\n",
      width, height, margin, pw, ph);
  svg += fmt::format(
      "<text x=\"{}\" y=\"{}\" font-size=\"14\" text-anchor=\"middle\">ln exposure g(z) "
      "[{:.2f}, {:.2f}]</text>\n",
      width / 2, height - 15, lo, hi);
  svg += fmt::format(
      "<text x=\"15\" y=\"{}\" font-size=\"14\" transform=\"rotate(-90 15 {})\" "
      "text-anchor=\"middle\">pixel level z (0..{})</text>\n",
      height / 2, height / 2, curve.levels - 1);
  svg += fmt::format("<text x=\"{}\" y=\"30\" font-size=\"14\">{} response</text>\n", margin,
                     curve.method);
  for (size_t c = 0; c < curve.g.size(); ++c) {
    const std::string name = c < curve.channels.size() ? curve.channels[c] : "";
    std::string points;
    const int step = std::max(1, curve.levels / 512);
    for (int z = 1; z < curve.levels; z += step) {
      const double x = margin + (std::clamp(curve.g[c][size_t(z)], lo, hi) - lo) / (hi - lo) * pw;
      const double y = margin + ph - double(z) / (curve.levels - 1) * ph;
      points += fmt::format("{:.1f},{:.1f} ", x, y);
    }
    svg +=
        fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" points=\"{}\"/>\n",
                    ChannelColour(name), points);
  }
  svg += "</svg>\n";
  return svg;
}

void WriteResponsePlot(const std::filesystem::path& path, const ResponseCurve& curve) {
  WriteFileAtomic(path, ResponsePlotSvg(curve));
}

}  // namespace igi::calib
