#include "sensitivity/modal_sensitivity.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/LU>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

using CMat = Eigen::MatrixXcd;
using CVec = Eigen::VectorXcd;

/// Shift of the inverse iteration off the computed eigenvalue, relative to |s| (and to the
/// model's frequency scale for s ~ 0): Q(s) is singular to round-off at s itself; at this
/// distance it is invertible and one iteration reduces the other eigenvectors' components by
/// the shift over the gap to the next eigenvalue (<= 1e-8 / kRepeatedEigenvalueFraction).
constexpr double kInverseIterationShift = 1e-10;
/// Inverse iterations (each multiplies the error by shift / gap; two leave round-off).
constexpr int kInverseIterations = 3;

/// The null vector of the nearly singular A by inverse iteration from a fixed start.
CVec nullVector(const Eigen::PartialPivLU<CMat>& lu, Eigen::Index n) {
  CVec x(n);
  for (Eigen::Index k = 0; k < n; ++k) x[k] = std::complex<double>(std::cos(1.3 * k + 0.1), std::sin(0.7 * k + 0.2));
  for (int it = 0; it < kInverseIterations; ++it) {
    x = lu.solve(x);
    x /= x.norm();
  }
  return x;
}

}  // namespace

std::vector<ModeDerivative> modeDerivatives(const LinearizedSystem& lin, const ReducedSystem& red,
                                            const std::vector<Mode>& modes,
                                            const std::array<LinearizedSystem, kStencilPoints>& perturbed, double h) {
  for (const LinearizedSystem& p : perturbed) {
    if (p.M.rows() != lin.M.rows() || p.G.rows() != lin.G.rows()) {
      throw InputError("eigenvalue sensitivity: the perturbed model has " + std::to_string(p.M.rows()) +
                       " velocities and " + std::to_string(p.G.rows()) + " constraint equations, the model " +
                       std::to_string(lin.M.rows()) + " and " + std::to_string(lin.G.rows()));
    }
  }
  // the reduced matrices at p + o_j h in the base's basis moved onto their null spaces
  const std::vector<int> dep = dependentVelocities(lin);
  std::array<ReducedSystem, kStencilPoints> r;
  for (std::size_t j = 0; j < kStencilPoints; ++j) r[j] = reduceNear(perturbed[j], red.N, dep);
  // five-point differences (AbramowitzStegun1964, eq. 25.3.6): error h^4 |d5K/dp5| / 30
  // + 0.95 eps |K| / h (docs/modes.md)
  const auto at = [&](int j) -> const ReducedSystem& { return r[static_cast<std::size_t>(j)]; };
  const MatX dM = stencilDerivative<MatX>(h, [&](int j) { return MatX(at(j).M); });
  const MatX dC = stencilDerivative<MatX>(h, [&](int j) { return MatX(at(j).C); });
  const MatX dK = stencilDerivative<MatX>(h, [&](int j) { return MatX(at(j).K); });
  const CMat M = MatX(red.M).cast<std::complex<double>>(), C = MatX(red.C).cast<std::complex<double>>(),
             K = MatX(red.K).cast<std::complex<double>>();
  const Eigen::Index n = M.rows();
  double largest = 0.0;
  for (const Mode& m : modes) largest = std::max(largest, std::abs(m.eigenvalue));
  std::vector<ModeDerivative> out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const std::complex<double> s = modes[k].eigenvalue;
    ModeDerivative d;
    if (s == 0.0) {  // a rigid-body mode stays at zero (the parameter keeps the structure)
      out.push_back(d);
      continue;
    }
    for (std::size_t j = 0; j < modes.size(); ++j) {
      if (j != k && std::abs(modes[j].eigenvalue - s) <= kRepeatedEigenvalueFraction * std::abs(s)) d.defined = false;
    }
    if (!d.defined) {
      d.eigenvalue = {nan, nan};
      d.omega = d.frequencyHz = d.dampingRatio = nan;
      out.push_back(d);
      continue;
    }
    const std::complex<double> sigma = s + kInverseIterationShift * std::max(std::abs(s), largest);
    const CMat Q = sigma * sigma * M + sigma * C + K;
    const CVec x = nullVector(Eigen::PartialPivLU<CMat>(Q), n);
    const CVec w = nullVector(Eigen::PartialPivLU<CMat>(Q.transpose()), n);
    // d/dp [w^T Q(s, p) x] = 0: ds/dp = -w^T (s^2 dM + s dC + dK) x / w^T (2 s M + C) x
    // (left and right eigenvectors: TisseurMeerbergen2001, sec. 3)
    const CMat dQ = (s * s) * dM.cast<std::complex<double>>() + s * dC.cast<std::complex<double>>() +
                    dK.cast<std::complex<double>>();
    const std::complex<double> num = (w.transpose() * dQ * x)(0, 0);
    const std::complex<double> den = (w.transpose() * ((2.0 * s) * M + C) * x)(0, 0);
    d.eigenvalue = -num / den;
    const double r = std::abs(s);
    d.omega = std::real(std::conj(s) * d.eigenvalue) / r;  // d|s| = Re(conj(s) ds) / |s|
    d.frequencyHz = d.omega / (2.0 * M_PI);
    // zeta = -Re(s) / |s|: dzeta = -Re(ds) / |s| + Re(s) d|s| / |s|^2
    d.dampingRatio = -d.eigenvalue.real() / r + s.real() * d.omega / (r * r);
    out.push_back(d);
  }
  return out;
}

}  // namespace flexmbd
