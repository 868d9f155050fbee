// User time laws and spring-damper laws: callables with user or finite-difference
// derivatives (core/user_function.hpp).
#include "core/user_function.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "core/errors.hpp"
#include "core/stop_request.hpp"

namespace flexmbd {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

std::string timeText(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", t);
  return buf;
}

/// Calls `call`; any exception it throws becomes a UserFunctionError
/// "the user <what> raised <message> at t = <t>".
template <class F>
auto guarded(const char* what, double t, F&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const UserFunctionError&) {
    throw;
  } catch (const std::exception& e) {
    pollStop(t);  // a stop requested while the callable ran (Ctrl-C in a Python one) ends the run as interrupted
    throw UserFunctionError(std::string("the user ") + what + " raised " + e.what() + " at t = " + timeText(t), t);
  } catch (...) {
    throw UserFunctionError(
        std::string("the user ") + what + " raised an exception that is not a std::exception at t = " + timeText(t), t);
  }
}

class UserTimeLaw final : public TimeLaw {
 public:
  UserTimeLaw(UserTimeFunction f, UserTimeFunction df, UserTimeFunction ddf)
      : f_(std::move(f)), df_(std::move(df)), ddf_(std::move(ddf)) {
    if (!f_) throw InputError("user time law: no function given; expected a callable f(t)");
    if (ddf_ && !df_) {
      throw InputError("user time law: a second derivative without the first; give both, or the first alone");
    }
  }
  double value(double t) const override { return f(t); }
  LawValue evaluate(double t) const override {
    LawValue v;
    v.f = f(t);
    const double scale = std::max(std::abs(t), 1.0);  // 1 s: the time scale the steps assume (header)
    if (df_) {
      v.df = guarded("time law's derivative", t, [&] { return df_(t); });
      if (ddf_) {
        v.ddf = guarded("time law's second derivative", t, [&] { return ddf_(t); });
      } else {
        // f'' = (f'(t+h) - f'(t-h)) / 2h, h = eps^(1/3) scale (header; NocedalWright2006, sec. 8.1)
        const double h = std::cbrt(kEps) * scale;
        const double up = guarded("time law's derivative", t, [&] { return df_(t + h); });
        const double down = guarded("time law's derivative", t, [&] { return df_(t - h); });
        v.ddf = (up - down) / (2.0 * h);
      }
      return v;
    }
    // central differences (header; NocedalWright2006, sec. 8.1): f' with h1 = eps^(1/3) scale,
    // f'' with h2 = eps^(1/4) scale
    const double h1 = std::cbrt(kEps) * scale;
    const double h2 = std::sqrt(std::sqrt(kEps)) * scale;
    v.df = (f(t + h1) - f(t - h1)) / (2.0 * h1);
    v.ddf = (f(t + h2) - 2.0 * v.f + f(t - h2)) / (h2 * h2);
    return v;
  }
  std::string typeName() const override { return "user"; }

 private:
  double f(double t) const {
    return guarded("time law", t, [&] { return f_(t); });
  }
  UserTimeFunction f_, df_, ddf_;
};

}  // namespace

void rethrowWithOwner(const UserFunctionError& e, const std::string& who) {
  throw UserFunctionError(who + ": " + e.what(), e.time());
}

TimeLawPtr makeUserTimeLaw(UserTimeFunction f, UserTimeFunction df, UserTimeFunction ddf) {
  return std::make_shared<UserTimeLaw>(std::move(f), std::move(df), std::move(ddf));
}

SpringLaw::SpringLaw(SpringFunction f, SpringDerivative derivative)
    : f_(std::move(f)), derivative_(std::move(derivative)) {
  if (!f_) throw InputError("user spring law: no function given; expected a callable f(t, x, xdot)");
}

double SpringLaw::call(double t, double x, double xdot) const {
  return guarded("spring law", t, [&] { return f_(t, x, xdot); });
}

SpringLawValue SpringLaw::evaluate(double t, double x, double xdot, bool withDerivatives) const {
  SpringLawValue v;
  v.f = call(t, x, xdot);
  if (!withDerivatives) return v;
  if (derivative_) {
    const std::array<double, 2> d = guarded("spring law's derivative", t, [&] { return derivative_(t, x, xdot); });
    v.dfdx = d[0];
    v.dfdxdot = d[1];
    return v;
  }
  // central differences, h = eps^(1/3) max(|x|, 1) (header; NocedalWright2006, sec. 8.1)
  const double hx = std::cbrt(kEps) * std::max(std::abs(x), 1.0);
  const double hv = std::cbrt(kEps) * std::max(std::abs(xdot), 1.0);
  v.dfdx = (call(t, x + hx, xdot) - call(t, x - hx, xdot)) / (2.0 * hx);
  v.dfdxdot = (call(t, x, xdot + hv) - call(t, x, xdot - hv)) / (2.0 * hv);
  return v;
}

}  // namespace flexmbd
