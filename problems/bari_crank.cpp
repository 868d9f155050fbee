#include "problems/bari_crank.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <unsupported/Eigen/AutoDiff>

namespace flexmbd::bari {
namespace {

// Constants of the test set (shared/benchmarks/simeon-slider-crank.md). PI is the test
// set's truncated value: part of its definition.
constexpr double PI = 3.1415927;
constexpr double L1 = 0.15, L2 = 0.30, b = 0.008, h = 0.008, E = 2e11, rho = 7870.0;
constexpr double Omega = 150.0;
constexpr double J1 = 0.002727;
constexpr double M2 = rho * b * h * L2, J2 = M2 * (L2 * L2 / 3.0 + h * h / 12.0), M3 = 0.5 * M2;
constexpr double F_ = rho * b * h * L2, K_ = E * b * h / L2, B_ = b * h * L2;

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

struct RodMatrices {
  Mat4 MQ, KQ, BQ;
  Vec4 c1, c2, c12, c21;
  RodMatrices() {
    // MQ = F blockdiag(1/2, 1/2, [[8, 1], [1, 2]]): the axial block is 15 times the
    // consistent one (the test set's definition).
    MQ << F_ / 2, 0, 0, 0, 0, F_ / 2, 0, 0, 0, 0, 8 * F_, F_, 0, 0, F_, 2 * F_;
    const double r2 = (h / L2) * (h / L2);
    KQ << K_ * std::pow(PI, 4) / 24 * r2, 0, 0, 0,  //
        0, K_ * 2 * std::pow(PI, 4) / 3 * r2, 0, 0,   //
        0, 0, K_ * 16.0 / 3, -K_ * 8.0 / 3,           //
        0, 0, -K_ * 8.0 / 3, K_ * 7.0 / 3;
    c1 << 0, 0, B_ * 2.0 / 3, B_ / 6;
    c2 << B_ * 2 / PI, 0, 0, 0;
    c12 << 0, 0, B_ * L2 / 3, B_ * L2 / 6;
    c21 << B_ * L2 / PI, -B_ * L2 / (2 * PI), 0, 0;
    BQ.setZero();
    BQ(0, 2) = -16 / std::pow(PI, 3) * B_;
    BQ(0, 3) = (8 / std::pow(PI, 3) - 1 / PI) * B_;
    BQ(1, 3) = 1 / (2 * PI) * B_;
    BQ = (BQ - BQ.transpose()).eval();  // skew-symmetric
  }
};

const RodMatrices& rod() {
  static const RodMatrices m;
  return m;
}

/// Rows 14..23 of F (M w - f + G^T lambda; G v - (0, 0, Omega)) from y; any scalar type.
template <class S>
void dynamicRows(const S* y, S* out) {
  using std::cos;
  using std::sin;
  const RodMatrices& R = rod();
  const S& phi1 = y[0];
  const S& phi2 = y[1];
  const Eigen::Matrix<S, 4, 1> q(y[3], y[4], y[5], y[6]);
  const S& dphi1 = y[7];
  const S& dphi2 = y[8];
  const Eigen::Matrix<S, 4, 1> dq(y[10], y[11], y[12], y[13]);
  const Eigen::Matrix<S, 7, 1> w = Eigen::Map<const Eigen::Matrix<S, 7, 1>>(y + 14);
  const Eigen::Matrix<S, 3, 1> lambda(y[21], y[22], y[23]);
  const S s = sin(phi1 - phi2), c = cos(phi1 - phi2);
  const S c1q = R.c1.cast<S>().dot(q), c2q = R.c2.cast<S>().dot(q), c12q = R.c12.cast<S>().dot(q);
  const Eigen::Matrix<S, 4, 1> MQq = R.MQ.cast<S>() * q;
  // Mass matrix (Simeon 1996; test set "crank")
  Eigen::Matrix<S, 7, 7> M = Eigen::Matrix<S, 7, 7>::Zero();
  M(0, 0) = S(J1 + M2 * L1 * L1);
  M(0, 1) = 0.5 * L1 * L2 * M2 * c + rho * L1 * (s * c2q + c * c1q);
  M(1, 1) = J2 + q.dot(MQq) + 2 * rho * c12q;
  M(2, 2) = S(M3);
  const Eigen::Matrix<S, 4, 1> qBQ = R.BQ.transpose().cast<S>() * q;  // (q^T BQ)_i
  for (int i = 0; i < 4; ++i) {
    M(0, 3 + i) = rho * L1 * (-s * R.c1[i] + c * R.c2[i]);
    M(1, 3 + i) = rho * (R.c21[i] + qBQ[i]);
    for (int j = 0; j < 4; ++j) M(3 + i, 3 + j) = S(R.MQ(i, j));
  }
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < i; ++j) M(i, j) = M(j, i);
  }
  // Force vector
  Eigen::Matrix<S, 7, 1> f;
  const S c1dq = R.c1.cast<S>().dot(dq), c2dq = R.c2.cast<S>().dot(dq), c12dq = R.c12.cast<S>().dot(dq);
  f[0] = -0.5 * L1 * L2 * M2 * dphi2 * dphi2 * s + rho * L1 * dphi2 * dphi2 * (-s * c1q + c * c2q) -
         2 * rho * L1 * dphi2 * (c * c1dq + s * c2dq);
  f[1] = 0.5 * L1 * L2 * M2 * dphi1 * dphi1 * s + rho * L1 * dphi1 * dphi1 * (s * c1q - c * c2q) -
         2 * rho * dphi2 * c12dq - 2 * dphi2 * dq.dot(MQq);
  f[2] = S(0.0);
  const Eigen::Matrix<S, 4, 1> BQdq = R.BQ.cast<S>() * dq, KQq = R.KQ.cast<S>() * q;
  for (int i = 0; i < 4; ++i) {
    f[3 + i] = dphi2 * dphi2 * MQq[i] +
               rho * (dphi2 * dphi2 * R.c12[i] + L1 * dphi1 * dphi1 * (c * R.c1[i] + s * R.c2[i]) + 2 * dphi2 * BQdq[i]) -
               KQq[i];
  }
  // Constraint Jacobian G (3 x 7)
  Eigen::Matrix<S, 3, 7> G = Eigen::Matrix<S, 3, 7>::Zero();
  G(0, 0) = L1 * cos(phi1);
  G(0, 1) = (L2 + q[3]) * cos(phi2);
  G(0, 6) = sin(phi2);
  G(1, 0) = L1 * sin(phi1);
  G(1, 1) = (L2 + q[3]) * sin(phi2);
  G(1, 2) = S(1.0);
  G(1, 6) = -cos(phi2);
  G(2, 0) = S(1.0);
  const Eigen::Matrix<S, 7, 1> v = Eigen::Map<const Eigen::Matrix<S, 7, 1>>(y + 7);
  Eigen::Map<Eigen::Matrix<S, 7, 1>> dyn(out);
  dyn = M * w - f + G.transpose() * lambda;
  Eigen::Map<Eigen::Matrix<S, 3, 1>> gv(out + 7);
  gv = G * v;
  gv[2] -= Omega;
}

