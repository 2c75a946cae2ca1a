// solver/inverse/numeric.h: the vectorisable exponential against std::exp, and Brent's minimiser on
// functions with known minima (smooth, kinked, at an end of the interval), with its evaluation
// count against golden sections' to the same tolerance.
#include "solver/inverse/numeric.h"

#include <gtest/gtest.h>

#include <cmath>

namespace igi::solver {
namespace {

TEST(ExpNonPositive, MatchesStdExpOverTheLobesRange) {
  double worst_near = 0, worst_far = 0;
  for (int i = 0; i <= 200000; ++i) {
    const float x = -87.0f * float(i) / 200000.0f;
    const double want = std::exp(double(x));
    const double err = std::abs(double(ExpNonPositive(x)) / want - 1.0);
    (x > -2.0f ? worst_near : worst_far) = std::max(x > -2.0f ? worst_near : worst_far, err);
  }
  EXPECT_LT(worst_near, 4e-7);  // measured 3.2e-7
  EXPECT_LT(worst_far, 5e-6);   // measured 3.9e-6 (x·log2 e rounded to float)
  EXPECT_EQ(ExpNonPositive(0.0f), 1.0f);
  EXPECT_EQ(ExpNonPositive(-0.0f), 1.0f);
  // Below −87 the result is 0 (no subnormal, no garbage from the exponent bits), far below too.
  EXPECT_EQ(ExpNonPositive(-88.0f), 0.0f);
  EXPECT_EQ(ExpNonPositive(-1000.0f), 0.0f);
  EXPECT_EQ(ExpNonPositive(-2.0e6f), 0.0f);
  // Monotone between neighbouring floats near 0 (the α search's cost must be smooth).
  float prev = ExpNonPositive(-1.0f);
  for (float x = -1.0f; x < -0.999f; x = std::nextafter(x, 0.0f)) {
    const float v = ExpNonPositive(x);
    ASSERT_GE(v, prev) << x;
    prev = v;
  }
}

TEST(BrentMinimum, FindsKnownMinimaInFewEvaluations) {
  struct Case {
    double a, b, want;
    double (*f)(double);
  };
  const Case cases[] = {
      {-1.0, 2.0, 0.3, [](double x) { return (x - 0.3) * (x - 0.3); }},
      {-1.0, 2.0, 0.7, [](double x) { return std::pow(std::abs(x - 0.7), 1.5); }},  // kinked
      {0.0, 3.0, 1.0, [](double x) { return x - std::log(x); }},                    // skewed
      {0.0, 1.0, 1.0, [](double x) { return -x; }},                                 // at b
      {0.0, 1.0, 0.0, [](double x) { return std::exp(x); }},                        // at a
  };
  for (const Case& c : cases) {
    int evals = 0;
    const double x = BrentMinimum(c.a, c.b, 1e-5, 100, [&](double t) {
      ++evals;
      EXPECT_GE(t, c.a);
      EXPECT_LE(t, c.b);
      return c.f(t);
    });
    EXPECT_NEAR(x, c.want, 5e-5) << "minimum at " << c.want;
    // Golden sections need log(3e5/3)/log(1.618) + 1 ≈ 25 evaluations to this tolerance.
    EXPECT_LE(evals, 40);
    if (c.want > c.a && c.want < c.b && c.want != 0.7) {
      EXPECT_LE(evals, 14) << c.want;
    }
  }
  // The budget is respected.
  int evals = 0;
  BrentMinimum(0.0, 1.0, 1e-12, 7, [&](double t) { return ++evals, std::sin(10 * t); });
  EXPECT_EQ(evals, 7);
}

}  // namespace
}  // namespace igi::solver
