#include "integrators/radau_coefficients.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.hpp"

namespace flexmbd {

namespace {

using LVec = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
using LMat = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;

/// Coefficients (ascending powers) of d^(s-1)/dx^(s-1) [x^(s-1) (x - 1)^s], whose roots
/// are the Radau IIA nodes (HairerWanner1996, IV.5, (5.3)).
LVec radauPolynomial(int s) {
  LVec p = LVec::Zero(2 * s);  // x^(s-1) (x - 1)^s: degree 2s - 1
  long double binom = 1.0L;
  for (int k = 0; k <= s; ++k) {
    p[s - 1 + k] = ((s - k) % 2 == 0 ? 1.0L : -1.0L) * binom;  // C(s, k) x^k (-1)^(s-k)
    binom = binom * (s - k) / (k + 1);
  }
  for (int r = 0; r < s - 1; ++r) {  // differentiate s - 1 times
    LVec q = LVec::Zero(p.size() - 1);
    for (int m = 1; m < p.size(); ++m) q[m - 1] = m * p[m];
    p = q;
  }
  return p;  // degree s
}

long double evaluate(const LVec& p, long double x, long double* derivative) {
  long double v = 0.0L, dv = 0.0L;
  for (int m = static_cast<int>(p.size()) - 1; m >= 0; --m) {
    dv = dv * x + v;
    v = v * x + p[m];
  }
  *derivative = dv;
  return v;
}

/// The s real roots in (0, 1]: eigenvalues of the companion matrix, polished by Newton.
LVec radauNodes(int s) {
  const LVec p = radauPolynomial(s);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(s, s);
  for (int i = 1; i < s; ++i) companion(i, i - 1) = 1.0;
  for (int i = 0; i < s; ++i) companion(i, s - 1) = -static_cast<double>(p[i] / p[s]);
  const Eigen::VectorXcd roots = companion.eigenvalues();
  LVec c(s);
  for (int i = 0; i < s; ++i) {
    long double x = roots[i].real();
    for (int it = 0; it < 20; ++it) {
      long double dp = 0.0L;
      const long double v = evaluate(p, x, &dp);
      if (dp == 0.0L) break;
      x -= v / dp;
    }
    c[i] = x;
  }
  std::sort(c.data(), c.data() + s);
  c[s - 1] = 1.0L;  // exact
  return c;
}

}  // namespace

RadauVector RadauCoefficients::lagrange(double x) const {
  RadauVector powers(stages);
  double xp = 1.0;
  for (int k = 0; k < stages; ++k) powers[k] = (xp *= x);
  return P.transpose() * powers;
}

RadauVector RadauCoefficients::lagrangeDerivative(double x) const {
  RadauVector powers(stages);
  double xp = 1.0;
  for (int k = 0; k < stages; ++k) {
    powers[k] = (k + 1) * xp;
    xp *= x;
  }
  return P.transpose() * powers;
}

double RadauCoefficients::lagrangeOfStart(double x) const {
  double v = 1.0;
  for (int i = 0; i < stages; ++i) v *= (x - c[i]) / (-c[i]);
  return v;
}

namespace {

RadauCoefficients compute(int s) {
  RadauCoefficients r;
  r.stages = s;
  r.pairs = (s - 1) / 2;
  const LVec c = radauNodes(s);
  // A = Q V^-1 with V_ik = c_i^k and Q_ik = c_i^(k+1) / (k + 1): a_ij = int_0^c_i l_j
  // (HairerWanner1996, IV.5, (5.4))
  LMat V(s, s), Q(s, s), C(s, s);
  for (int i = 0; i < s; ++i) {
    long double xp = 1.0L;
    for (int k = 0; k < s; ++k) {
      V(i, k) = xp;
      xp *= c[i];
      Q(i, k) = xp / (k + 1);
      C(i, k) = xp;  // c_i^(k+1): the collocation polynomial's basis without constant term
    }
  }
  const LMat A = Q * V.inverse();
  const LMat W = A.inverse();
  r.c = c.cast<double>();
  r.A = A.cast<double>();
  r.W = W.cast<double>();
  r.P = C.inverse().cast<double>();

  // A^-1 has one real eigenvalue gamma and pairs alpha +- i beta (HairerWanner1996, IV.8, (8.15)). With the
  // eigenvector v = a + i b of alpha + i beta (beta > 0): W a = alpha a - beta b and
  // W b = beta a + alpha b, so T = [v_gamma, a_1, b_1, ...] gives the block diagonal (8.16).
  const Eigen::MatrixXd Wd = r.W;
  const Eigen::EigenSolver<Eigen::MatrixXd> es(Wd);
  r.T.resize(s, s);
  r.alpha.resize(r.pairs);
  r.beta.resize(r.pairs);
  int pair = 0;
  for (int k = 0; k < s; ++k) {
    const auto lambda = es.eigenvalues()[k];
    if (std::abs(lambda.imag()) < 1e-10 * std::abs(lambda)) {
      r.gamma = lambda.real();
      r.T.col(0) = es.eigenvectors().col(k).real();
    } else if (lambda.imag() > 0.0) {
      r.alpha[pair] = lambda.real();
      r.beta[pair] = lambda.imag();
      r.T.col(1 + 2 * pair) = es.eigenvectors().col(k).real();
      r.T.col(2 + 2 * pair) = es.eigenvectors().col(k).imag();
      ++pair;
    }
  }
  r.Tinv = r.T.inverse();

  // Embedded method of order s (HairerWanner1996, IV.8, (8.17)):
  // yhat_1 = y0 + h (gamma0 y'_0 + sum bhat_i Y'_i)
  // with gamma0 = 1/gamma and sum_i bhat_i c_i^(q-1) + gamma0 0^(q-1) = 1/q, q = 1..s;
  // yhat_1 - y_1 = gamma0 h y'_0 + sum_j d_j Z_j with d = W^T (bhat - b) (8.18).
  LVec rhs(s);
  for (int q = 1; q <= s; ++q) rhs[q - 1] = 1.0L / q;
  rhs[0] -= 1.0L / static_cast<long double>(r.gamma);
  const LVec bhat = V.transpose().partialPivLu().solve(rhs);
  const LVec b = A.row(s - 1).transpose();
  r.d = (W.transpose() * (bhat - b)).cast<double>();

  // where the interpolation error factor x prod (x - c_i) peaks on [0, 1]: a fine scan,
  // then golden-section refinement in the neighbouring cells
  auto psi = [&](double x) {
    double v = x;
    for (int i = 0; i < s; ++i) v *= x - r.c[i];
    return std::abs(v);
  };
  constexpr int kScan = 2000;
  int best = 0;
  for (int k = 1; k <= kScan; ++k) {
    if (psi(static_cast<double>(k) / kScan) > psi(static_cast<double>(best) / kScan)) best = k;
  }
  double lo = std::max(0.0, (best - 1.0) / kScan), hi = std::min(1.0, (best + 1.0) / kScan);
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int it = 0; it < 60; ++it) {
    const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    if (psi(x1) > psi(x2)) hi = x2;  // the peak lies in [lo, x2]
    else lo = x1;
  }
  r.xDense = 0.5 * (lo + hi);
  return r;
}

}  // namespace

const RadauCoefficients& RadauCoefficients::get(int stages) {
  static const RadauCoefficients k3 = compute(3), k5 = compute(5), k7 = compute(7);
  switch (stages) {
    case 3: return k3;
    case 5: return k5;
    case 7: return k7;
    default: throw InputError("Radau IIA: " + std::to_string(stages) + " stages; expected 3, 5 or 7");
  }
}

}  // namespace flexmbd
