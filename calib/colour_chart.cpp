#include "calib/colour_chart.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>
#include <opencv2/mcc/ccm.hpp>

#include "tools/common/enum_names.h"
#include "tools/common/error.h"
#include "tools/common/json.h"
#include "tools/common/strings.h"

namespace igi::calib {
namespace {

constexpr int kPatches = 24;
constexpr int kColumns = 6;
// The neutral patches (white … black) in chart order.
constexpr int kFirstNeutral = 18;

// Linear sRGB (D65) → XYZ, IEC 61966-2-1 primaries with the D65 white of WhiteD65().
Eigen::Matrix3d SrgbToXyz() {
  Eigen::Matrix3d m;
  m << 0.4124564, 0.3575761, 0.1804375, 0.2126729, 0.7151522, 0.0721750, 0.0193339, 0.1191920,
      0.9503041;
  return m;
}

double LabF(double t) {
  constexpr double kDelta = 6.0 / 29.0;
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0 / 29.0;
}

double LabFInverse(double t) {
  constexpr double kDelta = 6.0 / 29.0;
  return t > kDelta ? t * t * t : 3 * kDelta * kDelta * (t - 4.0 / 29.0);
}

double Degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
double Radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Luminance Y of a linear sRGB colour.
double Luminance(const Eigen::Vector3d& rgb) { return SrgbToXyz().row(1).dot(rgb); }

}  // namespace

// ---- Colour science ----------------------------------------------------------------------

Eigen::Vector3d WhiteD50() { return {0.96422, 1.0, 0.82521}; }
Eigen::Vector3d WhiteD65() { return {0.95047, 1.0, 1.08883}; }

Eigen::Vector3d XyzFromLinearSrgb(const Eigen::Vector3d& rgb) { return SrgbToXyz() * rgb; }
Eigen::Vector3d LinearSrgbFromXyz(const Eigen::Vector3d& xyz) {
  return SrgbToXyz().inverse() * xyz;
}

Eigen::Vector3d LabFromXyz(const Eigen::Vector3d& xyz, const Eigen::Vector3d& white) {
  const double fx = LabF(xyz.x() / white.x());
  const double fy = LabF(xyz.y() / white.y());
  const double fz = LabF(xyz.z() / white.z());
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

Eigen::Vector3d XyzFromLab(const Eigen::Vector3d& lab, const Eigen::Vector3d& white) {
  const double fy = (lab.x() + 16) / 116;
  const double fx = fy + lab.y() / 500;
  const double fz = fy - lab.z() / 200;
  return {white.x() * LabFInverse(fx), white.y() * LabFInverse(fy), white.z() * LabFInverse(fz)};
}

Eigen::Matrix3d BradfordAdaptation(const Eigen::Vector3d& from_white,
                                   const Eigen::Vector3d& to_white) {
  Eigen::Matrix3d cone;
  cone << 0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296;
  const Eigen::Vector3d from = cone * from_white;
  const Eigen::Vector3d to = cone * to_white;
  return cone.inverse() * to.cwiseQuotient(from).asDiagonal() * cone;
}

Eigen::Vector3d LabD50FromLinearSrgb(const Eigen::Vector3d& rgb) {
  static const Eigen::Matrix3d kToXyzD50 = BradfordAdaptation(WhiteD65(), WhiteD50()) * SrgbToXyz();
  return LabFromXyz(kToXyzD50 * rgb, WhiteD50());
}

Eigen::Vector3d LinearSrgbFromLabD50(const Eigen::Vector3d& lab) {
  static const Eigen::Matrix3d kFromXyzD50 =
      SrgbToXyz().inverse() * BradfordAdaptation(WhiteD50(), WhiteD65());
  return kFromXyzD50 * XyzFromLab(lab, WhiteD50());
}

double DeltaE2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2) {
  const double c1 = std::hypot(lab1.y(), lab1.z());
  const double c2 = std::hypot(lab2.y(), lab2.z());
  const double c_mean7 = std::pow((c1 + c2) / 2, 7);
  const double g = 0.5 * (1 - std::sqrt(c_mean7 / (c_mean7 + std::pow(25.0, 7))));
  const double a1 = (1 + g) * lab1.y();
  const double a2 = (1 + g) * lab2.y();
  const double cp1 = std::hypot(a1, lab1.z());
  const double cp2 = std::hypot(a2, lab2.z());
  // Hue angles in degrees, [0, 360); 0 for an achromatic colour.
  auto hue = [](double a, double b) {
    if (a == 0 && b == 0) return 0.0;
    const double h = Degrees(std::atan2(b, a));
    return h < 0 ? h + 360 : h;
  };
  const double h1 = hue(a1, lab1.z());
  const double h2 = hue(a2, lab2.z());
  const bool achromatic = cp1 * cp2 == 0;
  double dh = 0;
  if (!achromatic) {
    dh = h2 - h1;
    if (dh > 180) dh -= 360;
    if (dh < -180) dh += 360;
  }
  const double d_l = lab2.x() - lab1.x();
  const double d_c = cp2 - cp1;
  const double d_h = 2 * std::sqrt(cp1 * cp2) * std::sin(Radians(dh / 2));
  const double l_mean = (lab1.x() + lab2.x()) / 2;
  const double c_mean = (cp1 + cp2) / 2;
  double h_mean = h1 + h2;
  if (!achromatic) {
    if (std::abs(h1 - h2) <= 180) {
      h_mean = (h1 + h2) / 2;
    } else {
      h_mean = h1 + h2 < 360 ? (h1 + h2 + 360) / 2 : (h1 + h2 - 360) / 2;
    }
  }
  const double t = 1 - 0.17 * std::cos(Radians(h_mean - 30)) +
                   0.24 * std::cos(Radians(2 * h_mean)) + 0.32 * std::cos(Radians(3 * h_mean + 6)) -
                   0.20 * std::cos(Radians(4 * h_mean - 63));
  const double d_theta = 30 * std::exp(-std::pow((h_mean - 275) / 25, 2));
  const double c_mean_7 = std::pow(c_mean, 7);
  const double r_c = 2 * std::sqrt(c_mean_7 / (c_mean_7 + std::pow(25.0, 7)));
  const double l50 = (l_mean - 50) * (l_mean - 50);
  const double s_l = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double s_c = 1 + 0.045 * c_mean;
  const double s_h = 1 + 0.015 * c_mean * t;
  const double r_t = -std::sin(Radians(2 * d_theta)) * r_c;
  const double tl = d_l / s_l;
  const double tc = d_c / s_c;
  const double th = d_h / s_h;
  return std::sqrt(tl * tl + tc * tc + th * th + r_t * tc * th);
}

// ---- Chart reference values ----------------------------------------------------------------

namespace {

// Tokens of one CGATS line: whitespace-separated, "quoted strings" kept whole (quotes removed).
std::vector<std::string> CgatsTokens(const std::string& line) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < line.size()) {
    if (std::isspace(static_cast<unsigned char>(line[i]))) {
      ++i;
    } else if (line[i] == '"') {
      const size_t end = line.find('"', i + 1);
      tokens.push_back(
          line.substr(i + 1, end == std::string::npos ? std::string::npos : end - i - 1));
      i = end == std::string::npos ? line.size() : end + 1;
    } else if (line[i] == '#') {
      break;
    } else {
      size_t end = i;
      while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end]))) ++end;
      tokens.push_back(line.substr(i, end - i));
      i = end;
    }
  }
  return tokens;
}

