// Unit tests of the prescribed time laws (core/time_law.hpp): exact derivatives
// against finite differences, closed-form values, spline properties, input checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/time_law.hpp"

namespace flexmbd {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Step of the central finite differences.
constexpr double kFdStep = 1e-5;
// Central difference error = truncation h^2/6 |g'''| + roundoff ~ eps |g| / h.
// With h = 1e-5: truncation 1.7e-11 |g'''|, roundoff 2.2e-11 |g| per ulp of error in
// g. The laws below keep |f|, |f'| <= 12 and |f'''| <= 140 (for f'': |f''''| <= 170)
// on the sampled times, so the error is < 1e-8 even with a few ulps of error in g
// (measured: <= 5e-9); 1e-7 leaves a 10x margin, while any wrong factor or sign in a
// derivative gives errors >= 1e-2.
constexpr double kFdTol = 1e-7;
// Closed-form values of order 1..10 computed with a few dozen floating-point
// operations: rounding errors are ~1e-15..1e-14; 1e-12 is a safe bound that still
// detects any formula error.
constexpr double kRoundoffTol = 1e-12;
// Left/right limits at a spline knot are evaluated one ulp apart on two different
// cubic pieces: the true change over one ulp is ~|f'''| * 1e-16 and rounding of the
// piece formula (terms up to |M| h^2 ~ 30) is ~1e-14 (measured: 2e-14); 1e-10 bounds
// both with margin.
// A wrong second-derivative solve makes f' jump by O(|data| / h) ~ 1 at the knots.
constexpr double kKnotContinuityTol = 1e-10;

/// Central differences of f and f' at t compared with the exact f' and f''.
void expectDerivativesMatchFiniteDifferences(const TimeLaw& law,
                                             const std::vector<double>& times) {
  for (const double t : times) {
    const LawValue v = law.evaluate(t);
    const LawValue p = law.evaluate(t + kFdStep);
    const LawValue m = law.evaluate(t - kFdStep);
    const double fdDf = (p.f - m.f) / (2.0 * kFdStep);
    const double fdDdf = (p.df - m.df) / (2.0 * kFdStep);
    EXPECT_NEAR(v.df, fdDf, kFdTol) << law.typeName() << " f' at t = " << t;
    EXPECT_NEAR(v.ddf, fdDdf, kFdTol) << law.typeName() << " f'' at t = " << t;
  }
}

/// Expects `make` to throw InputError whose one-line message contains `needle`.
void expectInputError(const std::function<void()>& make, const std::string& needle) {
  try {
    make();
    ADD_FAILURE() << "expected InputError mentioning '" << needle << "', nothing thrown";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(needle), std::string::npos)
        << "message '" << msg << "' does not mention '" << needle << "'";
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError mentioning '" << needle
                  << "', got another exception: " << e.what();
  }
}

// Parameters shared by several tests.
constexpr double kSpinSpeed = 4.0;
constexpr double kSpinRamp = 0.8;
constexpr double kSpinInitial = 0.3;

// A deliberately uneven, non-smooth table (non-uniform spacing, sign changes), so a
// wrong spline solve cannot hide behind symmetry.
const std::vector<double> kTableTimes = {-0.5, 0.0, 0.3, 1.0, 1.2, 2.0, 3.1};
const std::vector<double> kTableValues = {1.0, 0.2, 0.9, -0.4, -0.1, 1.5, 0.7};

// ---------------------------------------------------------------------------------
// (1) Exact derivatives against finite differences, for every law.

TEST(TimeLawDerivatives, ConstantMatchesFiniteDifferences) {
  const auto law = makeConstantLaw(2.5);
  expectDerivativesMatchFiniteDifferences(*law, {-3.0, 0.0, 0.7, 10.0});
}

TEST(TimeLawDerivatives, ConstantSpeedMatchesFiniteDifferences) {
  const auto law = makeConstantSpeedLaw(1.5, -0.7);
  expectDerivativesMatchFiniteDifferences(*law, {-3.0, 0.0, 0.7, 10.0});
}

TEST(TimeLawDerivatives, PolynomialMatchesFiniteDifferences) {
  // On [-2, 2]: |f| <= 11, |f'''| = |1.8 - 2.4 t| <= 6.6.
  const auto law = makePolynomialLaw({1.0, -2.0, 0.5, 0.3, -0.1});
  expectDerivativesMatchFiniteDifferences(*law, {-2.0, -1.3, -0.2, 0.0, 0.45, 1.1, 2.0});
}

