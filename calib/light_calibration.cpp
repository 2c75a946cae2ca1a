#include "calib/light_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

constexpr double kPi = std::numbers::pi;

std::string Num(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

double Luminance(const Image& image, int x, int y) {
  const int n = std::min(image.channels, 3);
  double sum = 0;
  for (int c = 0; c < n; ++c) sum += image.at(x, y, c);
  return sum / n;
}

bool Clipped(const Image& image, int x, int y, double saturated) {
  for (int c = 0; c < std::min(image.channels, 3); ++c) {
    if (image.at(x, y, c) >= saturated) return true;
  }
  return false;
}

// The q-quantile (0..1) of `values` (reordered).
double Quantile(std::vector<double>& values, double q) {
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

std::string CircleText(const ImageCircle& c) {
  return "centre (" + Num(c.center_px.x(), 5) + ", " + Num(c.center_px.y(), 5) + ") px, radius " +
         Num(c.radius_px, 4) + " px";
}

// One pixel of the searched disc.
struct DiscPixel {
  int x = 0, y = 0;
  double luminance = 0;
  bool clipped = false;
};

// The pixels of the disc, inside the image and the mask.
std::vector<DiscPixel> DiscPixels(const Image& image, const Image* mask, const Eigen::Vector2d& c,
                                  double r, double saturated) {
  std::vector<DiscPixel> pixels;
  // The disc's bounding box within the image, clamped as doubles (a far circle overflows int).
  const double fx0 = std::max(0.0, std::floor(c.x() - r));
  const double fx1 = std::min(double(image.width - 1), std::ceil(c.x() + r));
  const double fy0 = std::max(0.0, std::floor(c.y() - r));
  const double fy1 = std::min(double(image.height - 1), std::ceil(c.y() + r));
  if (!(fx0 <= fx1 && fy0 <= fy1)) return pixels;
  const int x0 = int(fx0), x1 = int(fx1), y0 = int(fy0), y1 = int(fy1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      if ((Eigen::Vector2d(x + 0.5, y + 0.5) - c).norm() > r) continue;
      if (mask != nullptr && mask->at(x, y, 0) <= 0) continue;
      pixels.push_back({x, y, Luminance(image, x, y), Clipped(image, x, y, saturated)});
    }
  }
  return pixels;
}

// The brightest connected set (8-neighbours) of the disc's pixels at or above `threshold`,
// weighted by their brightness above it (a clipped pixel by the peak's); its centroid.
Highlight BrightestBlob(const std::vector<DiscPixel>& pixels, double threshold, double peak) {
  int x0 = pixels[0].x, x1 = x0, y0 = pixels[0].y, y1 = y0;
  for (const DiscPixel& p : pixels) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  std::vector<int> grid(size_t(w) * h, -1);  // index into `pixels` of the bright pixels
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (pixels[i].luminance >= threshold || pixels[i].clipped) {
      grid[size_t(pixels[i].y - y0) * w + (pixels[i].x - x0)] = int(i);
    }
  }
  auto weight = [&](const DiscPixel& p) {
    return p.clipped ? peak - threshold : std::max(0.0, p.luminance - threshold);
  };
  Highlight best;
  double best_weight = -1;
  std::vector<char> seen(grid.size(), 0);
  std::vector<int> stack;
  for (size_t start = 0; start < grid.size(); ++start) {
    if (grid[start] < 0 || seen[start]) continue;
    Highlight blob;
    double sum = 0;
    Eigen::Vector2d moment = Eigen::Vector2d::Zero();
    stack.assign(1, int(start));
    seen[start] = 1;
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      const DiscPixel& p = pixels[size_t(grid[size_t(cell)])];
      const double wgt = weight(p);
      sum += wgt;
      moment += wgt * Eigen::Vector2d(p.x + 0.5, p.y + 0.5);
      ++blob.pixels;
      blob.saturated_pixels += p.clipped ? 1 : 0;
      const int cx = cell % w, cy = cell / w;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = cx + dx, ny = cy + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const size_t n = size_t(ny) * w + nx;
          if (grid[n] < 0 || seen[n]) continue;
          seen[n] = 1;
          stack.push_back(int(n));
        }
      }
    }
    if (sum > best_weight) {
      best_weight = sum;
      blob.pixel = sum > 0 ? Eigen::Vector2d(moment / sum)
                           : Eigen::Vector2d(pixels[size_t(grid[start])].x + 0.5,
                                             pixels[size_t(grid[start])].y + 0.5);
      best = blob;
    }
  }
  return best;
}

void Require(bool ok, const char* key, double value, const std::string& rule) {
  if (!ok) throw InputError(DescribeProblem("", key, Num(value), rule));
}