// The chart-order index of a ColorChecker patch name "A1" … "D6" (or "A01" … "D06"); -1 for
// other names.
int PatchIndex(const std::string& name) {
  if (name.size() < 2) return -1;
  const int row = std::toupper(static_cast<unsigned char>(name[0])) - 'A';
  const auto column = ParseInt(name.substr(1));
  if (row < 0 || row > 3 || !column || *column < 1 || *column > kColumns) return -1;
  return row * kColumns + int(*column) - 1;
}

struct CgatsTable {
  std::vector<std::string> fields;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> row_lines;  // 1-based line of each row
};

CgatsTable ReadCgats(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(DescribeProblem(file, "", "", "cannot read the file"));
  CgatsTable table;
  // The header's keywords, then BEGIN_DATA_FORMAT … END_DATA_FORMAT (the field names), more
  // keywords, then BEGIN_DATA … END_DATA (one set per line).
  enum class Section { kHeader, kFormat, kData, kDone } section = Section::kHeader;
  bool have_format = false;
  std::string line;
  int line_number = 0;
  while (section != Section::kDone && std::getline(in, line)) {
    ++line_number;
    const std::vector<std::string> tokens = CgatsTokens(line);
    if (tokens.empty()) continue;
    const std::string where = fmt::format("line {}", line_number);
    switch (section) {
      case Section::kHeader:
        if (tokens[0] == "BEGIN_DATA_FORMAT") section = Section::kFormat;
        if (tokens[0] == "BEGIN_DATA") {
          if (!have_format) {
            throw InputError(
                DescribeProblem(file, where, "BEGIN_DATA", "comes before BEGIN_DATA_FORMAT"));
          }
          section = Section::kData;
        }
        break;
      case Section::kFormat:
        for (const std::string& t : tokens) {
          if (t == "END_DATA_FORMAT") {
            section = Section::kHeader;
            have_format = !table.fields.empty();
            break;
          }
          table.fields.push_back(t);
        }
        break;
      case Section::kData:
        if (tokens[0] == "END_DATA") {
          section = Section::kDone;
          break;
        }
        if (tokens.size() != table.fields.size()) {
          throw InputError(
              DescribeProblem(file, where, fmt::format("{} values", tokens.size()),
                              fmt::format("the data format has {} fields", table.fields.size())));
        }
        table.rows.push_back(tokens);
        table.row_lines.push_back(line_number);
        break;
      case Section::kDone:
        break;
    }
  }
  if (!have_format) {
    throw InputError(DescribeProblem(file, "", "", "not a CGATS file (no BEGIN_DATA_FORMAT)"));
  }
  if (section != Section::kDone) {
    throw InputError(DescribeProblem(file, "", "", "no complete BEGIN_DATA … END_DATA block"));
  }
  return table;
}

