/// @file
/// The strain energy of a two-node Euler-Bernoulli beam element, planar (N = 6 element
/// coordinates) or spatial (N = 12): one code for BeamElement2d and BeamElement3d.
///
/// Linear model: U = e^T K e / 2. With geometric stiffening the membrane strain is the
/// element-averaged second-order strain
///   eps_m = u' + (1/2l) int_0^l |w_perp'|^2 dx = a e + e^T G e / (2l)
/// (constant along the element; a = the axial strain row, G = int b^T b dx over the slope
/// rows b), and U = EA l eps_m^2 / 2 + e^T K_b e / 2 with K_b the bending (and torsion)
/// part of K. The pointwise u' + |w'|^2 / 2 cannot vanish in bending with a linear u and
/// cubic transverse fields and locks coarse meshes (membrane locking: StolarskiBelytschko1982;
/// Crisfield1991; docs/flexible-bodies.md).
#pragma once

#include <Eigen/Core>

namespace flexmbd {

template <int N>
class BeamStrainEnergy {
 public:
  using Vec = Eigen::Matrix<double, N, 1>;
  using Row = Eigen::Matrix<double, 1, N>;
  using Mat = Eigen::Matrix<double, N, N>;

  BeamStrainEnergy() = default;
  /// a: axial strain row; G: slope integral; K: linear stiffness; Kb: K with its axial
  /// entries zero; EA, N; l, m.
  BeamStrainEnergy(const Row& a, const Mat& G, const Mat& K, const Mat& Kb, double EA, double l)
      : a_(a), G_(G), K_(K), Kb_(Kb), EA_(EA), l_(l) {}

  const Mat& stiffness() const { return K_; }
  const Mat& slopeIntegral() const { return G_; }

  /// u' (linear) or eps_m (stiffening), dimensionless.
  double membraneStrain(const Vec& e, bool stiffening) const {
    const double du = a_.dot(e);
    if (!stiffening) return du;
    return du + 0.5 * e.dot(G_ * e) / l_;  // eps_m = a e + e^T G e / (2l)
  }
  /// U(e), J.
  double energy(const Vec& e, bool stiffening) const {
    if (!stiffening) return 0.5 * e.dot(K_ * e);  // U = e^T K e / 2
    const double eps = membraneStrain(e, true);
    return 0.5 * EA_ * l_ * eps * eps + 0.5 * e.dot(Kb_ * e);  // U = EA l eps_m^2 / 2 + e^T K_b e / 2
  }
  /// dU/de.
  Vec gradient(const Vec& e, bool stiffening) const {
    if (!stiffening) return K_ * e;
    const double eps = membraneStrain(e, true);
    const Vec d = a_.transpose() + G_ * e / l_;  // d eps_m / de
    return (EA_ * l_ * eps) * d + Kb_ * e;       // dU/de = EA l eps_m d + K_b e
  }
  /// d2U/de2.
  Mat hessian(const Vec& e, bool stiffening) const {
    if (!stiffening) return K_;
    const double eps = membraneStrain(e, true);
    const Vec d = a_.transpose() + G_ * e / l_;
    // d2U/de2 = EA l d d^T + EA eps_m G (geometric stiffness, N = EA eps_m) + K_b
    return (EA_ * l_) * d * d.transpose() + (EA_ * eps) * G_ + Kb_;
  }

 private:
  Row a_ = Row::Zero();
  Mat G_ = Mat::Zero(), K_ = Mat::Zero(), Kb_ = Mat::Zero();
  double EA_ = 0.0, l_ = 0.0;
};

}  // namespace flexmbd