TEST(TimeLawDerivatives, HarmonicMatchesFiniteDifferences) {
  // |f| <= 3, |f'''| <= A w^3 = 54, |f''''| <= 162 (enters only at O(h^2) in f'').
  const auto law = makeHarmonicLaw(2.0, 3.0, 0.4, 1.0);
  expectDerivativesMatchFiniteDifferences(*law, {-1.0, 0.0, 0.25, 0.9, 1.7, 4.2});
}

TEST(TimeLawDerivatives, SpinUpMatchesFiniteDifferences) {
  // |f'''| <= (w/T)(2 pi/T) = 39. f''' = (w/T)(2 pi/T) sin(2 pi t/T) vanishes at
  // t = 0 and t = T, so the law is C3 there and differences across them are valid.
  const auto law = makeSpinUpLaw(kSpinSpeed, kSpinRamp, kSpinInitial);
  expectDerivativesMatchFiniteDifferences(
      *law, {-0.5, 0.0, 0.05, 0.2, 0.4, 0.61, 0.79, kSpinRamp, 1.0, 3.0});
}

TEST(TimeLawDerivatives, TabulatedMatchesFiniteDifferences) {
  // Sample times are >= 0.02 away from knots (f''' jumps there) and include both
  // extrapolation ranges. Here |M_i| <= 23 and |f'''| = |M_{i+1} - M_i| / h <= 140.
  const auto law = makeTabulatedLaw(kTableTimes, kTableValues);
  expectDerivativesMatchFiniteDifferences(
      *law, {-2.0, -0.7, -0.3, -0.1, 0.1, 0.2, 0.65, 1.1, 1.5, 1.9, 2.5, 3.0, 3.5, 6.0});
}

// ---------------------------------------------------------------------------------
// (2) Closed-form values.

TEST(TimeLawValues, ConstantAndConstantSpeed) {
  const LawValue c = makeConstantLaw(2.5)->evaluate(7.0);
  EXPECT_NEAR(c.f, 2.5, kRoundoffTol);
  EXPECT_NEAR(c.df, 0.0, kRoundoffTol);
  EXPECT_NEAR(c.ddf, 0.0, kRoundoffTol);
  const LawValue s = makeConstantSpeedLaw(1.5, -0.7)->evaluate(2.0);
  EXPECT_NEAR(s.f, -0.7 + 3.0, kRoundoffTol);
  EXPECT_NEAR(s.df, 1.5, kRoundoffTol);
  EXPECT_NEAR(s.ddf, 0.0, kRoundoffTol);
  // Default initial value is 0.
  EXPECT_NEAR(makeConstantSpeedLaw(1.5)->evaluate(2.0).f, 3.0, kRoundoffTol);
}

TEST(TimeLawValues, PolynomialAtAPoint) {
  // p = 1 - 2t + t^2/2 + t^3/4 - t^4/8 at t = 2 (by hand):
  //   p   = 1 - 4 + 2 + 2 - 2           = -1
  //   p'  = -2 + t + 3t^2/4 - t^3/2     = -2 + 2 + 3 - 4  = -1
  //   p'' = 1 + 3t/2 - 3t^2/2           = 1 + 3 - 6       = -2
  const auto law = makePolynomialLaw({1.0, -2.0, 0.5, 0.25, -0.125});
  const LawValue v = law->evaluate(2.0);
  EXPECT_NEAR(v.f, -1.0, kRoundoffTol);
  EXPECT_NEAR(v.df, -1.0, kRoundoffTol);
  EXPECT_NEAR(v.ddf, -2.0, kRoundoffTol);
  // At t = 0: p = c0, p' = c1, p'' = 2 c2.
  const LawValue z = law->evaluate(0.0);
  EXPECT_NEAR(z.f, 1.0, kRoundoffTol);
  EXPECT_NEAR(z.df, -2.0, kRoundoffTol);
  EXPECT_NEAR(z.ddf, 1.0, kRoundoffTol);
  // A single coefficient is a constant.
  const LawValue k = makePolynomialLaw({3.25})->evaluate(-5.0);
  EXPECT_NEAR(k.f, 3.25, kRoundoffTol);
  EXPECT_NEAR(k.df, 0.0, kRoundoffTol);
  EXPECT_NEAR(k.ddf, 0.0, kRoundoffTol);
}