// The column of the first of `names` the table has; -1 when none.
int FieldColumn(const CgatsTable& table, std::initializer_list<std::string_view> names) {
  for (std::string_view name : names) {
    const auto it = std::find(table.fields.begin(), table.fields.end(), name);
    if (it != table.fields.end()) return int(it - table.fields.begin());
  }
  return -1;
}

}  // namespace

ChartReference ReadChartReference(const std::filesystem::path& path) {
  const std::string file = path.string();
  const CgatsTable table = ReadCgats(path);
  const int id = FieldColumn(table, {"SAMPLE_ID", "SAMPLE_LOC", "SAMPLE_NAME"});
  const int lab_l = FieldColumn(table, {"LAB_L"});
  const int xyz_x = FieldColumn(table, {"XYZ_X"});
  const bool use_lab = lab_l >= 0 && FieldColumn(table, {"LAB_A"}) == lab_l + 1 &&
                       FieldColumn(table, {"LAB_B"}) == lab_l + 2;
  const bool use_xyz = xyz_x >= 0 && FieldColumn(table, {"XYZ_Y"}) == xyz_x + 1 &&
                       FieldColumn(table, {"XYZ_Z"}) == xyz_x + 2;
  if (!use_lab && !use_xyz) {
    throw InputError(DescribeProblem(file, "data format", Join(table.fields, " "),
                                     "needs LAB_L LAB_A LAB_B or XYZ_X XYZ_Y XYZ_Z"));
  }
  ChartReference reference;
  reference.file = file;
  reference.names.assign(kPatches, "");
  reference.lab_d50.assign(kPatches, Eigen::Vector3d::Zero());
  std::vector<bool> seen(kPatches, false);
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const auto& row = table.rows[r];
    // Without patch names, a 24-set file is read in chart order.
    int index = id >= 0 ? PatchIndex(row[id]) : (table.rows.size() == kPatches ? int(r) : -1);
    if (index < 0) continue;
    Eigen::Vector3d v;
    const int first = use_lab ? lab_l : xyz_x;
    for (int k = 0; k < 3; ++k) {
      const auto value = ParseDouble(row[first + k]);
      if (!value || !std::isfinite(*value)) {
        throw InputError(DescribeProblem(file, fmt::format("line {}", table.row_lines[r]),
                                         row[first + k], "must be a number"));
      }
      v[k] = *value;
    }
    reference.lab_d50[index] = use_lab ? v : LabFromXyz(v / 100.0, WhiteD50());
    reference.names[index] = id >= 0 ? row[id] : fmt::format("{}", index + 1);
    seen[index] = true;
  }
  std::vector<std::string> missing;
  for (int i = 0; i < kPatches; ++i) {
    if (!seen[i])
      missing.push_back(fmt::format("{}{}", char('A' + i / kColumns), i % kColumns + 1));
  }
  if (!missing.empty()) {
    throw InputError(DescribeProblem(file, "patches", "missing " + Join(missing, " "),
                                     "a ColorChecker reference needs the 24 patches A1 … D6"));
  }
  return reference;
}

// ---- Finding and reading the chart ---------------------------------------------------------

