#pragma once
// HtmlReport: one self-contained HTML5 page (report.html of igi-solve, igi-diagnose, igi-run).
// Nothing refers to an external file: images are embedded as data: URIs (PNG, base64), plots are
// inline SVG and the CSS is inline. All text given to the builder is HTML-escaped except
// RawHtml(). Non-finite pixels (NaN, ±Inf) are shown in magenta.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tools/common/image.h"

namespace igi {

class HtmlReport {
 public:
  // `title` is the page's <title> and its <h1>.
  explicit HtmlReport(std::string title);

  // <h2>..<h6> (level is clamped to 2..6; the title is the only <h1>).
  void Heading(const std::string& text, int level = 2);
  void Paragraph(const std::string& text);
  // A coloured box; kind is "info", "warning" or "error" (anything else is shown as "info").
  void Note(const std::string& text, std::string_view kind = "info");
  // A bordered table. `cell_classes` (optional, parallel to `rows`, may be shorter or ragged)
  // gives a css class per cell: "bad" (red), "warn" (amber), "good" (green); "" = none.
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows,
             const std::vector<std::vector<std::string>>& cell_classes = {});
  // A float image (e.g. linear radiance) shown as an sRGB PNG: values are multiplied by
  // `exposure` (0 = auto: the 99th percentile of the finite channel values maps to 0.9), clamped
  // to [0, 1] and sRGB-encoded. 1 channel = grey, 3 = RGB, 4+ = the first 3 (alpha dropped), 2 =
  // the last repeated. An empty image is shown as "(empty image)".
  // `width_px` is the display width (0 = native); an image more than twice as wide as width_px
  // is box-downsampled (integer factor) before encoding, to keep the page small.
  void Image(const igi::Image& linear, const std::string& caption, double exposure = 0,
             int width_px = 0);
  // A signed residual image in a diverging colour map: blue negative, white 0, red positive;
  // `scale` is the |value| shown at full colour (0 = auto: 99th percentile of |value|). The
  // colour channels (the first 3 at most) are averaged.
  void ResidualImage(const igi::Image& residual, const std::string& caption, double scale = 0,
                     int width_px = 0);
  // Several images side by side (each with its caption); options as in Image(). With exposure 0
  // each image gets its own auto exposure.
  void ImageRow(const std::vector<std::pair<igi::Image, std::string>>& images, double exposure = 0,
                int width_px = 0);

  struct Series {
    std::string name;
    std::vector<double> x, y;  // same length; non-finite points (and y <= 0 with log_y) skipped
  };
  // An inline SVG line plot: one <polyline> per series that has points, a legend, axes with
  // tick labels, optional logarithmic y axis.
  void LinePlot(const std::string& caption, const std::vector<Series>& series,
                const std::string& x_label, const std::string& y_label, bool log_y = false);
  // Appended as-is (the caller escapes).
  void RawHtml(const std::string& html);

  std::string Html() const;
  // Writes Html() atomically (temporary file + rename), creating parent folders.
  void Write(const std::filesystem::path& path) const;

 private:
  std::string title_;
  std::string body_;
};

// Escapes & < > " ' for use in text and attribute values.
std::string HtmlEscape(std::string_view text);
// Standard base64 (RFC 4648 §4) with '=' padding.
std::string Base64Encode(std::string_view bytes);
// PNG file bytes of an image whose values are display levels in [0, 1] (clamped, rounded to
// 8 bits; NaN becomes 0). 1, 2, 3 or 4 channels. Throws igi::Error if encoding fails.
std::string EncodePng(const igi::Image& display);

// The mappings Image() and ResidualImage() use, to 3-channel display levels in [0, 1]
// (non-finite pixels magenta; an image without channels gives an empty image). `exposure` /
// `scale` 0 = auto as described above; `exposure_used` receives the exposure applied.
igi::Image ToneMapSrgb(const igi::Image& linear, double exposure = 0,
                       double* exposure_used = nullptr);
igi::Image ResidualColours(const igi::Image& residual, double scale = 0);

}  // namespace igi