TEST(TimeLawValues, HarmonicAtAPoint) {
  // f = 1 + 2 sin(3t + 0.4). At 3t + 0.4 = pi/2: f = 3, f' = 0, f'' = -A w^2 = -18.
  const auto law = makeHarmonicLaw(2.0, 3.0, 0.4, 1.0);
  const LawValue top = law->evaluate((kPi / 2.0 - 0.4) / 3.0);
  EXPECT_NEAR(top.f, 3.0, kRoundoffTol);
  EXPECT_NEAR(top.df, 0.0, kRoundoffTol);
  EXPECT_NEAR(top.ddf, -18.0, kRoundoffTol);
  // At 3t + 0.4 = pi: f = offset = 1, f' = -A w = -6, f'' = 0.
  const LawValue zero = law->evaluate((kPi - 0.4) / 3.0);
  EXPECT_NEAR(zero.f, 1.0, kRoundoffTol);
  EXPECT_NEAR(zero.df, -6.0, kRoundoffTol);
  EXPECT_NEAR(zero.ddf, 0.0, kRoundoffTol);
}

// theta = (w/T)(t^2/2 + (T/(2pi))^2 (cos(2 pi t/T) - 1)), t < T, so
//   theta'  = (w/T)(t - (T/(2pi)) sin(2 pi t/T)),   theta'' = (w/T)(1 - cos(2 pi t/T)).
// t = 0:   theta = 0, theta' = 0, theta'' = 0.
// t = T/2: theta = wT/8 - wT/(2 pi^2), theta' = w/2, theta'' = 2w/T (peak).
// t = T:   theta = wT/2, theta' = w, theta'' = 0; the branch w (t - T/2) gives the
//          same values, so the law is C2 at T.
TEST(TimeLawValues, SpinUpAtStartMiddleEndOfRamp) {
  const double w = kSpinSpeed;
  const double T = kSpinRamp;
  const auto law = makeSpinUpLaw(w, T, kSpinInitial);

  const LawValue s = law->evaluate(0.0);
  EXPECT_NEAR(s.f, kSpinInitial, kRoundoffTol);
  EXPECT_NEAR(s.df, 0.0, kRoundoffTol);
  EXPECT_NEAR(s.ddf, 0.0, kRoundoffTol);

  const LawValue mid = law->evaluate(T / 2.0);
  EXPECT_NEAR(mid.f, kSpinInitial + w * T / 8.0 - w * T / (2.0 * kPi * kPi), kRoundoffTol);
  EXPECT_NEAR(mid.df, w / 2.0, kRoundoffTol);
  EXPECT_NEAR(mid.ddf, 2.0 * w / T, kRoundoffTol);

  const LawValue end = law->evaluate(T);
  EXPECT_NEAR(end.f, kSpinInitial + w * T / 2.0, kRoundoffTol);
  EXPECT_NEAR(end.df, w, kRoundoffTol);
  EXPECT_NEAR(end.ddf, 0.0, kRoundoffTol);
}

TEST(TimeLawValues, SpinUpIsC2AtEndOfRamp) {
  const double T = kSpinRamp;
  const auto law = makeSpinUpLaw(kSpinSpeed, T, kSpinInitial);
  // Left limit: last double below T (ramp formula); right limit: first above T.
  const LawValue left = law->evaluate(std::nextafter(T, 0.0));
  const LawValue right = law->evaluate(std::nextafter(T, 10.0));
  EXPECT_NEAR(left.f, right.f, kRoundoffTol);
  EXPECT_NEAR(left.df, right.df, kRoundoffTol);
  EXPECT_NEAR(left.ddf, right.ddf, kRoundoffTol);
  EXPECT_NEAR(left.ddf, 0.0, kRoundoffTol);
}

TEST(TimeLawValues, SpinUpHoldsSpeedAfterRampAndIsAtRestBefore) {
  const double w = kSpinSpeed;
  const double T = kSpinRamp;
  const auto law = makeSpinUpLaw(w, T, kSpinInitial);
  for (const double t : {T + 1e-3, 1.0, 2.0, 25.0}) {
    const LawValue v = law->evaluate(t);
    EXPECT_NEAR(v.f, kSpinInitial + w * (t - T / 2.0), kRoundoffTol) << "t = " << t;
    EXPECT_NEAR(v.df, w, kRoundoffTol) << "t = " << t;
    EXPECT_NEAR(v.ddf, 0.0, kRoundoffTol) << "t = " << t;
  }
  const LawValue before = law->evaluate(-1.0);
  EXPECT_NEAR(before.f, kSpinInitial, kRoundoffTol);
  EXPECT_NEAR(before.df, 0.0, kRoundoffTol);
  EXPECT_NEAR(before.ddf, 0.0, kRoundoffTol);
}

