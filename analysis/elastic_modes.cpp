#include "analysis/elastic_modes.hpp"

#include <Eigen/Dense>

#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"

namespace flexmbd {
namespace {

/// A beam model without reduction: each elastic coordinate is one nodal displacement
/// (its basis column holds a single 1).
template <class Model>
bool isNodalModel(const Model* model) {
  return model && model->basis().nonZeros() == model->numElastic();
}

bool hasNodalCoordinates(const Body& body) {
  if (const auto* b2 = dynamic_cast<const FfrBody2d*>(&body)) return isNodalModel(b2->beamModel());
  if (const auto* b3 = dynamic_cast<const FfrBody3d*>(&body)) return isNodalModel(b3->model());
  return false;
}

}  // namespace

std::vector<BodyModes> elasticModes(const System& sys, std::vector<std::string>* skipped, bool withShapes) {
  std::vector<BodyModes> out;
  for (int b = 0; b < sys.numBodies(); ++b) {
    const BodyIndex bi{b};
    const Body& body = sys.body(bi);
    const Body::ElasticMatrices em = body.elasticMatrices();
    if (!em.mass || !em.stiffness) continue;
    const int nf = static_cast<int>(em.mass->rows());
    if (nf == 0) continue;
    if (nf > kMaxElasticModesSize) {
      if (skipped) skipped->push_back(body.name());
      continue;
    }
    const MatX M(*em.mass);
    // K phi = omega^2 M phi, phi^T M phi = 1 (GeradinRixen; M, K symmetric, M positive definite: validated)
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(
        MatX(*em.stiffness), M, withShapes ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
    if (eig.info() != Eigen::Success) {
      if (skipped) skipped->push_back(body.name());
      continue;
    }
    BodyModes m;
    m.body = bi;
    m.name = body.name();
    // the elastic coordinates and velocities are the body's last nf
    m.coordinateOffset = sys.coordinateOffset(bi) + sys.numCoordinates(bi) - nf;
    m.velocityOffset = sys.velocityOffset(bi) + sys.numVelocities(bi) - nf;
    m.omega = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    if (withShapes) {
      m.shapes = eig.eigenvectors();
      m.projector = m.shapes.transpose() * M;
    }
    m.nodal = hasNodalCoordinates(body);
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace flexmbd