using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, HandCodedCrank::kSize, 1>>;

}  // namespace

double significantDigits(const std::array<double, 6>& p) {
  double err = 0.0;
  for (int k = 0; k < 6; ++k) {
    err = std::max(err, std::abs(p[k] - kReferencePositions[k]) / std::abs(kReferencePositions[k]));
  }
  return -std::log10(err);
}

HandCodedCrank::HandCodedCrank() {
  std::vector<std::pair<int, int>> entries;
  for (int k = 0; k < 14; ++k) {
    entries.emplace_back(k, k);      // cj
    entries.emplace_back(k, k + 7);  // -1
  }
  for (int r = 14; r < kSize; ++r) {
    for (int c = 0; c < kSize; ++c) entries.emplace_back(r, c);
  }
  pattern_ = SparsePattern(kSize, std::move(entries));
}

VecX HandCodedCrank::differentialIds() const {
  VecX id = VecX::Zero(kSize);
  id.head(14).setOnes();
  return id;
}

void HandCodedCrank::residual(double, const double* y, const double* yp, double* F, DaeScratch&) const {
  for (int k = 0; k < 14; ++k) F[k] = yp[k] - y[k + 7];
  dynamicRows(y, F + 14);
}

void HandCodedCrank::jacobian(double, const double* y, const double*, double cj, JacobianSink& J,
                              DaeScratch&) const {
  for (int k = 0; k < 14; ++k) {
    J.add(k, k, cj);
    J.add(k, k + 7, -1.0);
  }
  Dual yd[kSize], out[10];
  for (int k = 0; k < kSize; ++k) yd[k] = Dual(y[k], kSize, k);
  dynamicRows(yd, out);
  for (int c = 0; c < kSize; ++c) {
    double col[10];
    for (int r = 0; r < 10; ++r) col[r] = out[r].derivatives()[c];
    J.addColumn(c, 14, nullptr, col, 10, 1.0);
  }
}

void HandCodedCrank::initialValues(VecX& y0, VecX& yp0) {
  y0.resize(kSize);
  // p, q, p', q', w, lambda (consistent; shared/benchmarks/simeon-slider-crank.md)
  y0 << 0.0, 0.0, 0.450016933, 0.0, 0.0, 1.03339863e-5, 1.69327969e-5,  //
      150.0, -74.99576703969453, -2.68938672e-6, 0.4448961125816005, 4.634339319238007e-3, -1.78591076e-6,
      -2.68938672e-6,  //
      0.0, -1.3445415767203137e-3, -5.0621949247603625e+3, -6.8297253631324913e-5, -6.1271283043579049e-21,
      -4.2684630422777090, 2.0983363276459535e-1,  //
      -6.5527465619866792e-8, 3.8245895095549486e+2, -4.6359378247736649e-9;
  yp0 = VecX::Zero(kSize);
  yp0.head(14) = y0.segment(7, 14);
}

std::array<double, 6> HandCodedCrank::positions(const VecX& y) {
  return {y[1], y[2], y[3], y[4], y[5], y[6]};
}

}  // namespace flexmbd::bari
