/// @file
/// Prescribed functions of time f(t) with exact first and second derivatives, used by
/// drivers (rheonomic constraints) and by applied forces and torques.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace flexmbd {

/// Value and exact time derivatives of a prescribed law at one instant.
struct LawValue {
  double f = 0.0;    ///< f(t)
  double df = 0.0;   ///< f'(t)
  double ddf = 0.0;  ///< f''(t)
};

/// A scalar function of time. Immutable after construction; evaluate() is pure.
class TimeLaw {
 public:
  virtual ~TimeLaw() = default;
  /// f, f', f'' at time t (all exact, no finite differences).
  virtual LawValue evaluate(double t) const = 0;
  /// f(t) alone (loads): the same number as evaluate(t).f; a user law (core/user_function.hpp)
  /// computes no derivatives for it.
  virtual double value(double t) const { return evaluate(t).f; }
  /// Short type name as used in scene files ("constant_speed", ...).
  virtual std::string typeName() const = 0;
};

using TimeLawPtr = std::shared_ptr<const TimeLaw>;

// All factories throw InputError if any parameter is not finite (NaN or inf); the
// message names the parameter.

/// f(t) = value.
TimeLawPtr makeConstantLaw(double value);
/// f(t) = initial + speed * t.
TimeLawPtr makeConstantSpeedLaw(double speed, double initial = 0.0);
/// f(t) = sum_k c[k] t^k (c[0] + c[1] t + ...). @throws InputError if c is empty.
TimeLawPtr makePolynomialLaw(std::vector<double> coefficients);
/// f(t) = offset + amplitude * sin(omega t + phase).
TimeLawPtr makeHarmonicLaw(double amplitude, double omega, double phase = 0.0,
                           double offset = 0.0);
/// Smooth spin-up to angular speed w over time T:
///   theta(t) = (w/T) (t^2/2 + (T/(2 pi))^2 (cos(2 pi t/T) - 1))  for t < T,
///   theta(t) = w (t - T/2)                                        for t >= T;
/// plus `initial`. Continuous up to the second derivative at t = T. For t <= 0 the
/// law holds `initial` (theta, theta', theta'' all vanish at t = 0, so it stays C2).
/// @throws InputError if T <= 0.
TimeLawPtr makeSpinUpLaw(double speed, double rampTime, double initial = 0.0);
/// Natural cubic spline (Press2007, sec. 3.3) through (times[i], values[i]); times strictly increasing,
/// at least 2 points. Outside the table: linear extrapolation with the end slopes
/// (f'' = 0), so the law stays C1. @throws InputError on bad tables.
TimeLawPtr makeTabulatedLaw(std::vector<double> times, std::vector<double> values);

}  // namespace flexmbd
