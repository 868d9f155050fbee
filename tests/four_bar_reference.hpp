// Closed-form kinematics of a four-bar linkage by vector loop closure, independent of the
// deformation-parameter method: a reference for the kinematic analysis (source document
// 000, example 2) and for the driven dynamic model.
#pragma once

#include <cmath>

namespace flexmbd::reference {

/// Four-bar: ground pivots O1 = (0, 0) and O4 = (d, 0); crank O1O2 (length a) at angle
/// theta; coupler O2O3 (b); rocker O4O3 (c). `branch` = +1: O3 to the left of the
/// directed line O2 -> O4 (the upper assembly for theta = 0), -1: the other one.
struct FourBarState {
  double x, y;          ///< O3
  double vx, vy;        ///< velocity of O3
  double ax, ay;        ///< acceleration of O3
  double phi2, phi3;    ///< coupler angle (of O2 -> O3), rocker angle (of O4 -> O3)
  double w2, w3;        ///< their angular velocities
  double e2, e3;        ///< their angular accelerations
};

/// At crank angle theta, crank speed w and crank acceleration wd.
///
/// Position: O3 is the intersection of the circles (O2, b) and (O4, c): with
/// r = |O4 - O2|, u = (O4 - O2)/r, p = (b^2 - c^2 + r^2) / (2 r), h = sqrt(b^2 - p^2),
/// O3 = O2 + p u + branch h perp(u).
///
/// Velocity: the loop a e1 + b e2 = d ex + c e3 (e_k = (cos, sin) of link k, n_k its
/// perpendicular) differentiated: a w n1 + b w2 n2 - c w3 n3 = 0. Dotting with e3 and e2
/// (n_i . e_j = sin(phi_j - phi_i)):
///   w2 = -a w sin(phi3 - theta) / (b sin(phi3 - phi2)),
///   w3 =  a w sin(phi2 - theta) / (c sin(phi2 - phi3)).
/// Acceleration: a wd n1 - a w^2 e1 + b e2' n2 - b w2^2 e2 - c e3' n3 + c w3^2 e3 = 0,
/// dotted with e3 and e2 (e_i . e_j = cos(phi_j - phi_i)):
///   e2 = (-a wd sin(phi3 - theta) + a w^2 cos(phi3 - theta) + b w2^2 cos(phi3 - phi2) - c w3^2)
///        / (b sin(phi3 - phi2)),
///   e3 = (a wd sin(phi2 - theta) - a w^2 cos(phi2 - theta) - b w2^2 + c w3^2 cos(phi2 - phi3))
///        / (c sin(phi2 - phi3)).
/// O3 moves on the rocker's circle: v = c w3 n3, acc = c e3 n3 - c w3^2 e3.
inline FourBarState fourBar(double a, double b, double c, double d, double theta, double w = 1.0,
                            double wd = 0.0, int branch = 1) {
  const double o2x = a * std::cos(theta), o2y = a * std::sin(theta);
  const double dx = d - o2x, dy = -o2y;
  const double r = std::hypot(dx, dy);
  const double ux = dx / r, uy = dy / r;
  const double p = (b * b - c * c + r * r) / (2.0 * r);
  const double h = std::sqrt(b * b - p * p);
  FourBarState s{};
  s.x = o2x + p * ux - branch * h * uy;
  s.y = o2y + p * uy + branch * h * ux;
  s.phi2 = std::atan2(s.y - o2y, s.x - o2x);
  s.phi3 = std::atan2(s.y, s.x - d);
  const double s32 = std::sin(s.phi3 - s.phi2), s23 = -s32;
  s.w2 = -a * w * std::sin(s.phi3 - theta) / (b * s32);
  s.w3 = a * w * std::sin(s.phi2 - theta) / (c * s23);
  s.e2 = (-a * wd * std::sin(s.phi3 - theta) + a * w * w * std::cos(s.phi3 - theta) +
          b * s.w2 * s.w2 * std::cos(s.phi3 - s.phi2) - c * s.w3 * s.w3) /
         (b * s32);
  s.e3 = (a * wd * std::sin(s.phi2 - theta) - a * w * w * std::cos(s.phi2 - theta) - b * s.w2 * s.w2 +
          c * s.w3 * s.w3 * std::cos(s.phi2 - s.phi3)) /
         (c * s23);
  const double c3 = std::cos(s.phi3), n3x = -std::sin(s.phi3), n3y = c3;
  s.vx = c * s.w3 * n3x;
  s.vy = c * s.w3 * n3y;
  s.ax = c * s.e3 * n3x - c * s.w3 * s.w3 * c3;
  s.ay = c * s.e3 * n3y - c * s.w3 * s.w3 * std::sin(s.phi3);
  return s;
}

}  // namespace flexmbd::reference
