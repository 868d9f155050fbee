// Helpers shared by the unit tests: seeded random numbers, central differences and
// matrix comparisons that print both sides on failure. Each test file keeps its own
// step sizes and tolerances (named, with their justification, next to the test).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/types.hpp"

namespace flexmbd::testsupport {

inline constexpr double kPi = 3.14159265358979323846;

/// Seeded random numbers (the same sequence on every run: reproducible tests).
class Random {
 public:
  explicit Random(unsigned seed) : gen_(seed) {}
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(gen_); }
  /// An angle anywhere on the circle.
  double angle() { return uniform(-kPi, kPi); }
  Vec2 vec2(double a, double b) { return Vec2(uniform(a, b), uniform(a, b)); }
  /// A frame state (x, y, theta) with the origin off the world origin.
  VecX frame() { return Eigen::Vector3d(uniform(-3.0, 3.0), uniform(-3.0, 3.0), angle()); }
  VecX vector(int n, double a, double b) {
    VecX x(n);
    for (int k = 0; k < n; ++k) x[k] = uniform(a, b);
    return x;
  }

 private:
  std::mt19937 gen_;
};

inline std::string show(const MatX& A) {
  std::ostringstream os;
  os.precision(12);
  os << A;
  return os.str();
}

/// Steps h_k = rel (1 + |x_k|) for central differences.
inline VecX relativeSteps(const VecX& x, double rel) { return rel * (VecX::Ones(x.size()) + x.cwiseAbs()); }

/// Central-difference Jacobian (m x n) of f at x with the steps h.
inline MatX fdJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, const VecX& steps) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (int k = 0; k < x.size(); ++k) {
    const double h = steps[k];
    VecX xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    J.col(k) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

/// Central-difference gradient (a column) of a scalar function.
inline VecX fdGradient(const std::function<double(const VecX&)>& f, const VecX& x, const VecX& steps) {
  return fdJacobian([&](const VecX& z) { return VecX::Constant(1, f(z)); }, x, steps).transpose();
}

/// max |A - B| <= tol * max(floor, max |A|, max |B|); prints both on failure and
/// returns the relative error.
inline double expectMatrixNear(const MatX& analytic, const MatX& reference, double tol, const std::string& what,
                               double floor = 0.0) {
  EXPECT_EQ(analytic.rows(), reference.rows()) << what;
  EXPECT_EQ(analytic.cols(), reference.cols()) << what;
  if (analytic.rows() != reference.rows() || analytic.cols() != reference.cols()) return 1.0;
  if (analytic.size() == 0) return 0.0;
  const double scale = std::max({floor, analytic.cwiseAbs().maxCoeff(), reference.cwiseAbs().maxCoeff(), 1e-300});
  const double err = (analytic - reference).cwiseAbs().maxCoeff();
  EXPECT_LE(err, tol * scale) << what << " (relative error " << err / scale << ")\nanalytic:\n"
                              << show(analytic) << "\nreference:\n"
                              << show(reference);
  return err / scale;
}

/// Row by row: max_j |A_ij - B_ij| <= tol * max(1, max_j |A_ij|, max_j |B_ij|), so rows
/// of very different size (masses, cj, stiffnesses) are each compared on their own
/// scale. Returns the largest relative error.
inline double expectRowsNear(const MatX& analytic, const MatX& reference, double tol, const std::string& what) {
  EXPECT_EQ(analytic.rows(), reference.rows()) << what;
  EXPECT_EQ(analytic.cols(), reference.cols()) << what;
  if (analytic.rows() != reference.rows() || analytic.cols() != reference.cols()) return 1.0;
  double worst = 0.0;
  for (int i = 0; i < analytic.rows(); ++i) {
    const double scale =
        std::max({1.0, analytic.row(i).cwiseAbs().maxCoeff(), reference.row(i).cwiseAbs().maxCoeff()});
    const double err = (analytic.row(i) - reference.row(i)).cwiseAbs().maxCoeff() / scale;
    worst = std::max(worst, err);
    EXPECT_LE(err, tol) << what << ", row " << i << "\nanalytic:\n"
                        << show(analytic.row(i)) << "\nreference:\n"
                        << show(reference.row(i));
  }
  return worst;
}

/// f throws an InputError whose message contains every fragment.
inline void expectInputError(const std::function<void()>& f, const std::vector<std::string>& fragments) {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown; expected one mentioning '" << fragments.front() << "'";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const std::string& frag : fragments) EXPECT_NE(msg.find(frag), std::string::npos) << "message: " << msg;
  }
}

}  // namespace flexmbd::testsupport
