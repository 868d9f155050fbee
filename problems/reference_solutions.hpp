// Closed-form reference solutions used by validation tests and benchmarks.
#pragma once

#include <cmath>

namespace flexmbd::reference {

/// Slider position, velocity and acceleration of a centred slider-crank (crank l1,
/// rod l2) at crank angle a turning at constant speed w (so a'' = 0):
/// eqs. 30-32 of source document 000 (Yamada & Tatsumi 1981), with the chain rule
/// for w != 1 (x' = dx/da w, x'' = d2x/da2 w^2).
struct SliderState {
  double x, xd, xdd;
};
inline SliderState sliderCrank(double l1, double l2, double a, double w = 1.0) {
  const double s = std::sin(a), c = std::cos(a);
  const double r = std::sqrt(l2 * l2 - l1 * l1 * s * s);
  const double x = l1 * c + r;                                     // eq. 30
  const double dx = -l1 * s - l1 * l1 * s * c / r;                 // eq. 31
  const double ddx = -l1 * c - l1 * l1 * (l1 * l1 * std::pow(s, 4) + l2 * l2 * std::cos(2 * a)) /
                                   (r * r * r);                    // eq. 32
  return {x, dx * w, ddx * w * w};
}

/// Period of a physical pendulum released from rest at amplitude phi0 (rad from the
/// downward vertical): T = 4 sqrt(Ip / (m g L)) K(sin(phi0/2)), K the complete elliptic
/// integral of the first kind, Ip the inertia about the pivot.
inline double pendulumPeriod(double m, double Ip, double L, double g, double phi0) {
  return 4.0 * std::sqrt(Ip / (m * g * L)) * std::comp_ellint_1(std::sin(0.5 * phi0));
}

}  // namespace flexmbd::reference
