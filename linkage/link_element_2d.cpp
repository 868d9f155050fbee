#include "linkage/link_element_2d.hpp"

#include <cmath>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

/// a modulo 2 pi, into [-pi, pi] (std::remainder is exact).
double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

LinkElement2d::LinkElement2d(double referenceLength, const std::string& owner) : l0_(referenceLength) {
  if (!std::isfinite(referenceLength)) {
    throw InputError("link '" + owner + "': length must be a finite number, got " + std::to_string(referenceLength));
  }
  if (!(referenceLength > 0.0)) {
    throw InputError("link '" + owner + "': length must be > 0 (a zero-length link has no direction), got " +
                     std::to_string(referenceLength));
  }
}

double LinkElement2d::chordAngle(const Vec6& x) { return std::atan2(x[4] - x[1], x[3] - x[0]); }

double LinkElement2d::chordLength(const Vec6& x) { return std::hypot(x[3] - x[0], x[4] - x[1]); }

LinkElement2d::Vec3 LinkElement2d::deformations(const Vec6& x) const {
  const double l = chordLength(x);
  const double beta = chordAngle(x);
  Vec3 eps;
  eps[0] = l - l0_;                        // Doc000, eq. 5
  eps[1] = wrapAngle(x[2] - beta) * l0_;   // Doc000, eq. 6
  eps[2] = wrapAngle(beta - x[5]) * l0_;   // Doc000, eq. 7
  return eps;
}

LinkElement2d::Mat36 LinkElement2d::jacobian(const Vec6& x) const {
  const double dx = x[3] - x[0], dy = x[4] - x[1];
  const double l = std::hypot(dx, dy);
  const double c = dx / l, s = dy / l, r = l0_ / l;
  Mat36 d;
  d << -c, -s, 0.0, c, s, 0.0,                       //
      -s * r, c * r, l0_, s * r, -c * r, 0.0,        //
      s * r, -c * r, 0.0, -s * r, c * r, -l0_;
  return d;
}

LinkElement2d::Mat36 LinkElement2d::linearisedMatrix(double beta0, double l0) {
  const double c = std::cos(beta0), s = std::sin(beta0);
  Mat36 d;  // Doc000, eq. 15
  d << -c, -s, 0.0, c, s, 0.0,  //
      -s, c, l0, s, -c, 0.0,    //
      s, -c, 0.0, -s, c, -l0;
  return d;
}

LinkElement2d::Vec3 LinkElement2d::secondDerivative(const Vec6& x, const Vec6& dx) const {
  const Vec2 d(x[3] - x[0], x[4] - x[1]);
  const double l = d.norm();
  const Vec2 e = d / l, n = perp(e);
  const Vec2 dd(dx[3] - dx[0], dx[4] - dx[1]);
  const double ed = e.dot(dd), nd = n.dot(dd);
  // second derivatives of eq. 9 and eqs. 12-13 along dx (Doc000, eq. 23's dD/dalpha)
  const double d2l = nd * nd / l;              // d/dalpha (e . dd) with de = n dbeta
  const double d2beta = -2.0 * ed * nd / (l * l);  // d/dalpha (n . dd / l)
  return Vec3(d2l, -l0_ * d2beta, l0_ * d2beta);
}

}  // namespace flexmbd