namespace {

// The patch grid in the units of mcc's MCC24 model: patches 2.5 wide on a 2.75 pitch, the grid's
// outer corners at (0.25, 0.25) and (16.5, 11.0); the model's box (the detector's getBox()) is
// (0, 0) … (16.75, 11.25).
constexpr double kPitch = 2.75;
constexpr double kPatchSide = 2.5;
constexpr double kGridMin = 0.25;
const std::array<cv::Point2d, 4> kGridCorners = {cv::Point2d(0.25, 0.25), cv::Point2d(16.5, 0.25),
                                                 cv::Point2d(16.5, 11.0), cv::Point2d(0.25, 11.0)};

cv::Matx33d GridToImage(const ChartLocation& location) {
  std::vector<cv::Point2f> from, to;
  for (int i = 0; i < 4; ++i) {
    from.emplace_back(float(kGridCorners[i].x), float(kGridCorners[i].y));
    to.emplace_back(float(location.corners[i].x()), float(location.corners[i].y()));
  }
  return cv::Matx33d(cv::getPerspectiveTransform(from, to));
}

cv::Point2d Apply(const cv::Matx33d& h, double x, double y) {
  const cv::Vec3d p = h * cv::Vec3d(x, y, 1);
  return {p[0] / p[2], p[1] / p[2]};
}

// An 8-bit BGR picture of a linear image for the detector: grey-world balanced, its 99th
// percentile brightness at white, sRGB-encoded, reduced by `factor`.
cv::Mat DetectorImage(const Image& linear_rgb, int factor) {
  const Image small = BlockMeans(linear_rgb, factor);
  const size_t n = size_t(small.width) * small.height;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) mean[c] += std::max(0.0f, small.pixels[i * 3 + c]);
  }
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3; ++c) gain[c] = mean[c] > 0 ? mean[1] / mean[c] : 1.0;
  std::vector<float> brightness(n);
  for (size_t i = 0; i < n; ++i) {
    float m = 0;
    for (int c = 0; c < 3; ++c) m = std::max(m, float(gain[c]) * small.pixels[i * 3 + c]);
    brightness[i] = m;
  }
  std::nth_element(brightness.begin(), brightness.begin() + n * 99 / 100, brightness.end());
  const double top = brightness[n * 99 / 100];
  const double scale = top > 0 ? 1.0 / top : 1.0;
  cv::Mat bgr(small.height, small.width, CV_8UC3);
  for (int y = 0; y < small.height; ++y) {
    for (int x = 0; x < small.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = std::clamp(gain[c] * scale * small.at(x, y, c), 0.0, 1.0);
        const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
        bgr.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<uint8_t>(encoded * 255 + 0.5);
      }
    }
  }
  return bgr;
}

}  // namespace

std::optional<ChartLocation> FindColourChart(const Image& linear_rgb) {
  if (linear_rgb.channels < 3 || linear_rgb.empty()) return std::nullopt;
  // The detector's cost grows with the pixel count; a chart is found as well at ~2 MP.
  const int factor = std::max(1, ReductionFactor(linear_rgb.width, linear_rgb.height, 2.0));
  const cv::Mat bgr = DetectorImage(linear_rgb, factor);
  cv::Ptr<cv::mcc::CCheckerDetector> detector = cv::mcc::CCheckerDetector::create();
  try {
    if (!detector->process(bgr, cv::mcc::MCC24, 1)) return std::nullopt;
  } catch (const cv::Exception&) {  // e.g. an image below the detector's minimum size
    return std::nullopt;
  }
  const cv::Ptr<cv::mcc::CChecker> checker = detector->getBestColorChecker();
  if (!checker) return std::nullopt;
  const std::vector<cv::Point2f> box = checker->getBox();
  if (box.size() != 4) return std::nullopt;
  const std::vector<cv::Point2f> model = {
      {0.0f, 0.0f}, {16.75f, 0.0f}, {16.75f, 11.25f}, {0.0f, 11.25f}};
  const cv::Matx33d model_to_small(cv::getPerspectiveTransform(model, box));
  ChartLocation location;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d p = Apply(model_to_small, kGridCorners[i].x, kGridCorners[i].y);
    // OpenCV's pixel centres are at integers; igi's at +0.5. Then back to full resolution.
    location.corners[i] = Eigen::Vector2d((p.x + 0.5) * factor, (p.y + 0.5) * factor);
  }
  // mcc also answers to grids of windows or tiles: what it found counts as a chart only when its
  // patches can be read and its grey row darkens from white to black (at least 3×).
  std::vector<Eigen::Vector3d> patches;
  try {
    patches = SamplePatches(linear_rgb, location);
  } catch (const InputError&) {
    return std::nullopt;
  }
  for (int i = kFirstNeutral; i + 1 < kPatches; ++i) {
    if (!(patches[i].sum() > patches[i + 1].sum())) return std::nullopt;
  }
  if (!(patches[kFirstNeutral].sum() > 3 * patches[kPatches - 1].sum())) return std::nullopt;
  return location;
}

