#include "integrators/bdf_stability.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>


namespace flexmbd {

namespace {

/// cos(alpha_k): the smallest damping ratio inside BDF k's stability sector.
double sectorDampingRatio(int k) { return std::cos(kBdfStabilityAngleDegrees[k] * M_PI / 180.0); }

}  // namespace

std::string BdfOrderLimit::reason() const {
  if (body.empty()) return "";
  std::ostringstream os;
  os << "BDF order limited to " << order << ": body '" << body << "' has a mode with damping ratio " << dampingRatio
     << " (omega " << frequency << " rad/s) outside the stability sector of higher orders";
  return os.str();
}

BdfOrderLimit stableBdfOrder(const System& sys, int requested) {
  BdfOrderLimit limit;
  limit.order = requested;
  const double lightlyDamped = sectorDampingRatio(kLowestLimitedOrder);
  for (int b = 0; b < sys.numBodies() && limit.order > kLowestLimitedOrder; ++b) {
    const Body& body = sys.body(BodyIndex{b});
    const Body::ElasticMatrices em = body.elasticMatrices();
    if (!em.mass || !em.stiffness || !em.damping) continue;
    const int nf = static_cast<int>(em.mass->rows());
    if (nf == 0 || nf > kMaxModalAnalysisSize || em.damping->nonZeros() == 0) continue;
    const MatX D(*em.damping);
    if (D.cwiseAbs().maxCoeff() == 0.0) continue;
    // K phi = omega^2 M phi, phi^T M phi = 1 (GeradinRixen; M, K symmetric positive definite: validated)
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(MatX(*em.stiffness), MatX(*em.mass));
    if (eig.info() != Eigen::Success) continue;
    for (int i = 0; i < nf; ++i) {
      const double omega = std::sqrt(std::max(eig.eigenvalues()[i], 0.0));
      if (!(omega > 0.0)) continue;
      const auto phi = eig.eigenvectors().col(i);
      const double zeta = phi.dot(D * phi) / (2.0 * omega);
      if (zeta < lightlyDamped) continue;
      while (limit.order > kLowestLimitedOrder && zeta < sectorDampingRatio(limit.order)) {
        --limit.order;
        limit.body = body.name();
        limit.dampingRatio = zeta;
        limit.frequency = omega;
      }
    }
  }
  return limit;
}

}  // namespace flexmbd
