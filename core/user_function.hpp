/// @file
/// User functions: time laws and spring-damper laws given as callables
/// (C++ std::function, or Python callables wrapped into one by the Python module), with
/// their derivatives from the user or by central finite differences.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/time_law.hpp"

namespace flexmbd {

/// A user function raised (threw) during a run: the run stops there, with the results up
/// to the last output kept, as after a solver failure (exit status 1; in Python the
/// SolverFailure). The message names the element whose law raised, what it raised and t.
class UserFunctionError : public std::runtime_error {
 public:
  UserFunctionError(const std::string& message, double time) : std::runtime_error(message), time_(time) {}
  double time() const { return time_; }

 private:
  double time_;
};

/// Rethrows a UserFunctionError with "<who>: " before its message (the element that owns
/// the law). Called in a catch block only: nothing is allocated unless a law raised.
[[noreturn]] void rethrowWithOwner(const UserFunctionError& e, const std::string& who);

/// f(t), f'(t) or f''(t) of a user time law.
using UserTimeFunction = std::function<double(double t)>;

/// A time law f(t) given by a callable (drivers, applied loads and torques). Its
/// derivatives, which drivers need (the velocity constraint uses f', the accelerations
/// f''), come from `df` / `ddf` if given, otherwise by central differences:
///   f'  = (f(t+h1) - f(t-h1)) / (2 h1),          h1 = eps^(1/3) max(|t|, 1 s),
///   f'' = (f(t+h2) - 2 f(t) + f(t-h2)) / h2^2,   h2 = eps^(1/4) max(|t|, 1 s)
/// (f'' = (df(t+h1) - df(t-h1)) / (2 h1) when only df is given). Each step balances the
/// truncation error (h^2) against rounding (eps / h, eps / h^2): relative errors about
/// eps^(2/3) ~ 4e-11 and eps^(1/2) ~ 1.5e-8 for a law that varies on a scale of 1 s
/// (NocedalWright2006, sec. 8.1); faster laws should give df and ddf.
/// Loads use f only (TimeLaw::value): one call per evaluation. An exception thrown by a
/// callable becomes a UserFunctionError "the user time law raised <what> at t = ...".
/// @throws InputError if f is empty, or ddf is given without df.
TimeLawPtr makeUserTimeLaw(UserTimeFunction f, UserTimeFunction df = {}, UserTimeFunction ddf = {});

/// A spring-damper law's value and its partial derivatives at (t, x, x').
struct SpringLawValue {
  double f = 0.0;       ///< the force (translational) or torque (rotational)
  double dfdx = 0.0;    ///< df/dx: the stiffness the iteration matrix and linearisation see
  double dfdxdot = 0.0; ///< df/dx': the damping
};

/// f(t, x, x') of a spring-damper law.
using SpringFunction = std::function<double(double t, double x, double xdot)>;
/// (df/dx, df/dx') of a spring-damper law.
using SpringDerivative = std::function<std::array<double, 2>(double t, double x, double xdot)>;

/// The law of a spring-damper in place of k (x - x0) + c x': x is the spring's length
/// (translational) or its joint angle (rotational), x' its rate, and f has the sign of
/// the linear law (a tension > 0 pulls the points together; a torque > 0 turns the
/// joint back towards smaller angles). Partial derivatives from `derivative` if given,
/// otherwise by central differences with h = eps^(1/3) max(|x|, 1) (and the same in x';
/// NocedalWright2006, sec. 8.1):
/// they only enter the Newton iteration matrix and linearisations (modes), never the
/// residual, so their error (~ eps^(2/3) relative) does not change a run's results.
class SpringLaw {
 public:
  /// @throws InputError if f is empty.
  explicit SpringLaw(SpringFunction f, SpringDerivative derivative = {});
  /// f at (t, x, x'), and its partial derivatives if withDerivatives (else they are 0).
  /// @throws UserFunctionError "the user spring law raised <what> at t = ..." if a callable throws.
  SpringLawValue evaluate(double t, double x, double xdot, bool withDerivatives) const;
  bool hasUserDerivative() const { return static_cast<bool>(derivative_); }

 private:
  double call(double t, double x, double xdot) const;
  SpringFunction f_;
  SpringDerivative derivative_;
};

using SpringLawPtr = std::shared_ptr<const SpringLaw>;

inline SpringLawPtr makeSpringLaw(SpringFunction f, SpringDerivative derivative = {}) {
  return std::make_shared<const SpringLaw>(std::move(f), std::move(derivative));
}

/// The value of a spring-damper: the user law if given, else the linear law
/// f = k (x - x0) + c x' with df/dx = k, df/dx' = c. A UserFunctionError's message is
/// prefixed "force '<forceName>': ". One code for the planar and spatial elements.
inline SpringLawValue springDamperValue(const SpringLaw* law, double k, double c, double x0, double t, double x,
                                        double xdot, bool withDerivatives, const std::string& forceName) {
  if (!law) return {k * (x - x0) + c * xdot, k, c};
  try {
    return law->evaluate(t, x, xdot, withDerivatives);
  } catch (const UserFunctionError& e) {
    rethrowWithOwner(e, "force '" + forceName + "'");
  }
}

}  // namespace flexmbd