void PatchSamplingOptions::Validate() const {
  ProblemList problems;
  if (!(inner_fraction > 0 && inner_fraction <= 1)) {
    problems.Add("", "inner_fraction", fmt::format("{}", inner_fraction), "must be in (0, 1]");
  }
  if (!(trim_fraction >= 0 && trim_fraction < 0.5)) {
    problems.Add("", "trim_fraction", fmt::format("{}", trim_fraction), "must be in [0, 0.5)");
  }
  if (min_pixels < 1) problems.Add("", "min_pixels", std::to_string(min_pixels), "must be >= 1");
  problems.ThrowIfAny();
}

namespace {

// Mean of the values left after dropping `trim` of them at each end.
double TrimmedMean(std::vector<float>& values, double trim) {
  std::sort(values.begin(), values.end());
  const size_t drop = size_t(double(values.size()) * trim);
  double sum = 0;
  for (size_t i = drop; i < values.size() - drop; ++i) sum += values[i];
  return sum / double(values.size() - 2 * drop);
}

}  // namespace

std::vector<Eigen::Vector3d> SamplePatches(const Image& linear_rgb, const ChartLocation& location,
                                           const PatchSamplingOptions& options) {
  options.Validate();
  if (linear_rgb.channels < 3) {
    throw InputError(DescribeProblem("", "image", std::to_string(linear_rgb.channels) + " channels",
                                     "a colour chart needs an RGB image"));
  }
  const cv::Matx33d to_image = GridToImage(location);
  const cv::Matx33d to_grid = to_image.inv();
  const double half = kPatchSide / 2 * options.inner_fraction;
  constexpr int kCornerSigns[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  std::vector<Eigen::Vector3d> means;
  for (int i = 0; i < kPatches; ++i) {
    const double cx = kGridMin + kPitch * (i % kColumns) + kPatchSide / 2;
    const double cy = kGridMin + kPitch * (i / kColumns) + kPatchSide / 2;
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const auto& sign : kCornerSigns) {
      const cv::Point2d p = Apply(to_image, cx + sign[0] * half, cy + sign[1] * half);
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x),
      y1 = std::max(y1, p.y);
    }
    const std::string patch = fmt::format("patch {}", i + 1);
    if (!(x0 >= 0 && y0 >= 0 && x1 <= linear_rgb.width && y1 <= linear_rgb.height)) {
      throw InputError(DescribeProblem("", patch, fmt::format("({:.0f}, {:.0f})", x0, y0),
                                       "the chart's patch lies outside the image"));
    }
    std::array<std::vector<float>, 3> values;
    for (int y = int(y0); y < int(std::ceil(y1)) && y < linear_rgb.height; ++y) {
      for (int x = int(x0); x < int(std::ceil(x1)) && x < linear_rgb.width; ++x) {
        const cv::Point2d g = Apply(to_grid, x + 0.5, y + 0.5);
        if (std::abs(g.x - cx) > half || std::abs(g.y - cy) > half) continue;
        for (int c = 0; c < 3; ++c) values[c].push_back(linear_rgb.at(x, y, c));
      }
    }
    if (int(values[0].size()) < options.min_pixels) {
      throw InputError(DescribeProblem("", patch, fmt::format("{} pixels", values[0].size()),
                                       fmt::format("the chart is too small: a patch's sampled "
                                                   "square needs at least {} pixels",
                                                   options.min_pixels)));
    }
    Eigen::Vector3d mean;
    for (int c = 0; c < 3; ++c) mean[c] = TrimmedMean(values[c], options.trim_fraction);
    means.push_back(mean);
  }
  return means;
}

// ---- Fitting and evaluating ----------------------------------------------------------------

DeltaEStats EvaluateDeltaE(const std::vector<Eigen::Vector3d>& linear_srgb,
                           const ChartReference& reference) {
  DeltaEStats stats;
  for (size_t i = 0; i < linear_srgb.size() && i < reference.lab_d50.size(); ++i) {
    const double d = DeltaE2000(LabD50FromLinearSrgb(linear_srgb[i]), reference.lab_d50[i]);
    stats.per_patch.push_back(d);
    stats.mean += d;
    stats.max = std::max(stats.max, d);
  }
  if (!stats.per_patch.empty()) stats.mean /= double(stats.per_patch.size());
  return stats;
}

