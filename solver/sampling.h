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
#include <cmath>
#include <cstdint>
#include <numbers>

namespace igi {

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

// The generator for one sample of one pixel of a render seeded with `seed`: the same triple
// always gives the same numbers; different triples give independent-looking streams.
inline Pcg32 PixelSampleRng(uint64_t seed, uint64_t pixel_index, uint64_t sample_index) {
  return Pcg32(MixBits(seed ^ MixBits(sample_index + 0x9e3779b97f4a7c15ULL)),
               MixBits(pixel_index ^ MixBits(seed + 0x632be59bd9b4e019ULL)));
}

// ---------------------------------------------------------------------------------------------
// Orthonormal frames.

// A right-handed orthonormal frame (t, b, n) with b = n × t (CONTRACT.md §2): local coordinates
// are (x along t, y along b, z along n).
struct Frame {
  Eigen::Vector3d t = Eigen::Vector3d::UnitX();
  Eigen::Vector3d b = Eigen::Vector3d::UnitY();
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();

  // Any frame with normal `n` (unit). Continuous except where n.z changes sign (Duff et al. 2017).
  static Frame FromNormal(const Eigen::Vector3d& n);
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
// Warps. u is uniform in [0,1)^2.

// Uniform point on the unit disk (Shirley-Chiu concentric map: low distortion).
Eigen::Vector2d SampleUniformDiskConcentric(const Eigen::Vector2d& u);

// Local direction with density cosθ/π over the upper hemisphere (z >= 0).
Eigen::Vector3d SampleCosineHemisphere(const Eigen::Vector2d& u);
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
SphereSample SampleSphereFromPoint(const Eigen::Vector3d& point, const Eigen::Vector3d& center,
                                   double radius, const Eigen::Vector2d& u);
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

}  // namespace igi
