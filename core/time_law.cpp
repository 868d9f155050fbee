// Prescribed time laws: constant, constant speed, polynomial, harmonic, spin-up and
// tabulated (natural cubic spline). Every law returns exact f, f', f''.
#include "core/time_law.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Shortest round-trippable text of a number, for error messages.
std::string fmt(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

/// Throws InputError "<law> law: <name> = <x> is not finite; expected a finite number".
void requireFinite(const char* law, const std::string& name, double x) {
  if (!std::isfinite(x)) {
    throw InputError(std::string(law) + " law: " + name + " = " + fmt(x) +
                     " is not finite; expected a finite number");
  }
}

// ---------------------------------------------------------------------------------

class ConstantLaw final : public TimeLaw {
 public:
  explicit ConstantLaw(double value) : value_(value) {
    requireFinite("constant", "value", value);
  }
  // f = c, f' = f'' = 0 (definition).
  LawValue evaluate(double /*t*/) const override { return {value_, 0.0, 0.0}; }
  std::string typeName() const override { return "constant"; }

 private:
  double value_;
};

class ConstantSpeedLaw final : public TimeLaw {
 public:
  ConstantSpeedLaw(double speed, double initial) : speed_(speed), initial_(initial) {
    requireFinite("constant_speed", "speed", speed);
    requireFinite("constant_speed", "initial", initial);
  }
  // f = initial + speed t (definition, core/time_law.hpp).
  LawValue evaluate(double t) const override { return {initial_ + speed_ * t, speed_, 0.0}; }
  std::string typeName() const override { return "constant_speed"; }

 private:
  double speed_;
  double initial_;
};

class PolynomialLaw final : public TimeLaw {
 public:
  explicit PolynomialLaw(std::vector<double> coefficients) : c_(std::move(coefficients)) {
    if (c_.empty()) {
      throw InputError(
          "polynomial law: coefficients is empty; expected at least one coefficient "
          "(c[0] + c[1] t + ...)");
    }
    for (std::size_t k = 0; k < c_.size(); ++k) {
      requireFinite("polynomial", "coefficients[" + std::to_string(k) + "]", c_[k]);
    }
  }
  // f = sum_k c_k t^k with f', f'' by Horner's scheme carrying derivatives
  // (Knuth, sec. 4.6.4); the recursion for ddp yields p'' directly.
  LawValue evaluate(double t) const override {
    double p = c_.back();
    double dp = 0.0;
    double ddp = 0.0;
    for (std::size_t k = c_.size() - 1; k-- > 0;) {
      ddp = ddp * t + 2.0 * dp;
      dp = dp * t + p;
      p = p * t + c_[k];
    }
    return {p, dp, ddp};
  }
  std::string typeName() const override { return "polynomial"; }

 private:
  std::vector<double> c_;
};

class HarmonicLaw final : public TimeLaw {
 public:
  HarmonicLaw(double amplitude, double omega, double phase, double offset)
      : amplitude_(amplitude), omega_(omega), phase_(phase), offset_(offset) {
    requireFinite("harmonic", "amplitude", amplitude);
    requireFinite("harmonic", "omega", omega);
    requireFinite("harmonic", "phase", phase);
    requireFinite("harmonic", "offset", offset);
  }
  // f = offset + A sin(omega t + phase) and its exact derivatives (core/time_law.hpp).
  LawValue evaluate(double t) const override {
    const double arg = omega_ * t + phase_;
    const double s = std::sin(arg);
    const double c = std::cos(arg);
    return {offset_ + amplitude_ * s, amplitude_ * omega_ * c,
            -amplitude_ * omega_ * omega_ * s};
  }
  std::string typeName() const override { return "harmonic"; }

 private:
  double amplitude_;
  double omega_;
  double phase_;
  double offset_;
};

class SpinUpLaw final : public TimeLaw {
 public:
  SpinUpLaw(double speed, double rampTime, double initial)
      : speed_(speed), rampTime_(rampTime), initial_(initial) {
    requireFinite("spin_up", "speed", speed);
    requireFinite("spin_up", "rampTime", rampTime);
    requireFinite("spin_up", "initial", initial);
    if (!(rampTime > 0.0)) {
      throw InputError("spin_up law: rampTime = " + fmt(rampTime) +
                       " must be > 0 (duration of the spin-up ramp)");
    }
  }
  LawValue evaluate(double t) const override {
    const double w = speed_;
    const double T = rampTime_;
    if (t <= 0.0) {
      // At rest before the ramp: theta, theta', theta'' all vanish at t = 0, so
      // holding the initial value keeps the law C2 there.
      return {initial_, 0.0, 0.0};
    }
    if (t >= T) {
      // theta = w (t - T/2) after the ramp.
      return {initial_ + w * (t - 0.5 * T), w, 0.0};
    }
    const double x = 2.0 * kPi * t / T;
    const double r = T / (2.0 * kPi);
    // theta = (w/T)(t^2/2 + (T/(2 pi))^2 (cos(2 pi t/T) - 1)); the
    // derivatives follow by differentiating it: theta' = (w/T)(t - (T/(2 pi)) sin),
    // theta'' = (w/T)(1 - cos). cos - 1 = -2 sin^2(x/2) avoids cancellation at small t.
    const double sh = std::sin(0.5 * x);
    const double f = (w / T) * (0.5 * t * t - 2.0 * r * r * sh * sh);
    const double df = (w / T) * (t - r * std::sin(x));
    const double ddf = (w / T) * 2.0 * sh * sh;
    return {initial_ + f, df, ddf};
  }
  std::string typeName() const override { return "spin_up"; }

 private:
  double speed_;
  double rampTime_;
  double initial_;
};

class TabulatedLaw final : public TimeLaw {
 public:
  TabulatedLaw(std::vector<double> times, std::vector<double> values)
      : x_(std::move(times)), y_(std::move(values)) {
    if (x_.size() != y_.size()) {
      throw InputError("tabulated law: times has " + std::to_string(x_.size()) +
                       " entries but values has " + std::to_string(y_.size()) +
                       "; expected the same number");
    }
    if (x_.size() < 2) {
      throw InputError("tabulated law: times/values have " + std::to_string(x_.size()) +
                       " point(s); expected at least 2");
    }
    for (std::size_t i = 0; i < x_.size(); ++i) {
      requireFinite("tabulated", "times[" + std::to_string(i) + "]", x_[i]);
      requireFinite("tabulated", "values[" + std::to_string(i) + "]", y_[i]);
    }
    for (std::size_t i = 1; i < x_.size(); ++i) {
      if (!(x_[i] > x_[i - 1])) {
        throw InputError("tabulated law: times[" + std::to_string(i) + "] = " + fmt(x_[i]) +
                         " is not greater than times[" + std::to_string(i - 1) +
                         "] = " + fmt(x_[i - 1]) + "; expected strictly increasing times");
      }
    }
    computeSecondDerivatives();
    const std::size_t n = x_.size();
    const double h0 = x_[1] - x_[0];
    const double hn = x_[n - 1] - x_[n - 2];
    // End slopes S'(x_0), S'(x_{n-1}) of the cubic pieces with M_0 = M_{n-1} = 0
    // (derivative of the piece formula in evaluate(): Press2007, eq. 3.3.5).
    slopeStart_ = (y_[1] - y_[0]) / h0 - h0 * m_[1] / 6.0;
    slopeEnd_ = (y_[n - 1] - y_[n - 2]) / hn + hn * m_[n - 2] / 6.0;
  }

  LawValue evaluate(double t) const override {
    const std::size_t n = x_.size();
    if (t < x_.front()) {  // linear extrapolation with the end slope, f'' = 0 (header)
      return {y_.front() + slopeStart_ * (t - x_.front()), slopeStart_, 0.0};
    }
    if (t > x_.back()) {
      return {y_.back() + slopeEnd_ * (t - x_.back()), slopeEnd_, 0.0};
    }
    // Interval [x_i, x_{i+1}] containing t; t == x_{n-1} falls into the last one.
    std::size_t i =
        static_cast<std::size_t>(std::upper_bound(x_.begin(), x_.end(), t) - x_.begin());
    i = std::min(std::max<std::size_t>(i, 1), n - 1) - 1;
    const double h = x_[i + 1] - x_[i];
    const double a = x_[i + 1] - t;
    const double b = t - x_[i];
    const double m0 = m_[i];
    const double m1 = m_[i + 1];
    // Cubic piece in second-derivative form (Press2007, eq. 3.3.3):
    // S = M_i a^3/(6h) + M_{i+1} b^3/(6h) + (y_i - M_i h^2/6) a/h + (y_{i+1} - M_{i+1} h^2/6) b/h.
    const double f = (m0 * a * a * a + m1 * b * b * b) / (6.0 * h) +
                     (y_[i] - m0 * h * h / 6.0) * (a / h) +
                     (y_[i + 1] - m1 * h * h / 6.0) * (b / h);
    // S' and S'' by differentiating the same formula (Press2007, eqs. 3.3.5, 3.3.6).
    const double df = (m1 * b * b - m0 * a * a) / (2.0 * h) + (y_[i + 1] - y_[i]) / h -
                      (m1 - m0) * h / 6.0;
    const double ddf = (m0 * a + m1 * b) / h;
    return {f, df, ddf};
  }
  std::string typeName() const override { return "tabulated"; }

 private:
  /// Second derivatives M_i at the knots of the natural spline (M_0 = M_{n-1} = 0):
  /// h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1}
  ///   = 6 ((y_{i+1} - y_i)/h_i - (y_i - y_{i-1})/h_{i-1}),  i = 1..n-2
  /// (Press2007, eq. 3.3.7), solved by the Thomas algorithm (Press2007, sec. 2.4). The system
  /// is strictly diagonally dominant, so elimination without pivoting is stable.
  void computeSecondDerivatives() {
    const std::size_t n = x_.size();
    m_.assign(n, 0.0);
    if (n < 3) return;  // two points: a straight line
    const std::size_t k = n - 2;  // unknowns M_1..M_{n-2}
    std::vector<double> diag(k), upper(k), rhs(k);
    for (std::size_t j = 0; j < k; ++j) {
      const std::size_t i = j + 1;
      const double hl = x_[i] - x_[i - 1];
      const double hr = x_[i + 1] - x_[i];
      diag[j] = 2.0 * (hl + hr);
      upper[j] = hr;  // coefficient of M_{i+1}; the sub-diagonal of row j+1 is also hr
      rhs[j] = 6.0 * ((y_[i + 1] - y_[i]) / hr - (y_[i] - y_[i - 1]) / hl);
    }
    // Forward elimination (Press2007, sec. 2.4): row j -= (lower_j / diag_{j-1}) row j-1,
    // lower_j = upper_{j-1}.
    for (std::size_t j = 1; j < k; ++j) {
      const double factor = upper[j - 1] / diag[j - 1];
      diag[j] -= factor * upper[j - 1];
      rhs[j] -= factor * rhs[j - 1];
    }
    // Back substitution.
    m_[k] = rhs[k - 1] / diag[k - 1];
    for (std::size_t j = k - 1; j-- > 0;) {
      m_[j + 1] = (rhs[j] - upper[j] * m_[j + 2]) / diag[j];
    }
  }

  std::vector<double> x_;
  std::vector<double> y_;
  std::vector<double> m_;  ///< second derivatives at the knots
  double slopeStart_ = 0.0;
  double slopeEnd_ = 0.0;
};

}  // namespace

TimeLawPtr makeConstantLaw(double value) { return std::make_shared<ConstantLaw>(value); }

TimeLawPtr makeConstantSpeedLaw(double speed, double initial) {
  return std::make_shared<ConstantSpeedLaw>(speed, initial);
}

TimeLawPtr makePolynomialLaw(std::vector<double> coefficients) {
  return std::make_shared<PolynomialLaw>(std::move(coefficients));
}

TimeLawPtr makeHarmonicLaw(double amplitude, double omega, double phase, double offset) {
  return std::make_shared<HarmonicLaw>(amplitude, omega, phase, offset);
}

TimeLawPtr makeSpinUpLaw(double speed, double rampTime, double initial) {
  return std::make_shared<SpinUpLaw>(speed, rampTime, initial);
}

TimeLawPtr makeTabulatedLaw(std::vector<double> times, std::vector<double> values) {
  return std::make_shared<TabulatedLaw>(std::move(times), std::move(values));
}

}  // namespace flexmbd