double BestExposureScale(const std::vector<Eigen::Vector3d>& linear_srgb,
                         const ChartReference& reference) {
  // Start from the least-squares luminance scale on the neutral patches.
  double num = 0, den = 0;
  for (int i = kFirstNeutral; i < kPatches && i < int(linear_srgb.size()); ++i) {
    const double y = Luminance(linear_srgb[i]);
    num += y * XyzFromLab(reference.lab_d50[i], WhiteD50()).y();
    den += y * y;
  }
  const double start = den > 0 && num > 0 ? num / den : 1.0;
  auto cost = [&](double log_s) {
    std::vector<Eigen::Vector3d> scaled = linear_srgb;
    for (auto& v : scaled) v *= std::exp(log_s);
    return EvaluateDeltaE(scaled, reference).mean;
  };
  const double phi = (std::sqrt(5.0) - 1) / 2;
  double a = std::log(start) - 1, b = std::log(start) + 1;
  double c = b - phi * (b - a), d = a + phi * (b - a);
  double fc = cost(c), fd = cost(d);
  for (int it = 0; it < 60; ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - phi * (b - a), fc = cost(c);
    } else {
      a = c, c = d, fc = fd, d = a + phi * (b - a), fd = cost(d);
    }
  }
  return std::exp((a + b) / 2);
}

std::vector<Eigen::Vector3d> GreyBalancedDecoderColour(
    const std::vector<Eigen::Vector3d>& camera_rgb,
    const std::vector<Eigen::Vector3d>& decoder_srgb) {
  if (camera_rgb.size() != kPatches || decoder_srgb.size() != kPatches) {
    throw InputError(DescribeProblem("", "patches", std::to_string(camera_rgb.size()),
                                     "a ColorChecker needs 24 patches"));
  }
  // decoder_srgb_i = R camera_rgb_i: R = (Σ s cᵀ)(Σ c cᵀ)⁻¹, leaving out patches the decoder
  // clipped at zero (out of its gamut: a channel under 2 % of the brightest value).
  double brightest = 0;
  for (const auto& v : decoder_srgb) brightest = std::max(brightest, v.maxCoeff());
  Eigen::Matrix3d sc = Eigen::Matrix3d::Zero(), cc = Eigen::Matrix3d::Zero();
  Eigen::Vector3d grey = Eigen::Vector3d::Zero();
  for (int i = 0; i < kPatches; ++i) {
    if (decoder_srgb[i].minCoeff() > 0.02 * brightest) {
      sc += decoder_srgb[i] * camera_rgb[i].transpose();
      cc += camera_rgb[i] * camera_rgb[i].transpose();
    }
    if (i > kFirstNeutral && i < kPatches - 1) grey += camera_rgb[i];  // D2 … D5
  }
  // The fitted matrix is the decoder's rgb_cam times its channel scaling; rgb_cam maps equal
  // camera channels to sRGB white (dcraw's normalisation, rows summing to 1), which fixes it.
  const Eigen::Matrix3d fitted = sc * cc.inverse();
  const Eigen::Matrix3d decoder =
      fitted * (fitted.inverse() * Eigen::Vector3d::Ones()).asDiagonal();
  const Eigen::Vector3d gain(grey.y() / grey.x(), 1.0, grey.y() / grey.z());
  std::vector<Eigen::Vector3d> out;
  for (const auto& c : camera_rgb) out.push_back(decoder * gain.cwiseProduct(c));
  return out;
}

void ColourFitOptions::Validate() const {
  ProblemList problems;
  if (!(saturated_fraction > 0 && saturated_fraction <= 1)) {
    problems.Add("", "saturated_fraction", fmt::format("{}", saturated_fraction),
                 "must be in (0, 1]");
  }
  if (!(clip_level >= 0 && std::isfinite(clip_level))) {
    problems.Add("", "clip_level", fmt::format("{}", clip_level), "must be >= 0");
  }
  if (max_iterations < 1) {
    problems.Add("", "max_iterations", std::to_string(max_iterations), "must be >= 1");
  }
  problems.ThrowIfAny();
}