TEST(TimeLawValues, SpinUpSpeedRisesMonotonicallyFromZeroToW) {
  // theta'' = (w/T)(1 - cos) >= 0, so theta' rises monotonically from 0 to w and
  // theta'' never exceeds its peak 2w/T.
  const double w = kSpinSpeed;
  const double T = kSpinRamp;
  const auto law = makeSpinUpLaw(w, T, 0.0);
  double previous = 0.0;
  for (int k = 0; k <= 200; ++k) {
    const LawValue v = law->evaluate(T * k / 200.0);
    EXPECT_GE(v.df, previous - kRoundoffTol) << "k = " << k;
    EXPECT_LE(v.df, w + kRoundoffTol) << "k = " << k;
    EXPECT_GE(v.ddf, -kRoundoffTol) << "k = " << k;
    EXPECT_LE(v.ddf, 2.0 * w / T + kRoundoffTol) << "k = " << k;
    previous = v.df;
  }
}

// ---------------------------------------------------------------------------------
// (3) Natural cubic spline.

TEST(TabulatedLaw, InterpolatesTableExactlyAtKnots) {
  const auto law = makeTabulatedLaw(kTableTimes, kTableValues);
  for (std::size_t i = 0; i < kTableTimes.size(); ++i) {
    EXPECT_NEAR(law->evaluate(kTableTimes[i]).f, kTableValues[i], kRoundoffTol)
        << "knot " << i;
  }
}

TEST(TabulatedLaw, ReproducesStraightLineInsideAndOutside) {
  // Every cubic spline of linear data is the line itself (all M_i = 0).
  const std::vector<double> t = {-1.0, -0.3, 0.0, 0.7, 2.2, 2.5};
  std::vector<double> y;
  for (const double ti : t) y.push_back(2.0 - 0.5 * ti);
  const auto law = makeTabulatedLaw(t, y);
  for (const double s : {-4.0, -1.0, -0.8, -0.1, 0.0, 0.35, 1.9, 2.5, 3.0, 10.0}) {
    const LawValue v = law->evaluate(s);
    EXPECT_NEAR(v.f, 2.0 - 0.5 * s, kRoundoffTol) << "t = " << s;
    EXPECT_NEAR(v.df, -0.5, kRoundoffTol) << "t = " << s;
    EXPECT_NEAR(v.ddf, 0.0, kRoundoffTol) << "t = " << s;
  }
  // Two points: the spline is the line through them.
  const auto two = makeTabulatedLaw({1.0, 3.0}, {5.0, 4.0});
  const LawValue v = two->evaluate(2.5);
  EXPECT_NEAR(v.f, 4.25, kRoundoffTol);
  EXPECT_NEAR(v.df, -0.5, kRoundoffTol);
  EXPECT_NEAR(v.ddf, 0.0, kRoundoffTol);
}

TEST(TabulatedLaw, NaturalEndConditionsAndC1Extrapolation) {
  const auto law = makeTabulatedLaw(kTableTimes, kTableValues);
  for (const double end : {kTableTimes.front(), kTableTimes.back()}) {
    const LawValue at = law->evaluate(end);
    const LawValue below = law->evaluate(std::nextafter(end, -kInf));
    const LawValue above = law->evaluate(std::nextafter(end, kInf));
    EXPECT_NEAR(at.ddf, 0.0, kRoundoffTol) << "end knot t = " << end;
    // Continuous value and slope across the end knot (spline | linear extrapolation).
    EXPECT_NEAR(below.f, above.f, kKnotContinuityTol) << "t = " << end;
    EXPECT_NEAR(below.df, above.df, kKnotContinuityTol) << "t = " << end;
    EXPECT_NEAR(below.ddf, 0.0, kKnotContinuityTol) << "t = " << end;
    EXPECT_NEAR(above.ddf, 0.0, kKnotContinuityTol) << "t = " << end;
  }
  // Far outside the table: straight lines with the end slopes.
  const LawValue s0 = law->evaluate(kTableTimes.front());
  const LawValue s1 = law->evaluate(kTableTimes.back());
  const LawValue farLeft = law->evaluate(kTableTimes.front() - 4.0);
  const LawValue farRight = law->evaluate(kTableTimes.back() + 4.0);
  EXPECT_NEAR(farLeft.f, s0.f - 4.0 * s0.df, kRoundoffTol);
  EXPECT_NEAR(farLeft.df, s0.df, kRoundoffTol);
  EXPECT_NEAR(farLeft.ddf, 0.0, kRoundoffTol);
  EXPECT_NEAR(farRight.f, s1.f + 4.0 * s1.df, kRoundoffTol);
  EXPECT_NEAR(farRight.df, s1.df, kRoundoffTol);
  EXPECT_NEAR(farRight.ddf, 0.0, kRoundoffTol);
}

