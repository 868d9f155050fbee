/// @file
/// Basic types of the engine: Eigen aliases, planar rotation helpers, typed indices.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cmath>
#include <string>

namespace flexmbd {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using RowVecX = Eigen::RowVectorXd;
using Mat2X = Eigen::Matrix<double, 2, Eigen::Dynamic>;
using ConstVecRef = Eigen::Ref<const VecX>;
using SpMat = Eigen::SparseMatrix<double>;  ///< column-major sparse matrix

/// Planar rotation matrix A(theta).
inline Mat2 rotation(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Mat2 a;
  a << c, -s, s, c;
  return a;
}

/// Counter-clockwise perpendicular S v = (-v_y, v_x); note dA/dtheta = S A (Nikravesh1988).
inline Vec2 perp(const Vec2& v) { return Vec2(-v.y(), v.x()); }

/// A planar vector in the x-y plane of space.
inline Vec3 lift(const Vec2& v) { return Vec3(v.x(), v.y(), 0.0); }

/// Planar cross product a x b (a scalar).
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// An index that cannot be mixed up with an index of another kind.
template <class Tag>
struct TypedIndex {
  int value = -1;
  constexpr TypedIndex() = default;
  constexpr explicit TypedIndex(int v) : value(v) {}
  constexpr bool valid() const { return value >= 0; }
  constexpr bool operator==(TypedIndex o) const { return value == o.value; }
  constexpr bool operator!=(TypedIndex o) const { return value != o.value; }
};

using BodyIndex = TypedIndex<struct BodyTag>;
using ConstraintIndex = TypedIndex<struct ConstraintTag>;
using ForceIndex = TypedIndex<struct ForceTag>;

/// The ground is body 0 of every system; it has no coordinates.
inline constexpr BodyIndex kGround{0};

/// Throws InputError naming `what` unless x is finite.
void requireFinite(double x, const std::string& what);
/// Throws InputError naming `what` unless x > 0 and finite.
void requirePositive(double x, const std::string& what);
/// Throws InputError naming `what` unless x >= 0 and finite.
void requireNonNegative(double x, const std::string& what);

}  // namespace flexmbd
