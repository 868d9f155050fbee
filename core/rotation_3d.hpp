/// @file
/// Spatial rotations: the skew-symmetric matrix of a vector and the Euler parameters (unit
/// quaternion) of a rotation with their kinematic matrices (Nikravesh1988, ch. 6).
#pragma once

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/types.hpp"

namespace flexmbd {

using Vec4 = Eigen::Vector4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat4 = Eigen::Matrix4d;

/// a~ with a~ b = a x b (Nikravesh1988).
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

/// Rotation matrix of the Euler parameters p = (e0, e) normalised: A(p / |p|) = R(p) / |p|^2 with
/// R(p) = (e0^2 - e.e) I + 2 e e^T + 2 e0 e~ (Nikravesh1988, eq. 6.19). The length of p is a
/// gauge: no material point depends on it.
inline Mat3 quaternionRotation(const Vec4& p) {
  const double e0 = p[0];
  const Vec3 e = p.tail<3>();
  return ((e0 * e0 - e.dot(e)) * Mat3::Identity() + 2.0 * e * e.transpose() + 2.0 * e0 * skew(e)) / p.squaredNorm();
}

/// L(p) = [-e, e0 I - e~] (3 x 4): body-axes angular velocity w = 2 L(p) p' (unit p), and
/// p' = 1/2 L(p)^T w (Nikravesh1988, eqs. 6.39-6.41); L p = 0, L L^T = |p|^2 I.
inline Mat34 quaternionL(const Vec4& p) {
  Mat34 L;
  L.col(0) = -p.tail<3>();
  L.rightCols<3>() = p[0] * Mat3::Identity() - skew(p.tail<3>());
  return L;
}

/// W(w) with L(p)^T w = W(w) p (4 x 4): d(L(p)^T w)/dp for a fixed w.
inline Mat4 quaternionLTransposeJacobian(const Vec3& w) {
  Mat4 W;
  W(0, 0) = 0.0;
  W.block<1, 3>(0, 1) = -w.transpose();
  W.block<3, 1>(1, 0) = w;
  W.block<3, 3>(1, 1) = -skew(w);
  return W;
}

/// Euler parameters of the rotation by `angle` about the unit `axis`.
inline Vec4 quaternionFromAxisAngle(const Vec3& axis, double angle) {
  Vec4 p;
  p[0] = std::cos(0.5 * angle);
  p.tail<3>() = std::sin(0.5 * angle) * axis.normalized();
  return p;
}

/// Quaternion product p (x) r (composition of rotations: A(p (x) r) = A(p) A(r)).
inline Vec4 quaternionProduct(const Vec4& p, const Vec4& r) {
  Vec4 out;
  out[0] = p[0] * r[0] - p.tail<3>().dot(r.tail<3>());
  out.tail<3>() = p[0] * r.tail<3>() + r[0] * p.tail<3>() + p.tail<3>().cross(r.tail<3>());
  return out;
}

/// Euler parameters of a rotation matrix (Shepperd's method, Shepperd1978), e0 >= 0.
Vec4 quaternionFromRotation(const Mat3& A);

}  // namespace flexmbd
