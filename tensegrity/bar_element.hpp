/// @file
/// Axially elastic bar (tensegrity strut) between two pin-joined nodes, in 2D or 3D.
/// Pure and const: the constant stiffness and mass are fixed at construction, the
/// geometric quantities are computed from the nodal positions passed in.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace flexmbd {

/// How a bar's own mass is distributed over its two nodes.
enum class BarMassModel {
  Lumped,      ///< m/2 at each node
  Consistent,  ///< linear interpolation: m/6 [2I I; I 2I]
};

template <int Dim>
class BarElement {
  static_assert(Dim == 2 || Dim == 3, "bars are planar or spatial");

 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  using NodalVec = Eigen::Matrix<double, 2 * Dim, 1>;
  using NodalMat = Eigen::Matrix<double, 2 * Dim, 2 * Dim>;

  /// @pre axialStiffness (EA) >= 0, naturalLength > 0, mass >= 0 (checked by the owner).
  BarElement(double axialStiffness, double naturalLength, double mass, BarMassModel massModel)
      : ea_(axialStiffness), l0_(naturalLength), mass_(mass), massModel_(massModel) {}

  double axialStiffness() const { return ea_; }
  double naturalLength() const { return l0_; }
  double mass() const { return mass_; }

  static double length(const Vec& xi, const Vec& xj) { return (xj - xi).norm(); }

  /// Axial force, tension positive, of a linear (engineering-strain) bar:
  ///   N = EA (l - l0) / l0                      (Doc001, strut law K_s u)
  double axialForce(double l) const { return ea_ * (l - l0_) / l0_; }

  /// Strain energy U = EA (l - l0)^2 / (2 l0), so that dU/dl = N (Doc001's strut law).
  double strainEnergy(double l) const { return 0.5 * ea_ * (l - l0_) * (l - l0_) / l0_; }

  /// Gradient of the length with respect to [xi; xj]: dl/dx = [-e; e], e = (xj - xi)/l (Doc001, eq. 6).
  /// @pre xi != xj
  static NodalVec lengthGradient(const Vec& xi, const Vec& xj) {
    const Vec e = (xj - xi).normalized();
    NodalVec b;
    b << -e, e;
    return b;
  }

  /// Internal (elastic) nodal forces g = dU/dx = N dl/dx; the equations of motion read
  /// M a = f - g (Doc001, eq. 6: the term K_s(u) u).
  NodalVec internalForces(const Vec& xi, const Vec& xj) const {
    return axialForce(length(xi, xj)) * lengthGradient(xi, xj);
  }

  /// Constant mass matrix of the bar's own mass (lumped or consistent).
  NodalMat massMatrix() const {
    NodalMat m = NodalMat::Zero();
    const auto I = Eigen::Matrix<double, Dim, Dim>::Identity();
    if (massModel_ == BarMassModel::Lumped) {
      m.template topLeftCorner<Dim, Dim>() = 0.5 * mass_ * I;
      m.template bottomRightCorner<Dim, Dim>() = 0.5 * mass_ * I;
    } else {
      // Linear shape functions N1 = 1 - s, N2 = s: int rho A N_a N_b dx = m/6 [2 1; 1 2]
      // (the bar's consistent mass, Przemieniecki1968).
      m.template topLeftCorner<Dim, Dim>() = (mass_ / 3.0) * I;
      m.template bottomRightCorner<Dim, Dim>() = (mass_ / 3.0) * I;
      m.template topRightCorner<Dim, Dim>() = (mass_ / 6.0) * I;
      m.template bottomLeftCorner<Dim, Dim>() = (mass_ / 6.0) * I;
    }
    return m;
  }

 private:
  double ea_, l0_, mass_;
  BarMassModel massModel_;
};

}  // namespace flexmbd