TEST(TabulatedLaw, IsC2AcrossInteriorKnots) {
  const auto law = makeTabulatedLaw(kTableTimes, kTableValues);
  for (std::size_t i = 1; i + 1 < kTableTimes.size(); ++i) {
    // One ulp on each side selects the cubic piece left and right of the knot.
    const LawValue left = law->evaluate(std::nextafter(kTableTimes[i], -kInf));
    const LawValue right = law->evaluate(std::nextafter(kTableTimes[i], kInf));
    EXPECT_NEAR(left.f, right.f, kKnotContinuityTol) << "knot " << i;
    EXPECT_NEAR(left.df, right.df, kKnotContinuityTol) << "knot " << i;
    EXPECT_NEAR(left.ddf, right.ddf, kKnotContinuityTol) << "knot " << i;
  }
}

/// Max errors of the natural spline of sin on n uniform knots over [0, pi].
struct SplineErrors {
  double h, f, df, ddf;
};
SplineErrors sinSplineErrors(int n) {
  std::vector<double> t(n), y(n);
  for (int i = 0; i < n; ++i) {
    t[i] = kPi * i / (n - 1);
    y[i] = std::sin(t[i]);
  }
  const auto law = makeTabulatedLaw(t, y);
  SplineErrors e{kPi / (n - 1), 0.0, 0.0, 0.0};
  constexpr int kSamples = 4000;  // ~100 per interval: resolves the error maxima
  for (int k = 0; k <= kSamples; ++k) {
    const double s = kPi * k / kSamples;
    const LawValue v = law->evaluate(s);
    e.f = std::max(e.f, std::abs(v.f - std::sin(s)));
    e.df = std::max(e.df, std::abs(v.df - std::cos(s)));
    e.ddf = std::max(e.ddf, std::abs(v.ddf + std::sin(s)));
  }
  return e;
}

TEST(TabulatedLaw, MatchesSmoothFunctionWithinSplineErrorBound) {
  // sin on [0, pi] has sin'' = 0 at both ends, so the natural end conditions are exact:
  // by odd symmetry about 0 and pi, this spline is the periodic spline of sin, for
  // which the Hall & Meyer (1976) bounds hold with |f''''| <= 1:
  //   |S - f| <= 5/384 h^4,  |S' - f'| <= 1/24 h^3,  |S'' - f''| <= 3/8 h^2.
  // The tolerances are these bounds (plus roundoff), not a fitted number.
  const SplineErrors e = sinSplineErrors(41);
  const double h = e.h;
  EXPECT_LE(e.f, 5.0 / 384.0 * std::pow(h, 4) + kRoundoffTol);
  EXPECT_LE(e.df, 1.0 / 24.0 * std::pow(h, 3) + kRoundoffTol);
  EXPECT_LE(e.ddf, 3.0 / 8.0 * std::pow(h, 2) + kRoundoffTol);
}

TEST(TabulatedLaw, ValueErrorConvergesAtFourthOrder) {
  // Halving h must divide the value error by ~2^4 = 16. The ratio tends to 16 as
  // h -> 0; [12, 20] accepts the O(h^6) correction at h = pi/20 while rejecting
  // third order (8) or fifth order (32).
  constexpr double kMinRatio = 12.0;
  constexpr double kMaxRatio = 20.0;
  const SplineErrors coarse = sinSplineErrors(21);
  const SplineErrors fine = sinSplineErrors(41);
  const double ratio = coarse.f / fine.f;
  EXPECT_GE(ratio, kMinRatio);
  EXPECT_LE(ratio, kMaxRatio);
}