ColourFit FitColourMatrix(const std::vector<Eigen::Vector3d>& camera_rgb,
                          const ChartReference& reference, const ColourFitOptions& options) {
  options.Validate();
  if (camera_rgb.size() != kPatches || reference.lab_d50.size() != kPatches) {
    throw InputError(DescribeProblem("", "patches", std::to_string(camera_rgb.size()),
                                     "a ColorChecker fit needs 24 patches"));
  }
  // ccm takes camera values in [0, 1] and leaves out those outside its saturation interval:
  // scale by the clip level when it is known, else by the largest value (nothing left out).
  double largest = 0;
  for (const auto& v : camera_rgb) largest = std::max(largest, v.maxCoeff());
  const bool clip_known = options.clip_level > 0;
  const double norm = clip_known ? options.clip_level : largest;
  const double upper = clip_known ? options.saturated_fraction : 1.0;
  cv::Mat src(kPatches, 1, CV_64FC3), ref(kPatches, 1, CV_64FC3);
  int usable = 0;
  for (int i = 0; i < kPatches; ++i) {
    const Eigen::Vector3d v = camera_rgb[i] / norm;
    src.at<cv::Vec3d>(i) = cv::Vec3d(v.x(), v.y(), v.z());
    const Eigen::Vector3d& lab = reference.lab_d50[i];
    ref.at<cv::Vec3d>(i) = cv::Vec3d(lab.x(), lab.y(), lab.z());
    if (v.minCoeff() >= 0 && v.maxCoeff() <= upper) ++usable;
  }
  if (!(norm > 0) || usable < 9) {
    throw InputError(
        DescribeProblem("", "patches", fmt::format("{} usable", usable),
                        "the fit needs at least 9 patches that are neither clipped nor negative"));
  }
  cv::ccm::ColorCorrectionModel model(src, ref, cv::ccm::COLOR_SPACE_Lab_D50_2);
  model.setColorSpace(cv::ccm::COLOR_SPACE_sRGB);
  model.setCCM_TYPE(cv::ccm::CCM_3x3);
  model.setDistance(cv::ccm::DISTANCE_CIE2000);
  model.setLinear(cv::ccm::LINEARIZATION_IDENTITY);
  model.setInitialMethod(cv::ccm::INITIAL_METHOD_LEAST_SQUARE);
  model.setSaturatedThreshold(0, upper);
  model.setMaxCount(options.max_iterations);
  model.run();
  // ccm multiplies row vectors (rgb_out = rgb_in * ccm); igi's matrix multiplies columns.
  const cv::Mat ccm = model.getCCM();
  ColourFit fit;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) fit.matrix_absolute(r, c) = ccm.at<double>(c, r) / norm;
  }
  fit.patches_used = usable;
  fit.rms_loss = model.getLoss();
  std::vector<Eigen::Vector3d> corrected;
  for (const auto& v : camera_rgb) corrected.push_back(fit.matrix_absolute * v);
  fit.delta_e2000 = EvaluateDeltaE(corrected, reference);
  // exposure_scale: corrected luminance = camera green on the neutral patches (least squares).
  double num = 0, den = 0;
  for (int i = kFirstNeutral; i < kPatches; ++i) {
    num += Luminance(corrected[i]) * camera_rgb[i].y();
    den += camera_rgb[i].y() * camera_rgb[i].y();
  }
  fit.exposure_scale = den > 0 && num > 0 ? num / den : 1.0;
  fit.matrix = fit.matrix_absolute / fit.exposure_scale;
  return fit;
}

void ApplyColourMatrix(float* rgb, size_t pixels, const Eigen::Matrix3d& matrix) {
  const Eigen::Matrix3f m = matrix.cast<float>();
  for (size_t i = 0; i < pixels; ++i) {
    float* p = rgb + i * 3;
    const Eigen::Vector3f out = m * Eigen::Vector3f(p[0], p[1], p[2]);
    p[0] = out.x(), p[1] = out.y(), p[2] = out.z();
  }
}

// ---- colour.json ---------------------------------------------------------------------------

constexpr EnumNames<ColourInput, 2> kColourInputNames{
    {{ColourInput::kCameraRaw, "camera_raw"}, {ColourInput::kLinear, "linear"}}};

std::string_view ColourInputName(ColourInput input) { return kColourInputNames.Name(input); }
std::optional<ColourInput> ColourInputFromName(std::string_view name) {
  return kColourInputNames.FromName(name);
}

