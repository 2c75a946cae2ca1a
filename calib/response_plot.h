#pragma once
// A plot of response curves as SVG, drawn like Debevec & Malik's figure: pixel level (y) against
// ln exposure g (x), one polyline per channel in its colour.

#include <filesystem>
#include <string>

#include "calib/response_curve.h"

namespace igi::calib {

// The SVG document of `curve` (width x height pixels).
std::string ResponsePlotSvg(const ResponseCurve& curve, int width = 640, int height = 480);

// Writes it atomically. Throws igi::Error when the file can't be written.
void WriteResponsePlot(const std::filesystem::path& path, const ResponseCurve& curve);

}  // namespace igi::calib