// Two unit vectors perpendicular to the unit `axis` and to each other.
std::pair<Eigen::Vector3d, Eigen::Vector3d> Perpendiculars(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d ref =
      std::abs(axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d a = (ref - axis * axis.dot(ref)).normalized();
  return {a, axis.cross(a)};
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / kPi;
}

Json Vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// The per-channel median of `estimates` and the spread of their luminance.
EmissionEstimate Summarise(std::vector<Eigen::Vector3d> estimates) {
  EmissionEstimate e;
  e.samples = int(estimates.size());
  std::vector<double> channel(estimates.size());
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < estimates.size(); ++i) channel[i] = estimates[i][c];
    e.value[c] = Quantile(channel, 0.5);
  }
  for (size_t i = 0; i < estimates.size(); ++i) channel[i] = estimates[i].mean();
  const double median = Quantile(channel, 0.5);
  const double lo = Quantile(channel, 0.1), hi = Quantile(channel, 0.9);
  e.spread = median > 0 ? (hi - lo) / median : 0;
  return e;
}

}  // namespace

std::optional<ImageCircle> CircleFromMask(const Image& mask) {
  double n = 0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      if (mask.at(x, y, 0) <= 0) continue;
      n += 1;
      sum += Eigen::Vector2d(x + 0.5, y + 0.5);
    }
  }
  if (n == 0) return std::nullopt;
  return ImageCircle{sum / n, std::sqrt(n / kPi)};
}

void HighlightOptions::Validate() const {
  Require(level > 0 && level < 1, "level", level, "must be in (0, 1)");
  Require(saturated > 0, "saturated", saturated, "must be > 0");
  Require(min_contrast > 1, "min_contrast", min_contrast, "must be > 1");
  Require(search_radius > 0 && search_radius <= 1, "search_radius", search_radius,
          "must be in (0, 1]");
  Require(min_inside > 0 && min_inside <= 1, "min_inside", min_inside, "must be in (0, 1]");
}

Highlight FindSphereHighlight(const Image& image, const ImageCircle& circle, const Image* mask,
                              const HighlightOptions& options, const std::string& source) {
  options.Validate();
  const double r = options.search_radius * circle.radius_px;
  std::vector<DiscPixel> pixels;
  if (std::isfinite(r) && r > 0 && std::isfinite(circle.center_px.norm())) {
    pixels = DiscPixels(image, mask, circle.center_px, r, options.saturated);
  }
  const double disc = kPi * r * r;
  if (pixels.empty() || double(pixels.size()) < options.min_inside * disc || r < 2) {
    throw InputError(DescribeProblem(
        source, "", CircleText(circle),
        "the sphere's outline lies mostly outside the " + std::to_string(image.width) + "x" +
            std::to_string(image.height) + " image" + (mask ? " or its mask" : "") +
            " (or is under 2 px): the sphere is not in this photo"));
  }
  std::vector<double> lum(pixels.size());
  double peak = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    lum[i] = pixels[i].luminance;
    peak = std::max(peak, lum[i]);
  }
  const double median = Quantile(lum, 0.5);
  if (!(peak > 0) || !(peak >= options.min_contrast * median)) {
    throw InputError(DescribeProblem(
        source, "", "peak " + Num(peak, 4) + ", median " + Num(median, 4),
        "no highlight on the sphere (" + CircleText(circle) + "): its brightest pixel must be " +
            Num(options.min_contrast, 3) + "x its median luminance"));
  }
  const double threshold = median + options.level * (peak - median);
  Highlight h = BrightestBlob(pixels, threshold, peak);
  h.peak = peak;
  h.median = median;
  return h;
}

std::optional<Sphere> FitSphere(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= double(points.size());
  // |q|² = 2c·q + k with q = p − mean (centred for conditioning), k = r² − |c|².
  Eigen::MatrixXd a(points.size(), 4);
  Eigen::VectorXd b(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d q = points[i] - mean;
    a.row(Eigen::Index(i)) << 2 * q.x(), 2 * q.y(), 2 * q.z(), 1;
    b[Eigen::Index(i)] = q.squaredNorm();
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-9);
  if (qr.rank() < 4) return std::nullopt;
  const Eigen::Vector4d x = qr.solve(b);
  const double r2 = x[3] + x.head<3>().squaredNorm();
  if (!(r2 > 0)) return std::nullopt;
  Sphere s;
  s.center = mean + x.head<3>();
  s.radius = std::sqrt(r2);
  double sum2 = 0;
  for (const Eigen::Vector3d& p : points) sum2 += std::pow((p - s.center).norm() - s.radius, 2);
  s.fit_rms = std::sqrt(sum2 / double(points.size()));
  return s;
}

