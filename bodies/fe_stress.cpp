#include "bodies/fe_stress.hpp"

#include <Eigen/QR>
#include <array>
#include <cmath>

#include "core/errors.hpp"
#include "core/number_text.hpp"

namespace flexmbd {

FeStressSamples joinedSamples(const FeStressSamples& a, const FeStressSamples& b) {
  FeStressSamples out;
  out.displacement.resize(a.displacement.rows(), a.displacement.cols() + b.displacement.cols());
  out.displacement << a.displacement, b.displacement;
  out.stress.resize(a.stress.rows(), a.stress.cols() + b.stress.cols());
  out.stress << a.stress, b.stress;
  return out;
}

MatX stressShapes(const FeBodyModel& model, const FeStressSamples& samples, const std::string& owner) {
  const MatX U = model.nodalMap() * model.basis();  // the coordinates' nodal displacements
  if (samples.displacement.rows() != U.rows()) {
    throw InputError(owner + ": stress samples of " + std::to_string(samples.displacement.rows()) +
                     " DOF for a body of " + std::to_string(U.rows()));
  }
  const Eigen::ColPivHouseholderQR<MatX> qr(samples.displacement);
  const MatX C = qr.solve(U);  // u = D c, least squares
  for (int j = 0; j < U.cols(); ++j) {
    const double miss = (samples.displacement * C.col(j) - U.col(j)).norm() / U.col(j).norm();
    if (!(miss <= kStressSpanTolerance)) {
      throw InputError(owner + ": the stress samples (" + std::to_string(samples.displacement.cols()) +
                       " displacement fields) do not span elastic coordinate " + std::to_string(j + 1) +
                       ": its displacement is missed by " + fmt(miss, 3) +
                       " of itself (expected <= 1e-3; give the FE code's results for the body's own reduction: "
                       "its modes with the same supports, and static cases at its interfaces)");
    }
  }
  return samples.stress * C;
}

double vonMises(const Eigen::Ref<const Eigen::Matrix<double, 6, 1>>& s) {
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

}  // namespace flexmbd
