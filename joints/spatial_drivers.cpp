#include "joints/spatial_drivers.hpp"

#include <cmath>

namespace flexmbd {

FramePairConstraint::FramePairConstraint(std::string name, BodyIndex bodyI, const JointFrame& frameI,
                                         BodyIndex bodyJ, const JointFrame& frameJ, const std::string& kind)
    : Constraint(std::move(name), {bodyI, bodyJ}), frameI_(frameI), frameJ_(frameJ) {
  const std::string who = kind + " '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  checkJointFrame(frameI, who + " frame 0");
  checkJointFrame(frameJ, who + " frame 1");
}

SpatialJointAngleDriver::SpatialJointAngleDriver(std::string name, BodyIndex bodyI, const JointFrame& frameI,
                                                 BodyIndex bodyJ, const JointFrame& frameJ, TimeLawPtr law)
    : LawDriver<FramePairConstraint>(std::move(law), std::move(name), bodyI, frameI, bodyJ, frameJ) {}

double SpatialJointAngleDriver::equationPeriod() const { return 2.0 * M_PI; }

void evaluateJointAngle(const BodyStates& bodies, const JointFrame& frameI, const JointFrame& frameJ,
                        KinematicsWork& w, double& theta, RowVecX& grad, MatX* H) {
  // theta = atan2(s, c), s = y_i . x_j, c = x_i . x_j;  r^2 = s^2 + c^2
  //   grad = (c G_s - s G_c) / r^2
  //   H = (c H_s - s H_c + G_s^T Gq_c - G_c^T Gq_s) / r^2 - grad^T (2 s Gq_s + 2 c Gq_c) / r^2,
  // with Gq = G T+ the coordinate gradients.
  FramePair pair(bodies, frameI, frameJ, H != nullptr, w);
  const int n = pair.numVelocities(), nq = pair.numCoordinates();
  double s = 0.0, c = 0.0;
  w.row.resize(n);
  w.row2.resize(n);
  if (H) {
    w.hessian.setZero(n, nq);
    H->setZero(n, nq);
  }
  pair.axisAxis(1, 0, s, w.row, H ? &w.hessian : nullptr);
  pair.axisAxis(0, 0, c, w.row2, H);
  const double r2 = s * s + c * c;
  theta = std::atan2(s, c);
  grad = (c * w.row - s * w.row2) / r2;
  if (!H) return;
  RowVecX &gqs = w.row3, &gqc = w.row4, &k = w.row5;
  gqs.noalias() = w.row * pair.Tinv();
  gqc.noalias() = w.row2 * pair.Tinv();
  k = (2.0 * s / r2) * gqs + (2.0 * c / r2) * gqc;
  *H = (c * w.hessian - s * *H) / r2;  // H held H_c
  H->noalias() -= grad.transpose() * k;
  gqs /= r2;
  gqc /= r2;
  H->noalias() += w.row.transpose() * gqc;
  H->noalias() -= w.row2.transpose() * gqs;
}

void SpatialJointAngleDriver::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  double theta = 0.0;
  if (withHessians) out.H.resize(1);
  evaluateJointAngle(bodies, frameI_, frameJ_, out.work, theta, out.work.row6, withHessians ? &out.H[0] : nullptr);
  out.h.setConstant(1, theta);
  out.G = out.work.row6;
}

SpatialJointDisplacementDriver::SpatialJointDisplacementDriver(std::string name, BodyIndex bodyI,
                                                               const JointFrame& frameI, BodyIndex bodyJ,
                                                               const JointFrame& frameJ, TimeLawPtr law)
    : LawDriver<FramePairConstraint>(std::move(law), std::move(name), bodyI, frameI, bodyJ, frameJ) {}

void SpatialJointDisplacementDriver::evaluate(const BodyStates& bodies, bool withHessians,
                                              ConstraintEvaluation& out) const {
  FramePair pair(bodies, frameI_, frameJ_, withHessians, out.work);
  const int n = pair.numVelocities(), nq = pair.numCoordinates();
  out.h.resize(1);
  out.G.resize(1, n);
  MatX* H = nullptr;
  if (withHessians) {
    out.H.resize(1);
    out.H[0].setZero(n, nq);
    H = &out.H[0];
  }
  pair.axisGap(2, out.h[0], out.G.row(0), H);
}

}  // namespace flexmbd