std::optional<ImageCircle> ProjectSphere(const Sphere& sphere, const SphereView& view) {
  const Eigen::Vector3d to_center = sphere.center - view.eye;
  const double d = to_center.norm();
  if (!(d > sphere.radius)) return std::nullopt;
  const Eigen::Vector3d u = to_center / d;
  // The rim: the circle of points whose tangent rays pass through the eye.
  const Eigen::Vector3d rim_center = sphere.center - u * (sphere.radius * sphere.radius / d);
  const double rim_radius = sphere.radius * std::sqrt(1 - std::pow(sphere.radius / d, 2));
  const auto [a, b] = Perpendiculars(u);
  constexpr int kRimPoints = 64;
  std::vector<Eigen::Vector2d> px;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i = 0; i < kRimPoints; ++i) {
    const double phi = 2 * kPi * i / kRimPoints;
    const auto p = view.project(rim_center + rim_radius * (std::cos(phi) * a + std::sin(phi) * b));
    if (!p) return std::nullopt;
    px.push_back(*p);
    mean += *p;
  }
  mean /= kRimPoints;
  double radius = 0;
  for (const Eigen::Vector2d& p : px) radius = std::max(radius, (p - mean).norm());
  return ImageCircle{mean, radius};
}

Eigen::Vector3d MirrorDirection(const Eigen::Vector3d& normal, const Eigen::Vector3d& to_viewer) {
  return (2 * normal.dot(to_viewer) * normal - to_viewer).normalized();
}

LightRay MeasureLightRay(const Image& image, const Image* mask, const Sphere& sphere,
                         const SphereView& view, const HighlightOptions& options,
                         const std::string& source) {
  const std::optional<ImageCircle> circle = ProjectSphere(sphere, view);
  if (!circle) {
    throw InputError(DescribeProblem(source, "", sphere.name,
                                     "the sphere is behind the camera or holds it: the sphere is "
                                     "not in this photo"));
  }
  LightRay ray;
  ray.photo = source;
  ray.sphere = sphere.name;
  ray.highlight = FindSphereHighlight(image, *circle, mask, options, source);
  const Eigen::Vector3d d = view.world_ray(ray.highlight.pixel).normalized();
  const Eigen::Vector3d oc = view.eye - sphere.center;
  const double b = oc.dot(d);
  const double disc = b * b - (oc.squaredNorm() - sphere.radius * sphere.radius);
  if (disc >= 0) {
    ray.surface = view.eye + (-b - std::sqrt(disc)) * d;
  } else {  // past the rim: its nearest point, the ray's closest approach put on the sphere
    const Eigen::Vector3d closest = view.eye - b * d;
    const double miss_m = (closest - sphere.center).norm() - sphere.radius;
    ray.surface = sphere.center + sphere.radius * (closest - sphere.center).normalized();
    ray.miss_px = miss_m * circle->radius_px / sphere.radius;
  }
  ray.normal = (ray.surface - sphere.center).normalized();
  ray.to_light = MirrorDirection(ray.normal, (view.eye - ray.surface).normalized());
  return ray;
}

DirectionEstimate AverageDirection(const std::vector<LightRay>& rays) {
  DirectionEstimate e;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const LightRay& r : rays) sum += r.to_light;
  if (sum.norm() > 0) e.to_light = sum.normalized();
  for (const LightRay& r : rays)
    e.spread_deg = std::max(e.spread_deg, AngleDeg(r.to_light, e.to_light));
  return e;
}

PositionEstimate TriangulateRays(const std::vector<LightRay>& rays, const std::string& light,
                                 double min_ray_angle_deg) {
  if (rays.size() < 2) {
    throw InputError(DescribeProblem("", "lights." + light, std::to_string(rays.size()) + " ray",
                                     "a position needs the highlights of two or more views or "
                                     "spheres (or calibrate it as directional)"));
  }
  PositionEstimate e;
  for (size_t i = 0; i < rays.size(); ++i) {
    for (size_t j = i + 1; j < rays.size(); ++j) {
      e.ray_angle_deg = std::max(e.ray_angle_deg, AngleDeg(rays[i].to_light, rays[j].to_light));
    }
  }
  if (!(e.ray_angle_deg >= min_ray_angle_deg)) {
    throw InputError(DescribeProblem(
        "", "lights." + light, "rays " + Num(e.ray_angle_deg, 3) + " deg apart",
        "the highlights' rays must be at least " + Num(min_ray_angle_deg, 3) +
            " deg apart to triangulate (the light is too far for the spheres' baseline: "
            "calibrate it as directional, or use spheres further apart)"));
  }
  // Normal equations of Σ |(I − d dᵀ)(x − o)|²: Σ(I − d dᵀ) x = Σ(I − d dᵀ) o.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const LightRay& r : rays) {
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - r.to_light * r.to_light.transpose();
    a += p;
    b += p * r.surface;
  }
  e.position = a.ldlt().solve(b);
  double sum2 = 0;
  for (const LightRay& r : rays) {
    const Eigen::Vector3d off = e.position - r.surface;
    if (off.dot(r.to_light) <= 0) {
      throw InputError(DescribeProblem("", "lights." + light, r.photo,
                                       "the highlights' rays meet behind the sphere of this "
                                       "photo: a highlight was mistaken"));
    }
    const double dist = (off - r.to_light * off.dot(r.to_light)).norm();
    sum2 += dist * dist;
    e.max_distance = std::max(e.max_distance, dist);
  }
  e.rms_distance = std::sqrt(sum2 / double(rays.size()));
  return e;
}

