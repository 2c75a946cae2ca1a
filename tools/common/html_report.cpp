#include "tools/common/html_report.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "tools/common/atomic_file.h"
#include "tools/common/error.h"

namespace igi {
namespace {

constexpr std::string_view kCss = R"(
body { font-family: sans-serif; max-width: 1200px; margin: 1em auto; padding: 0 1em;
       line-height: 1.4; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #999; padding: 2px 8px; text-align: left; }
th { background: #eee; }
td.bad { background: #f8c8c8; } td.warn { background: #fde9a8; } td.good { background: #cdeccd; }
.note { border-left: 5px solid; padding: 0.4em 0.8em; margin: 0.5em 0; }
.note.info { border-color: #3366cc; background: #eef3fb; }
.note.warning { border-color: #cc9900; background: #fff6dd; }
.note.error { border-color: #cc3333; background: #fde8e8; }
.row { display: flex; flex-wrap: wrap; gap: 10px; align-items: flex-start; }
figure { margin: 0.5em 0; }
figcaption { font-size: 90%; color: #444; }
img, svg { max-width: 100%; height: auto; }
svg text { font-family: sans-serif; font-size: 11px; }
)";

constexpr float kMagenta[3] = {1.0f, 0.0f, 1.0f};

// Number of colour channels shown: the first 3 at most (alpha and extras dropped).
int ColourChannels(const igi::Image& image) { return std::min(image.channels, 3); }

bool PixelFinite(const igi::Image& image, size_t pixel) {
  for (int c = 0; c < ColourChannels(image); ++c) {
    if (!std::isfinite(image.pixels[pixel * image.channels + c])) return false;
  }
  return true;
}

// The q-quantile (0..1) of the finite values; 0 if there are none.
double Quantile(std::vector<float> values, double q) {
  std::erase_if(values, [](float v) { return !std::isfinite(v); });
  if (values.empty()) return 0.0;
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

float SrgbEncode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
}

// Block means by an integer factor when the image is more than twice `width_px` wide.
igi::Image ShrinkForDisplay(const igi::Image& image, int width_px) {
  if (width_px <= 0 || image.width <= 2 * width_px) return image;
  return igi::BlockMeans(image, image.width / width_px);
}

std::string Figure(const igi::Image& display, const std::string& caption, int width_px,
                   const std::string& title) {
  if (display.empty()) {
    return "<figure><p>(empty image)</p><figcaption>" + HtmlEscape(caption) +
           "</figcaption></figure>\n";
  }
  const std::string alt = caption.empty() ? std::string("image") : caption;
  std::string html = "<figure><img src=\"data:image/png;base64," +
                     Base64Encode(EncodePng(display)) + "\" alt=\"" + HtmlEscape(alt) +
                     "\" title=\"" + HtmlEscape(title) + "\"";
  if (width_px > 0) html += fmt::format(" width=\"{}\"", width_px);
  html += "><figcaption>" + HtmlEscape(caption) + "</figcaption></figure>\n";
  return html;
}

std::string ImageFigure(const igi::Image& linear, const std::string& caption, double exposure,
                        int width_px) {
  double used = 0;
  const igi::Image display = ToneMapSrgb(ShrinkForDisplay(linear, width_px), exposure, &used);
  return Figure(display, caption, width_px,
                fmt::format("{} x {}, exposure {:.4g}", linear.width, linear.height, used));
}

// ---- SVG line plot ----

struct Axis {
  double lo = 0, hi = 1;
  std::vector<double> ticks;
};

Axis LinearAxis(double lo, double hi) {
  if (!(hi > lo)) {
    lo -= 0.5;
    hi += 0.5;
  }
  const double raw = (hi - lo) / 5;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {2.0, 5.0, 10.0}) {
    if (step < raw) step = m * mag;
  }
  Axis axis{std::floor(lo / step) * step, std::ceil(hi / step) * step, {}};
  for (int i = 0; i <= 12; ++i) {
    const double t = axis.lo + i * step;
    if (t > axis.hi + step * 1e-6) break;
    axis.ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  }
  return axis;
}

// lo, hi are log10 values; ticks at whole decades.
Axis LogAxis(double lo, double hi) {
  Axis axis{std::floor(lo), std::ceil(hi), {}};
  if (axis.hi <= axis.lo) axis.hi = axis.lo + 1;
  const double step = std::max(1.0, std::ceil((axis.hi - axis.lo) / 8));
  for (double t = axis.lo; t <= axis.hi + 1e-9; t += step) axis.ticks.push_back(t);  // <= 9
  return axis;
}

constexpr const char* kSeriesColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                          "#9467bd", "#8c564b", "#e377c2", "#17becf"};

}  // namespace

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64Encode(std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) {
      v = (v << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
    }
    for (size_t k = 0; k < 4; ++k) {
      out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
    }
  }
  return out;
}

std::string EncodePng(const igi::Image& display) {
  if (display.empty() || display.channels < 1 || display.channels > 4) {
    throw Error(fmt::format("EncodePng: cannot encode a {}x{} image with {} channels",
                            display.width, display.height, display.channels));
  }
  std::vector<unsigned char> levels(display.pixels.size());
  for (size_t i = 0; i < levels.size(); ++i) {
    const float v = display.pixels[i];
    levels[i] = std::isfinite(v) ? uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)) : 0;
  }
  OIIO::Filesystem::IOVecOutput proxy;
  auto out = OIIO::ImageOutput::create("png");
  if (!out || !out->set_ioproxy(&proxy)) {
    throw Error("EncodePng: no in-memory PNG writer: " + OIIO::geterror());
  }
  const OIIO::ImageSpec spec(display.width, display.height, display.channels,
                             OIIO::TypeDesc::UINT8);
  if (!out->open("memory.png", spec) || !out->write_image(OIIO::TypeDesc::UINT8, levels.data()) ||
      !out->close()) {
    throw Error("EncodePng: PNG encoding failed: " + out->geterror());
  }
  const auto& buffer = proxy.buffer();
  return std::string(buffer.begin(), buffer.end());
}

igi::Image ToneMapSrgb(const igi::Image& linear, double exposure, double* exposure_used) {
  const int cc = ColourChannels(linear);
  if (cc <= 0) return {};
  const size_t n = size_t(linear.width) * linear.height;
  if (exposure <= 0) {
    std::vector<float> values;
    values.reserve(n * cc);
    for (size_t p = 0; p < n; ++p) {
      for (int c = 0; c < cc; ++c) values.push_back(linear.pixels[p * linear.channels + c]);
    }
    const double p99 = Quantile(std::move(values), 0.99);
    exposure = p99 > 0 ? 0.9 / p99 : 1.0;
  }
  if (exposure_used != nullptr) *exposure_used = exposure;
  igi::Image out(linear.width, linear.height, 3);
  for (size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) {
      out.pixels[p * 3 + c] =
          PixelFinite(linear, p)
              ? SrgbEncode(exposure * linear.pixels[p * linear.channels + std::min(c, cc - 1)])
              : kMagenta[c];
    }
  }
  return out;
}

igi::Image ResidualColours(const igi::Image& residual, double scale) {
  const int cc = ColourChannels(residual);
  if (cc <= 0) return {};
  const size_t n = size_t(residual.width) * residual.height;
  std::vector<float> mean(n);
  for (size_t p = 0; p < n; ++p) {
    double sum = 0;
    for (int c = 0; c < cc; ++c) sum += residual.pixels[p * residual.channels + c];
    mean[p] = float(sum / cc);
  }
  if (scale <= 0) {
    std::vector<float> magnitudes(n);
    for (size_t p = 0; p < n; ++p) magnitudes[p] = std::abs(mean[p]);
    scale = Quantile(std::move(magnitudes), 0.99);
    if (!(scale > 0)) scale = 1.0;
  }
  igi::Image out(residual.width, residual.height, 3);
  for (size_t p = 0; p < n; ++p) {
    float* rgb = &out.pixels[p * 3];
    if (!std::isfinite(mean[p])) {
      std::copy(kMagenta, kMagenta + 3, rgb);
      continue;
    }
    const float t = float(std::clamp(mean[p] / scale, -1.0, 1.0));
    rgb[0] = t < 0 ? 1 + t : 1;  // negative: white -> blue
    rgb[1] = 1 - std::abs(t);
    rgb[2] = t > 0 ? 1 - t : 1;  // positive: white -> red
  }
  return out;
}

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::Heading(const std::string& text, int level) {
  level = std::clamp(level, 2, 6);
  body_ += fmt::format("<h{0}>{1}</h{0}>\n", level, HtmlEscape(text));
}

void HtmlReport::Paragraph(const std::string& text) {
  body_ += "<p>" + HtmlEscape(text) + "</p>\n";
}

void HtmlReport::Note(const std::string& text, std::string_view kind) {
  if (kind != "warning" && kind != "error") kind = "info";
  body_ += fmt::format("<div class=\"note {}\">{}</div>\n", kind, HtmlEscape(text));
}

void HtmlReport::Table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows,
                       const std::vector<std::vector<std::string>>& cell_classes) {
  body_ += "<table>\n";
  if (!header.empty()) {
    body_ += "<tr>";
    for (const auto& h : header) body_ += "<th>" + HtmlEscape(h) + "</th>";
    body_ += "</tr>\n";
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    body_ += "<tr>";
    for (size_t c = 0; c < rows[r].size(); ++c) {
      const bool has_class =
          r < cell_classes.size() && c < cell_classes[r].size() && !cell_classes[r][c].empty();
      body_ += has_class ? "<td class=\"" + HtmlEscape(cell_classes[r][c]) + "\">" : "<td>";
      body_ += HtmlEscape(rows[r][c]) + "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::Image(const igi::Image& linear, const std::string& caption, double exposure,
                       int width_px) {
  body_ += ImageFigure(linear, caption, exposure, width_px);
}

void HtmlReport::ResidualImage(const igi::Image& residual, const std::string& caption, double scale,
                               int width_px) {
  const igi::Image small = ShrinkForDisplay(residual, width_px);
  body_ += Figure(ResidualColours(small, scale), caption, width_px,
                  scale > 0 ? fmt::format("full colour at ±{:.4g}", scale) : "auto scale");
}

void HtmlReport::ImageRow(const std::vector<std::pair<igi::Image, std::string>>& images,
                          double exposure, int width_px) {
  body_ += "<div class=\"row\">\n";
  for (const auto& [image, caption] : images) {
    body_ += ImageFigure(image, caption, exposure, width_px);
  }
  body_ += "</div>\n";
}

void HtmlReport::LinePlot(const std::string& caption, const std::vector<Series>& series,
                          const std::string& x_label, const std::string& y_label, bool log_y) {
  constexpr double kW = 760, kH = 360, kLeft = 70, kRight = 560, kTop = 15, kBottom = 310;
  // Kept points per series (y in log10 when log_y).
  std::vector<std::vector<std::pair<double, double>>> points(series.size());
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (size_t s = 0; s < series.size(); ++s) {
    const size_t n = std::min(series[s].x.size(), series[s].y.size());
    for (size_t i = 0; i < n; ++i) {
      const double x = series[s].x[i];
      const double y = log_y ? std::log10(series[s].y[i]) : series[s].y[i];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      points[s].emplace_back(x, y);
      x_lo = std::min(x_lo, x);
      x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y);
      y_hi = std::max(y_hi, y);
    }
  }
  if (!(x_hi >= x_lo)) {  // no points at all
    x_lo = y_lo = 0;
    x_hi = y_hi = 1;
  }
  const Axis ax = LinearAxis(x_lo, x_hi);
  const Axis ay = log_y ? LogAxis(y_lo, y_hi) : LinearAxis(y_lo, y_hi);
  auto px = [&](double x) { return kLeft + (x - ax.lo) / (ax.hi - ax.lo) * (kRight - kLeft); };
  auto py = [&](double y) { return kBottom - (y - ay.lo) / (ay.hi - ay.lo) * (kBottom - kTop); };

  std::string svg = fmt::format(
      "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\" role=\"img\" aria-label=\"{2}\"><title>{2}</title>\n",
      kW, kH, HtmlEscape(caption));
  for (double t : ax.ticks) {
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#ddd\"/>"
        "<text x=\"{0:.1f}\" y=\"{3}\" text-anchor=\"middle\">{4:.4g}</text>\n",
        px(t), kTop, kBottom, kBottom + 15, t);
  }
  for (double t : ay.ticks) {
    const std::string label =
        log_y ? fmt::format("{:.4g}", std::pow(10.0, t)) : fmt::format("{:.4g}", t);
    svg += fmt::format(
        "<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#ddd\"/>"
        "<text x=\"{3}\" y=\"{4:.1f}\" text-anchor=\"end\">{5}</text>\n",
        kLeft, py(t), kRight, kLeft - 5, py(t) + 4, label);
  }
  svg += fmt::format(
      "<rect x=\"{0}\" y=\"{1}\" width=\"{2}\" height=\"{3}\" fill=\"none\" stroke=\"#333\"/>\n"
      "<text x=\"{4}\" y=\"{5}\" text-anchor=\"middle\">{6}</text>\n"
      "<text x=\"15\" y=\"{7}\" text-anchor=\"middle\" transform=\"rotate(-90 15 {7})\">{8}"
      "</text>\n",
      kLeft, kTop, kRight - kLeft, kBottom - kTop, (kLeft + kRight) / 2, kBottom + 35,
      HtmlEscape(x_label), (kTop + kBottom) / 2, HtmlEscape(y_label) + (log_y ? " (log)" : ""));
  for (size_t s = 0; s < series.size(); ++s) {
    const char* colour = kSeriesColours[s % std::size(kSeriesColours)];
    std::string coords;
    for (const auto& [x, y] : points[s]) {
      coords += fmt::format("{}{:.1f},{:.1f}", coords.empty() ? "" : " ", px(x), py(y));
    }
    svg +=
        fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" points=\"{}\"/>\n",
                    colour, coords);
    if (points[s].size() <= 30) {  // markers make short series (and single points) visible
      for (const auto& [x, y] : points[s]) {
        svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"{}\"/>", px(x),
                           py(y), colour);
      }
    }
    const double ly = kTop + 10 + 18 * double(s);
    svg += fmt::format(
        "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{3}\" stroke-width=\"3\"/>"
        "<text x=\"{4}\" y=\"{5}\">{6}</text>\n",
        kRight + 12, ly, kRight + 32, colour, kRight + 38, ly + 4,
        HtmlEscape(series[s].name) + (points[s].empty() ? " (no points)" : ""));
  }
  body_ += svg + "</svg><figcaption>" + HtmlEscape(caption) + "</figcaption></figure>\n";
}

void HtmlReport::RawHtml(const std::string& html) { body_ += html; }

std::string HtmlReport::Html() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         HtmlEscape(title_) + "</title>\n<style>" + std::string(kCss) + "</style>\n</head>\n" +
         "<body>\n<h1>" + HtmlEscape(title_) + "</h1>\n" + body_ + "</body>\n</html>\n";
}

void HtmlReport::Write(const std::filesystem::path& path) const { WriteFileAtomic(path, Html()); }

}  // namespace igi
