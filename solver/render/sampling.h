#pragma once
// Random numbers and sample warps for the forward renderer.
//
// Pcg32 is the PCG32 generator (O'Neill 2014: 64-bit LCG state, XSH-RR output), one independent
// stream per (seed, pixel, sample) through PixelSampleRng, so renders are deterministic whatever
// the thread count. The warps map uniform numbers u in [0,1)^2 to directions or points; each comes
// with its density. Directions are unit vectors; "local" means the frame of a Frame (z = normal);
// densities over directions are per steradian (solid angle), over surfaces per unit area.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace igi::render {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kInvPi = std::numbers::inv_pi;

// ---------------------------------------------------------------------------------------------
// PCG32 random numbers.

class Pcg32 {
 public:
  Pcg32() { Seed(0, 0); }
  Pcg32(uint64_t seed, uint64_t stream) { Seed(seed, stream); }

  // Same initialisation as the reference pcg32_srandom_r(seed, stream); 2^63 distinct streams.
  void Seed(uint64_t seed, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    NextUInt32();
    state_ += seed;
    NextUInt32();
  }

  uint32_t NextUInt32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform integer in [0, bound), bound >= 1, without modulo bias (Lemire's method).
  uint32_t UniformUInt32(uint32_t bound) {
    uint64_t m = uint64_t{NextUInt32()} * bound;
    auto low = static_cast<uint32_t>(m);
    if (low < bound) {
      const uint32_t threshold = (0u - bound) % bound;
      while (low < threshold) {
        m = uint64_t{NextUInt32()} * bound;
        low = static_cast<uint32_t>(m);
      }
    }
    return static_cast<uint32_t>(m >> 32u);
  }

  // Uniform in [0, 1): a multiple of 2^-32, so 1 - u is never 0 (safe under log).
  double UniformDouble() { return NextUInt32() * 0x1p-32; }
  Eigen::Vector2d Uniform2D() {
    const double u0 = UniformDouble();
    return {u0, UniformDouble()};
  }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

// A 64-bit finaliser (SplitMix64's): distinct inputs give decorrelated outputs.
inline uint64_t MixBits(uint64_t v) {
  v ^= v >> 30u;
  v *= 0xbf58476d1ce4e5b9ULL;
  v ^= v >> 27u;
  v *= 0x94d049bb133111ebULL;
  return v ^ (v >> 31u);
}

// Whether item `key` is in a subset that keeps each item with probability `p`, decided by a hash
// of the key alone: reproducible, and even over any pattern in the keys (a regular stride
// through pixel rows aliases with a texture's period; this does not).
inline bool InHashedSubset(uint64_t key, double p) {
  return p >= 1.0 || double(MixBits(key + 0x9e3779b97f4a7c15ULL) >> 11) * 0x1.0p-53 < p;
}

// The generator for one sample of one pixel of a render seeded with `seed`: the same triple
// always gives the same numbers; different triples give independent-looking streams.
inline Pcg32 PixelSampleRng(uint64_t seed, uint64_t pixel_index, uint64_t sample_index) {
  return Pcg32(MixBits(seed ^ MixBits(sample_index + 0x9e3779b97f4a7c15ULL)),
               MixBits(pixel_index ^ MixBits(seed + 0x632be59bd9b4e019ULL)));
}

// ---------------------------------------------------------------------------------------------
// Orthonormal frames.

// A right-handed orthonormal frame (t, b, n) with b = n × t (docs/scene-format.md, "Reflectance
// models"): local coordinates are (x along t, y along b, z along n).
struct Frame {
  Eigen::Vector3d t = Eigen::Vector3d::UnitX();
  Eigen::Vector3d b = Eigen::Vector3d::UnitY();
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();

  // Any frame with normal `n` (unit). Continuous except where n.z changes sign (Duff et al. 2017).
  static Frame FromNormal(const Eigen::Vector3d& n) {
    const double sign = std::copysign(1.0, n.z());
    const double a = -1.0 / (sign + n.z());
    const double bxy = n.x() * n.y() * a;
    Frame frame;
    frame.n = n;
    frame.t = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * bxy, -sign * n.x());
    frame.b = Eigen::Vector3d(bxy, sign + n.y() * n.y() * a, -n.y());  // = n × t
    return frame;
  }
  // The frame with normal `n` (unit) whose t is `tangent` made orthogonal to n and normalised;
  // a tangent (nearly) parallel to n, or zero, falls back to FromNormal(n).
  static Frame FromNormalTangent(const Eigen::Vector3d& n, const Eigen::Vector3d& tangent);

  Eigen::Vector3d ToLocal(const Eigen::Vector3d& v_world) const {
    return {v_world.dot(t), v_world.dot(b), v_world.dot(n)};
  }
  Eigen::Vector3d ToWorld(const Eigen::Vector3d& v_local) const {
    return t * v_local.x() + b * v_local.y() + n * v_local.z();
  }
};

// ---------------------------------------------------------------------------------------------
// Sine and cosine for the warps, without libm's general argument reduction: every angle the
// warps need is a known fraction of a turn, so the reduction to [-π/4, π/4] is exact and a short
// polynomial gives sin and cos to within 2 ulp of the correctly rounded values (about 1e-16).

// sin(a) and cos(a) for |a| <= π/4 (Taylor series to a^15 and a^16: remainder < 5e-17).
inline void SinCosQuarterPi(double a, double* sin_a, double* cos_a) {
  const double a2 = a * a;
  double s = -1.0 / 1307674368000.0;  // -1/15!
  s = s * a2 + 1.0 / 6227020800.0;
  s = s * a2 - 1.0 / 39916800.0;
  s = s * a2 + 1.0 / 362880.0;
  s = s * a2 - 1.0 / 5040.0;
  s = s * a2 + 1.0 / 120.0;
  s = s * a2 - 1.0 / 6.0;
  *sin_a = a + a * a2 * s;
  double c = 1.0 / 20922789888000.0;  // 1/16!
  c = c * a2 - 1.0 / 87178291200.0;
  c = c * a2 + 1.0 / 479001600.0;
  c = c * a2 - 1.0 / 3628800.0;
  c = c * a2 + 1.0 / 40320.0;
  c = c * a2 - 1.0 / 720.0;
  c = c * a2 + 1.0 / 24.0;
  c = c * a2 - 0.5;
  *cos_a = 1.0 + a2 * c;
}

// sin(2πu) and cos(2πu) for u in [0, 1) (other u are wrapped into it). Without branches on u:
// 2πu = θq + a with θq = qπ/2 + π/4 the middle of quadrant q and |a| <= π/4, then the angle
// sum formulas with θq's tabulated sine and cosine (±√2/2).
inline void SinCos2Pi(double u, double* sin_phi, double* cos_phi) {
  if (!(u >= 0.0 && u < 1.0)) u -= std::floor(u);
  const double t = 4.0 * u;                  // quarter turns, in [0, 4]: exact
  const int quadrant = static_cast<int>(t);  // 0..3 (4 only if u rounded up to 1: same as 0)
  double s, c;
  SinCosQuarterPi((t - quadrant - 0.5) * (0.5 * kPi), &s, &c);
  constexpr double h = 0.70710678118654752440;  // √2/2
  static constexpr double kCos[4] = {h, -h, -h, h};
  static constexpr double kSin[4] = {h, h, -h, -h};
  const double cq = kCos[quadrant & 3], sq = kSin[quadrant & 3];
  *sin_phi = s * cq + c * sq;
  *cos_phi = c * cq - s * sq;
}

// ---------------------------------------------------------------------------------------------
// Warps. u is uniform in [0,1)^2.

// Uniform point on the unit disk (Shirley-Chiu concentric map: low distortion).
inline Eigen::Vector2d SampleUniformDiskConcentric(const Eigen::Vector2d& u) {
  const double x = 2.0 * u.x() - 1.0;
  const double y = 2.0 * u.y() - 1.0;
  if (x == 0.0 && y == 0.0) return Eigen::Vector2d::Zero();
  // r = x and φ = a = π/4·(y/x), or r = y and φ = π/2 − a with a = π/4·(x/y), where
  // cos φ = sin a and sin φ = cos a. |a| <= π/4 either way. (Selects, not branches: the
  // choice is a coin toss per sample.)
  const bool x_major = std::abs(x) > std::abs(y);
  const double r = x_major ? x : y;
  double sin_a, cos_a;
  SinCosQuarterPi(0.25 * kPi * ((x_major ? y : x) / r), &sin_a, &cos_a);
  return {r * (x_major ? cos_a : sin_a), r * (x_major ? sin_a : cos_a)};
}

// Local direction with density cosθ/π over the upper hemisphere (z >= 0).
inline Eigen::Vector3d SampleCosineHemisphere(const Eigen::Vector2d& u) {
  const Eigen::Vector2d d = SampleUniformDiskConcentric(u);
  return {d.x(), d.y(), std::sqrt(std::max(0.0, 1.0 - d.squaredNorm()))};
}
inline double CosineHemispherePdf(double cos_theta) {
  return cos_theta > 0.0 ? cos_theta * kInvPi : 0.0;
}

// Local direction with density 1/(2π) over the upper hemisphere.
Eigen::Vector3d SampleUniformHemisphere(const Eigen::Vector2d& u);
inline double UniformHemispherePdf() { return 0.5 * kInvPi; }

// Direction with density 1/(4π) over the sphere.
Eigen::Vector3d SampleUniformSphere(const Eigen::Vector2d& u);
inline double UniformSpherePdf() { return 0.25 * kInvPi; }

// Local direction uniform in the cone around +z of half-angle acos(cos_theta_max), with
// cos_theta_max in [-1, 1). Density UniformConePdf(cos_theta_max) inside the cone, 0 outside.
Eigen::Vector3d SampleUniformCone(const Eigen::Vector2d& u, double cos_theta_max);
inline double UniformConePdf(double cos_theta_max) {
  return 1.0 / (2.0 * kPi * (1.0 - cos_theta_max));
}

// Barycentric weights (w0, w1, w2) of a point uniform over a triangle: point = w0 p0 + w1 p1 +
// w2 p2. Density 1/area over the triangle.
Eigen::Vector3d SampleUniformTriangle(const Eigen::Vector2d& u);

// A direction from `point` toward a sphere (a sphere light), uniform over the cone of directions
// that hit it, as seen from `point`.
struct SphereSample {
  Eigen::Vector3d direction;  // unit, world frame, from `point`
  double distance = 0.0;      // from `point` to the sphere's surface along `direction`
  double pdf = 0.0;           // per steradian
};
// From outside the sphere: uniform in the cone subtended, distance to the near surface. From on
// or inside the sphere: uniform over all directions (pdf 1/(4π)), distance to the far surface.
namespace sampling_internal {
// The case of a point on or inside the sphere (sampling.cpp).
SphereSample SampleSphereFromInside(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                                    double radius, const Eigen::Vector2d& u);
}  // namespace sampling_internal
inline SphereSample SampleSphereFromPoint(const Eigen::Vector3d& point,
                                          const Eigen::Vector3d& center, double radius,
                                          const Eigen::Vector2d& u) {
  const Eigen::Vector3d to_center = center - point;
  const double dist2 = to_center.squaredNorm();
  const double radius2 = radius * radius;
  if (!(dist2 > radius2))
    return sampling_internal::SampleSphereFromInside(point, center, radius, u);
  // Cone of half-angle θmax with sin²θmax = r²/d²; 1 - cosθmax = sin²/(1 + cos) keeps precision
  // for small or distant spheres.
  const double dist = std::sqrt(dist2);
  const double inv_dist = 1.0 / dist;
  const double sin2_max = radius2 / dist2;
  const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
  const double one_minus_cos_max = sin2_max / (1.0 + cos_max);
  // θ from the axis: 1 - cosθ uniform in [0, 1 - cosθmax]; φ uniform.
  const double one_minus_cos = u.x() * one_minus_cos_max;
  const double cos_theta = 1.0 - one_minus_cos;
  const double sin2_theta = one_minus_cos * (2.0 - one_minus_cos);
  const double sin_theta = std::sqrt(std::max(0.0, sin2_theta));
  double sin_phi, cos_phi;
  SinCos2Pi(u.y(), &sin_phi, &cos_phi);
  const Frame frame = Frame::FromNormal(to_center * inv_dist);
  SphereSample sample;
  // Unit: an orthonormal frame and a unit local direction.
  sample.direction =
      frame.t * (sin_theta * cos_phi) + frame.b * (sin_theta * sin_phi) + frame.n * cos_theta;
  // Near intersection: the ray passes the centre at dist·cosθ, at a distance dist·sinθ from it.
  sample.distance =
      std::max(0.0, dist * cos_theta - std::sqrt(std::max(0.0, radius2 - dist2 * sin2_theta)));
  sample.pdf = 1.0 / (2.0 * kPi * one_minus_cos_max);
  return sample;
}
// The density SampleSphereFromPoint gives `direction` (unit): 0 for directions missing the sphere.
double SphereFromPointPdf(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                          double radius, const Eigen::Vector3d& direction);

// ---------------------------------------------------------------------------------------------
// Multiple importance sampling (Veach 1997): the weight of a sample drawn by strategy f (nf
// samples, density f_pdf) against strategy g. An infinite f_pdf (a delta) gets weight 1.
inline double PowerHeuristic(int nf, double f_pdf, int ng, double g_pdf) {
  const double f = nf * f_pdf;
  const double g = ng * g_pdf;
  if (std::isinf(f)) return 1.0;
  if (f <= 0.0) return 0.0;
  const double ratio = g / f;
  return 1.0 / (1.0 + ratio * ratio);
}
inline double BalanceHeuristic(int nf, double f_pdf, int ng, double g_pdf) {
  const double f = nf * f_pdf;
  const double g = ng * g_pdf;
  if (std::isinf(f)) return 1.0;
  if (f <= 0.0) return 0.0;
  return f / (f + g);
}

}  // namespace igi::render