namespace {

Json DeltaEJson(const DeltaEStats& stats) {
  return {{"mean", stats.mean}, {"max", stats.max}, {"per_patch", stats.per_patch}};
}

std::optional<DeltaEStats> ReadDeltaE(const JsonCursor& cursor) {
  if (!cursor.ExpectObject({"mean", "max", "per_patch"})) return std::nullopt;
  DeltaEStats stats;
  stats.mean = cursor["mean"].Number(NumberRule::NonNegative()).value_or(0);
  stats.max = cursor["max"].Number(NumberRule::NonNegative()).value_or(0);
  stats.per_patch = cursor["per_patch"]
                        .Numbers(kPatches, NumberRule::NonNegative())
                        .value_or(std::vector<double>{});
  return stats;
}

}  // namespace

void WriteColourFile(const std::filesystem::path& path, const ColourFile& colour) {
  if (!colour.matrix.allFinite()) {
    throw InputError(DescribeProblem(path.string(), "matrix", "", "must be finite"));
  }
  if (!(colour.exposure_scale > 0 && std::isfinite(colour.exposure_scale))) {
    throw InputError(DescribeProblem(path.string(), "exposure_scale",
                                     fmt::format("{}", colour.exposure_scale), "must be > 0"));
  }
  // What the reader requires: one ΔE per patch of the chart.
  if (colour.delta_e2000.per_patch.size() != 24) {
    throw InputError(DescribeProblem(path.string(), "delta_e2000.per_patch",
                                     fmt::format("{} values", colour.delta_e2000.per_patch.size()),
                                     "must be 24, one per patch"));
  }
  Json json;
  json["format"] = "igi-colour";
  json["version"] = 1;
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) {
    rows.push_back({colour.matrix(r, 0), colour.matrix(r, 1), colour.matrix(r, 2)});
  }
  json["matrix"] = rows;
  json["target"] = "linear_srgb";
  json["input"] = std::string(ColourInputName(colour.input));
  json["chart"] = colour.chart;
  json["image"] = colour.image;
  json["exposure_scale"] = colour.exposure_scale;
  json["delta_e2000"] = DeltaEJson(colour.delta_e2000);
  if (colour.camera_matrix_delta_e2000) {
    json["camera_matrix_delta_e2000"] = DeltaEJson(*colour.camera_matrix_delta_e2000);
  }
  if (colour.as_shot_delta_e2000) {
    json["as_shot_delta_e2000"] = DeltaEJson(*colour.as_shot_delta_e2000);
  }
  WriteJsonFile(path, json, 1);
}

ColourFile ReadColourFile(const std::filesystem::path& path) {
  const std::string file = path.string();
  const Json json = ReadJsonFile(path);
  ProblemList problems;
  const JsonCursor root = JsonCursor::Root(json, file, &problems);
  ColourFile colour;
  if (!root.ExpectObject({"format", "version", "matrix", "target", "input", "chart", "image",
                          "exposure_scale", "delta_e2000", "camera_matrix_delta_e2000",
                          "as_shot_delta_e2000"})) {
    problems.ThrowIfAny();
  }
  (void)root["format"].Enum({"igi-colour"});
  if (root["version"].present()) root["version"].Integer(NumberRule::Between(1, 1));
  if (root["matrix"].ArraySize() == 3) {
    for (size_t r = 0; r < 3; ++r) {
      if (auto row = root["matrix"][r].Numbers(3)) {
        for (int c = 0; c < 3; ++c) colour.matrix(int(r), c) = (*row)[c];
      }
    }
  } else if (root["matrix"].IsArray()) {
    root["matrix"].Problem("must be 3 rows of 3 numbers");
  }
  (void)root["target"].Enum({"linear_srgb"});
  if (auto input = root["input"].Enum({"camera_raw", "linear"})) {
    colour.input = ColourInputFromName(*input).value();
  }
  if (root["chart"].present()) colour.chart = root["chart"].String().value_or("");
  if (root["image"].present()) colour.image = root["image"].String().value_or("");
  if (root["exposure_scale"].present()) {
    colour.exposure_scale = root["exposure_scale"].Number(NumberRule::Positive()).value_or(1);
  }
  if (auto stats = ReadDeltaE(root["delta_e2000"])) colour.delta_e2000 = *stats;
  if (root["camera_matrix_delta_e2000"].present()) {
    colour.camera_matrix_delta_e2000 = ReadDeltaE(root["camera_matrix_delta_e2000"]);
  }
  if (root["as_shot_delta_e2000"].present()) {
    colour.as_shot_delta_e2000 = ReadDeltaE(root["as_shot_delta_e2000"]);
  }
  problems.ThrowIfAny();
  return colour;
}

}  // namespace igi::calib