// ---------------------------------------------------------------------------------
// Type names and purity.

TEST(TimeLaw, TypeNames) {
  EXPECT_EQ(makeConstantLaw(1.0)->typeName(), "constant");
  EXPECT_EQ(makeConstantSpeedLaw(1.0)->typeName(), "constant_speed");
  EXPECT_EQ(makePolynomialLaw({1.0})->typeName(), "polynomial");
  EXPECT_EQ(makeHarmonicLaw(1.0, 1.0)->typeName(), "harmonic");
  EXPECT_EQ(makeSpinUpLaw(1.0, 1.0)->typeName(), "spin_up");
  EXPECT_EQ(makeTabulatedLaw({0.0, 1.0}, {0.0, 1.0})->typeName(), "tabulated");
}

TEST(TimeLaw, EvaluateIsPureInAnyOrder) {
  // No hidden state (e.g. a cached spline interval): out-of-order evaluation gives
  // bit-identical results.
  const auto law = makeTabulatedLaw(kTableTimes, kTableValues);
  const LawValue first = law->evaluate(1.1);
  law->evaluate(3.0);
  law->evaluate(-0.4);
  const LawValue again = law->evaluate(1.1);
  EXPECT_EQ(first.f, again.f);
  EXPECT_EQ(first.df, again.df);
  EXPECT_EQ(first.ddf, again.ddf);
}

// ---------------------------------------------------------------------------------
// (4) Bad input: InputError naming the offending parameter.

TEST(TimeLawInput, SpinUpRampTimeMustBePositive) {
  expectInputError([] { makeSpinUpLaw(1.0, 0.0); }, "rampTime");
  expectInputError([] { makeSpinUpLaw(1.0, -2.0); }, "rampTime");
  expectInputError([] { makeSpinUpLaw(1.0, kNaN); }, "rampTime");
  expectInputError([] { makeSpinUpLaw(kInf, 1.0); }, "speed");
  expectInputError([] { makeSpinUpLaw(1.0, 1.0, kNaN); }, "initial");
}

TEST(TimeLawInput, PolynomialNeedsFiniteCoefficients) {
  expectInputError([] { makePolynomialLaw({}); }, "coefficients");
  expectInputError([] { makePolynomialLaw({1.0, kNaN}); }, "coefficients[1]");
  expectInputError([] { makePolynomialLaw({-kInf}); }, "coefficients[0]");
}

TEST(TimeLawInput, TabulatedTableChecks) {
  expectInputError([] { makeTabulatedLaw({0.0}, {1.0}); }, "at least 2");
  expectInputError([] { makeTabulatedLaw({}, {}); }, "at least 2");
  expectInputError([] { makeTabulatedLaw({0.0, 1.0, 2.0}, {1.0, 2.0}); }, "values");
  expectInputError([] { makeTabulatedLaw({0.0, 1.0}, {1.0, 2.0, 3.0}); }, "times");
  expectInputError([] { makeTabulatedLaw({0.0, 1.0, 1.0}, {1.0, 2.0, 3.0}); }, "times[2]");
  expectInputError([] { makeTabulatedLaw({0.0, 2.0, 1.0}, {1.0, 2.0, 3.0}); }, "times[2]");
  expectInputError([] { makeTabulatedLaw({kNaN, 1.0}, {1.0, 2.0}); }, "times[0]");
  expectInputError([] { makeTabulatedLaw({0.0, 1.0}, {1.0, kInf}); }, "values[1]");
}

TEST(TimeLawInput, NonFiniteParametersOfSimpleLaws) {
  expectInputError([] { makeConstantLaw(kNaN); }, "value");
  expectInputError([] { makeConstantSpeedLaw(kInf); }, "speed");
  expectInputError([] { makeConstantSpeedLaw(1.0, kNaN); }, "initial");
  expectInputError([] { makeHarmonicLaw(kNaN, 1.0); }, "amplitude");
  expectInputError([] { makeHarmonicLaw(1.0, kInf); }, "omega");
  expectInputError([] { makeHarmonicLaw(1.0, 1.0, kNaN); }, "phase");
  expectInputError([] { makeHarmonicLaw(1.0, 1.0, 0.0, -kInf); }, "offset");
}

}  // namespace
}  // namespace flexmbd
