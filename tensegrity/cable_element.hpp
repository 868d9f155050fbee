/// @file
/// Tension-only cable between two nodes, in 2D or 3D. Massless. Either elastic with
/// stiffness EA (piecewise-linear law: no force when slack) or inextensible (its length
/// can never exceed the natural length; its tension is a multiplier of the time-stepper).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace flexmbd {

template <int Dim>
class CableElement {
  static_assert(Dim == 2 || Dim == 3, "cables are planar or spatial");

 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  using NodalVec = Eigen::Matrix<double, 2 * Dim, 1>;

  /// @pre naturalLength > 0, axialStiffness > 0 unless inextensible (checked by the owner).
  CableElement(double axialStiffness, double naturalLength, bool inextensible)
      : ea_(axialStiffness), l0_(naturalLength), inextensible_(inextensible) {}

  double axialStiffness() const { return ea_; }
  double naturalLength() const { return l0_; }
  bool inextensible() const { return inextensible_; }

  static double length(const Vec& xi, const Vec& xj) { return (xj - xi).norm(); }

  /// Elongation e_c = l - l0 = e^e + e^s (Doc001, sec. 3.1): the elastic part e^e >= 0
  /// carries the tension, the slack part e^s <= 0 carries none.
  double elongation(double l) const { return l - l0_; }

  /// Tension of the elastic law tau = k_c e^e = (EA/l0) max(l - l0, 0) (Doc001, eq. 7).
  /// Zero for an inextensible cable (its tension comes from the LCP).
  double tension(double l) const {
    if (inextensible_) return 0.0;
    return ea_ * std::max(l - l0_, 0.0) / l0_;
  }

  /// Stored energy U = EA max(l - l0, 0)^2 / (2 l0) (dU/dl = tau of Doc001, eq. 7; zero when slack).
  double storedEnergy(double l) const {
    if (inextensible_) return 0.0;
    const double e = std::max(l - l0_, 0.0);
    return 0.5 * ea_ * e * e / l0_;
  }

  /// b_c = dl/dx = [-e; e], e = (xj - xi)/l: the cable's column of B_c^T (Doc001, eq. 6).
  static NodalVec lengthGradient(const Vec& xi, const Vec& xj) {
    const Vec e = (xj - xi).normalized();
    NodalVec b;
    b << -e, e;
    return b;
  }

 private:
  double ea_, l0_;
  bool inextensible_;
};

}  // namespace flexmbd