EmissionEstimate PointIntensityFromTarget(const std::vector<TargetSample>& samples,
                                          const Eigen::Vector3d& position,
                                          const Eigen::Vector3d& rho, const std::string& light,
                                          double min_cos) {
  std::vector<Eigen::Vector3d> estimates;
  for (const TargetSample& s : samples) {
    const Eigen::Vector3d w = position - s.position;
    const double d = w.norm();
    const double cos = s.normal.dot(w) / d;
    if (!(cos >= min_cos)) continue;
    estimates.push_back((kPi * d * d / cos) * s.radiance.cwiseQuotient(rho));
  }
  if (estimates.empty()) {
    throw InputError(DescribeProblem("", "lights." + light,
                                     std::to_string(samples.size()) + " target pixels",
                                     "none faces the light at cos >= " + Num(min_cos, 3)));
  }
  return Summarise(std::move(estimates));
}

EmissionEstimate DirectionalIrradianceFromTarget(const std::vector<TargetSample>& samples,
                                                 const Eigen::Vector3d& direction,
                                                 const Eigen::Vector3d& rho,
                                                 const std::string& light, double min_cos) {
  std::vector<Eigen::Vector3d> estimates;
  for (const TargetSample& s : samples) {
    const double cos = -s.normal.dot(direction.normalized());
    if (!(cos >= min_cos)) continue;
    estimates.push_back((kPi / cos) * s.radiance.cwiseQuotient(rho));
  }
  if (estimates.empty()) {
    throw InputError(DescribeProblem("", "lights." + light,
                                     std::to_string(samples.size()) + " target pixels",
                                     "none faces the light at cos >= " + Num(min_cos, 3)));
  }
  return Summarise(std::move(estimates));
}

void WriteLightsFile(const std::filesystem::path& path, const std::vector<Sphere>& spheres,
                     const std::vector<CalibratedLight>& lights) {
  Json doc;
  doc["format"] = "igi-lights";
  doc["version"] = 1;
  doc["lights"] = Json::object();
  doc["calibration"] = Json::object();
  for (const CalibratedLight& l : lights) {
    doc["lights"][l.name] = l.entry;
    Json c;
    c["lighting"] = l.lighting;
    c["method"] = l.position ? "triangulation" : "mirror_direction";
    Json views = Json::array();
    for (const LightRay& r : l.rays) {
      Json v;
      v["photo"] = r.photo;
      v["sphere"] = r.sphere;
      v["highlight_px"] = Json::array({r.highlight.pixel.x(), r.highlight.pixel.y()});
      v["highlight_pixels"] = r.highlight.pixels;
      v["saturated_pixels"] = r.highlight.saturated_pixels;
      v["contrast"] = r.highlight.median > 0 ? r.highlight.peak / r.highlight.median : 0.0;
      v["to_light"] = Vec(r.to_light);
      if (r.miss_px > 0) v["rim_miss_px"] = r.miss_px;
      views.push_back(v);
    }
    c["views"] = views;
    if (l.direction) c["angle_spread_deg"] = l.direction->spread_deg;
    if (l.position) {
      c["ray_rms_distance_m"] = l.position->rms_distance;
      c["ray_max_distance_m"] = l.position->max_distance;
      c["ray_angle_deg"] = l.position->ray_angle_deg;
    }
    if (l.emission) {
      c["emission"] = {
          {"source", "target"}, {"pixels", l.emission->samples}, {"spread", l.emission->spread}};
    } else {
      c["emission"] = {{"source", "scene"}};
    }
    doc["calibration"][l.name] = c;
  }
  Json list = Json::array();
  for (const Sphere& s : spheres) {
    list.push_back({{"name", s.name},
                    {"center", Vec(s.center)},
                    {"radius", s.radius},
                    {"fit_rms_m", s.fit_rms}});
  }
  doc["spheres"] = list;
  WriteJsonFile(path, doc);
}

}  // namespace igi::calib
