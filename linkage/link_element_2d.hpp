/// @file
/// Planar rigid link element of the deformation-parameter formulation (Doc000, after
/// VanDerWerff1977).
#pragma once

#include <string>

#include <Eigen/Core>

#include "core/types.hpp"

namespace flexmbd {

/// Two nodes; nodal coordinates x = [x1, y1, beta1, x2, y2, beta2] (Doc000, eq. 2): the node
/// positions and the orientation angles of the element at its two ends. Three
/// deformation parameters (Doc000, eqs. 5-7), all zero for a rigid link:
///
///   eps1 = l - l0                      (elongation)
///   eps2 = (beta1 - beta) l0           (rotation of end 1 relative to the chord, x l0)
///   eps3 = (beta - beta2) l0           (rotation of end 2 relative to the chord, x l0)
///
/// with l the current node distance and beta the chord angle (Doc000, eqs. 9, 12, 13). Angle
/// differences are taken modulo 2 pi into (-pi, pi], so the end angles may be
/// continuous coordinates (a crank angle running past 2 pi).
///
/// Pure and const: the element holds only its reference length l0.
class LinkElement2d {
 public:
  using Vec3 = Eigen::Matrix<double, 3, 1>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat36 = Eigen::Matrix<double, 3, 6>;

  /// @throws InputError naming `owner` unless l0 is finite and > 0.
  LinkElement2d(double referenceLength, const std::string& owner);

  double referenceLength() const { return l0_; }

  /// Exact deformation parameters eps(x), Doc000, eqs. 5-7.
  Vec3 deformations(const Vec6& x) const;

  /// D(x) = d eps / d x at any x. With e = (c, s) the chord direction and l the current
  /// length:
  ///   row 1: [-c, -s, 0, c, s, 0]
  ///   row 2: (l0 / l) [-s, c, 0, s, -c, 0] + [0, 0, l0, 0, 0, 0]
  ///   row 3: (l0 / l) [s, -c, 0, -s, c, 0] + [0, 0, 0, 0, 0, -l0]
  /// At a rigid position (l = l0) this is the linearised matrix D^0 of Doc000, eq. 15.
  Mat36 jacobian(const Vec6& x) const;

  /// Doc000's eq. 15 exactly as printed: D^0 for chord angle beta0 and length l0.
  static Mat36 linearisedMatrix(double beta0, double l0);

  /// Second derivatives along a direction: component k is dx^T (d2 eps_k / dx2) dx,
  /// i.e. (dD/dalpha) x' for dx = x' (the term that makes the second-order transfer
  /// functions, Doc000, eq. 23). With dd = (dx2 - dx1, dy2 - dy1), n = (-s, c):
  ///   d2 l    = (n . dd)^2 / l,
  ///   d2 beta = -2 (e . dd)(n . dd) / l^2,
  /// so [d2 l, -l0 d2 beta, l0 d2 beta] (eps is linear in the end angles).
  Vec3 secondDerivative(const Vec6& x, const Vec6& dx) const;

  /// Chord angle beta of Doc000, eqs. 12-13 (atan2, in (-pi, pi]) and length l of eq. 9.
  static double chordAngle(const Vec6& x);
  static double chordLength(const Vec6& x);

 private:
  double l0_;
};

}  // namespace flexmbd
