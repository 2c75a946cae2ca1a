#pragma once
// Small numerical helpers of the region fits (solver/inverse/region_fit.cpp), written here because
// no dependency of igi offers them: Ceres has no public one-dimensional minimiser (Boost.Math's
// brent_find_minima is not among the Debian packages igi uses), and libm's expf is a call per
// value, which keeps a loop of them from being vectorised.

#include <bit>
#include <cmath>

namespace igi::solver {

// exp(x) for −2^21 < x <= 0 in float: relative error under 4e−7 for x > −2, under 5e−6 down to
// −87, and 0 below about −87 (where the result would be subnormal). 2^(x·log2 e) split into an
// integer power of two, built in the float's exponent bits, and 2^f, |f| <= 1/2, by the Taylor
// series of e^(f·ln 2) to the 6th power; without branches, so that GCC vectorises a loop of it.
inline float ExpNonPositive(float x) {
  const float t = x * 1.44269504f;
  const float r = (t + 12582912.0f) - 12582912.0f;  // t rounded to an integer (1.5·2^23)
  const float g = (t - r) * 0.693147181f;           // |g| <= ln 2 / 2
  const float p =
      1.0f +
      g * (1.0f + g * (0.5f + g * (1.0f / 6 + g * (1.0f / 24 + g * (1.0f / 120 + g / 720)))));
  const int e = static_cast<int>(r) + 127;        // 2^r's biased exponent
  const int bits = (e << 23) & ~((e - 1) >> 31);  // 0 (the float 0) where e < 1
  return p * std::bit_cast<float>(bits);
}

// The minimum of f on [a, b] by Brent's method (golden sections, and parabolic steps through the
// three best points where they behave), to within about 2·tol; at most max_evals calls of f.
// For a unimodal f it finds the minimum (an end of [a, b] when f is monotone there, to within
// 2·tol); otherwise a local one.
template <typename F>
double BrentMinimum(double a, double b, double tol, int max_evals, F&& f) {
  constexpr double kGold = 0.3819660112501051;  // (3 − √5)/2
  double x = a + kGold * (b - a), w = x, v = x;
  double fx = f(x), fw = fx, fv = fx;
  double step = 0, before = 0;  // the last step, and the one before it
  for (int evals = 1; evals < max_evals; ++evals) {
    const double mid = 0.5 * (a + b);
    if (std::abs(x - mid) <= 2 * tol - 0.5 * (b - a)) break;
    bool parabolic = false;
    if (std::abs(before) > tol) {
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      // Accepted when it moves less than half the step before last and stays inside [a, b].
      if (std::abs(p) < std::abs(0.5 * q * before) && p > q * (a - x) && p < q * (b - x)) {
        before = step;
        step = p / q;
        if (x + step - a < 2 * tol || b - (x + step) < 2 * tol) step = mid >= x ? tol : -tol;
        parabolic = true;
      }
    }
    if (!parabolic) {
      before = x >= mid ? a - x : b - x;
      step = kGold * before;
    }
    const double u = std::abs(step) >= tol ? x + step : x + (step > 0 ? tol : -tol);
    const double fu = f(u);
    if (fu <= fx) {
      (u >= x ? a : b) = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  return x;
}

}  // namespace igi::solver
