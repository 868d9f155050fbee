#include "bodies/ffr_body_2d.hpp"

#include <sstream>

#include "core/errors.hpp"

namespace flexmbd {
namespace {

void checkFrame(const std::string& who, const FrameState2d& s) {
  requireFinite(s.position.x(), who + ": position[0]");
  requireFinite(s.position.y(), who + ": position[1]");
  requireFinite(s.angle, who + ": angle");
  requireFinite(s.velocity.x(), who + ": velocity[0]");
  requireFinite(s.velocity.y(), who + ": velocity[1]");
  requireFinite(s.angularVelocity, who + ": angular_velocity");
}

const FfrBeamModel& requireModel(const std::shared_ptr<const FfrBeamModel>& model, const std::string& name) {
  if (!model) throw InputError("body '" + name + "': no beam model given");
  return *model;
}

}  // namespace

FfrBody2d::FfrBody2d(std::string name, FfrInvariants invariants, const FrameState2d& initial)
    : Body(std::move(name)), ownInvariants_(std::move(invariants)), inv_(ownInvariants_), initial_(initial) {
  inv_.validate("body '" + this->name() + "'");
  checkFrame("body '" + this->name() + "'", initial);
}

FfrBody2d::FfrBody2d(std::string name, std::shared_ptr<const FfrBeamModel> model, const FrameState2d& initial)
    : Body(std::move(name)), model_(std::move(model)), inv_(requireModel(model_, this->name()).invariants()),
      initial_(initial) {
  checkFrame("body '" + this->name() + "'", initial);
}

std::vector<std::string> FfrBody2d::coordinateNames() const {
  std::vector<std::string> n = {"x", "y", "theta"};
  for (int k = 1; k <= numElastic(); ++k) n.push_back("q" + std::to_string(k));
  return n;
}

FfrBody2d& FfrBody2d::setInitialElasticState(const VecX& qf, const VecX& qfDot) {
  const std::string who = "body '" + name() + "'";
  if (qf.size() != numElastic() || qfDot.size() != numElastic()) {
    throw InputError(who + ": initial elastic state must have " + std::to_string(numElastic()) + " entries, got " +
                     std::to_string(qf.size()) + " and " + std::to_string(qfDot.size()));
  }
  if (!qf.allFinite() || !qfDot.allFinite()) throw InputError(who + ": initial elastic state is not finite");
  initialQf_ = qf;
  initialQfDot_ = qfDot;
  return *this;
}

VecX FfrBody2d::initialCoordinates() const {
  VecX q = VecX::Zero(numCoordinates());
  q.head<2>() = initial_.position;
  q[2] = initial_.angle;
  if (initialQf_.size() == numElastic()) q.tail(numElastic()) = initialQf_;
  return q;
}

VecX FfrBody2d::initialVelocities() const {
  VecX v = VecX::Zero(numCoordinates());
  v.head<2>() = initial_.velocity;
  v[2] = initial_.angularVelocity;
  if (initialQfDot_.size() == numElastic()) v.tail(numElastic()) = initialQfDot_;
  return v;
}

MatX FfrBody2d::massMatrix(const ConstVecRef& q) const {
  const int nf = numElastic(), n = 3 + nf;
  const auto qf = q.tail(nf);
  const Mat2 A = rotation(q[2]);
  const Vec2 s = inv_.firstMoment + inv_.sBar * qf;
  MatX M = MatX::Zero(n, n);
  M(0, 0) = M(1, 1) = inv_.mass;
  M.block<2, 1>(0, 2) = perp(A * s);                        // m_R theta = S A s
  M.block(0, 3, 2, nf) = A * inv_.sBar;                     // m_Rf = A S-bar
  M(2, 2) = inv_.polarMoment + 2.0 * inv_.i1.dot(qf) + qf.dot(inv_.mff * qf);  // m_theta theta
  M.block(2, 3, 1, nf) = inv_.j0.transpose() + qf.transpose() * inv_.sTilde;   // m_theta f
  M.bottomRightCorner(nf, nf) = inv_.mff;
  M.block(3, 0, nf, 3) = M.block(0, 3, 3, nf).transpose();
  M.block<1, 2>(2, 0) = M.block<2, 1>(0, 2).transpose();
  return M;
}

void FfrBody2d::addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a, MatX& K) const {
  const int nf = numElastic();
  const auto qf = q.tail(nf);
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Mat2X ASb = A * inv_.sBar;
  Mat2X SASb(2, nf);
  for (int k = 0; k < nf; ++k) SASb.col(k) = perp(ASb.col(k));
  const Vec2 aR = a.head<2>();
  const double at = a[2];
  const auto af = a.tail(nf);
  // row R: (S A s) a_t + A S-bar a_f
  K.block<2, 1>(0, 2) += -As * at + SASb * af;
  K.block(0, 3, 2, nf) += SASb * at;
  // row theta: (S A s)^T a_R + m_tt a_t + m_tf a_f
  K(2, 2) += -As.dot(aR);
  K.block(2, 3, 1, nf) += aR.transpose() * SASb + 2.0 * at * (inv_.i1 + inv_.mff * qf).transpose() +
                          (inv_.sTilde * af).transpose();
  // rows f: S-bar^T A^T a_R + m_ft a_t + m_ff a_f
  K.block(3, 2, nf, 1) += SASb.transpose() * aR;
  K.block(3, 3, nf, nf) += inv_.sTilde.transpose() * at;
}

VecX FfrBody2d::elasticGradient(const VecX& qf) const {
  return model_ ? model_->strainEnergyGradient(qf) : VecX(inv_.kff * qf);
}

void FfrBody2d::addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const {
  const int nf = numElastic();
  const VecX qf = q.tail(nf);
  const auto p = v.tail(nf);
  const double w = v[2];
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Vec2 ASbp = A * (inv_.sBar * p);
  const VecX iu = inv_.i1 + inv_.mff * qf;  // int rho N^T u dV
  // Quadratic velocity vector Q_v = -int rho (dr/dq)^T (-A u w^2 + 2 S A N p w) dV
  Q.head<2>() += As * w * w - 2.0 * perp(ASbp) * w;
  Q[2] += -2.0 * w * iu.dot(p);
  Q.tail(nf) += w * w * iu + 2.0 * w * (inv_.sTilde * p);
  // elastic and damping forces
  Q.tail(nf) -= elasticGradient(qf) + inv_.dff * p;
}

void FfrBody2d::addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, MatX& dQdq,
                                          MatX& dQdv) const {
  const int nf = numElastic();
  const VecX qf = q.tail(nf);
  const auto p = v.tail(nf);
  const double w = v[2];
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Mat2X ASb = A * inv_.sBar;
  const Vec2 ASbp = ASb * p;
  Mat2X SASb(2, nf);
  for (int k = 0; k < nf; ++k) SASb.col(k) = perp(ASb.col(k));
  const VecX iu = inv_.i1 + inv_.mff * qf;
  // Q_R = A s w^2 - 2 S A S-bar p w
  dQdq.block<2, 1>(0, 2) += perp(As) * w * w + 2.0 * ASbp * w;
  dQdq.block(0, 3, 2, nf) += ASb * w * w;
  dQdv.block<2, 1>(0, 2) += 2.0 * As * w - 2.0 * perp(ASbp);
  dQdv.block(0, 3, 2, nf) += -2.0 * SASb * w;
  // Q_theta = -2 w iu^T p
  dQdq.block(2, 3, 1, nf) += -2.0 * w * (inv_.mff * p).transpose();
  dQdv(2, 2) += -2.0 * iu.dot(p);
  dQdv.block(2, 3, 1, nf) += -2.0 * w * iu.transpose();
  // Q_f = w^2 iu + 2 w S~ p - dU/dqf - D p
  const MatX Kt = model_ ? model_->strainEnergyHessian(qf) : inv_.kff;
  dQdq.block(3, 3, nf, nf) += w * w * inv_.mff - Kt;
  dQdv.block(3, 2, nf, 1) += 2.0 * w * iu + 2.0 * inv_.sTilde * p;
  dQdv.block(3, 3, nf, nf) += 2.0 * w * inv_.sTilde - inv_.dff;
}

void FfrBody2d::addGravityForce(const ConstVecRef& q, const Vec2& g, VecX& Q) const {
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  Q.head<2>() += inv_.mass * g;
  Q[2] += perp(As).dot(g);
  Q.tail(nf) += (A * inv_.sBar).transpose() * g;
}

void FfrBody2d::addGravityJacobian(const ConstVecRef& q, const Vec2& g, MatX& K) const {
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  const Mat2X ASb = A * inv_.sBar;
  Mat2X SASb(2, nf);
  for (int k = 0; k < nf; ++k) SASb.col(k) = perp(ASb.col(k));
  K(2, 2) += -As.dot(g);
  K.block(2, 3, 1, nf) += g.transpose() * SASb;
  K.block(3, 2, nf, 1) += SASb.transpose() * g;
}

double FfrBody2d::gravityPotential(const ConstVecRef& q, const Vec2& g) const {
  return -g.dot(inv_.mass * q.head<2>() + rotation(q[2]) * (inv_.firstMoment + inv_.sBar * q.tail(numElastic())));
}

double FfrBody2d::internalPotential(const ConstVecRef& q) const {
  const VecX qf = q.tail(numElastic());
  return model_ ? model_->strainEnergy(qf) : 0.5 * qf.dot(inv_.kff * qf);
}

int FfrBody2d::findPoint(const Vec2& point) const {
  double scale = 1.0;
  for (const auto& p : inv_.points) scale = std::max(scale, p.position.norm());
  for (size_t k = 0; k < inv_.points.size(); ++k) {
    if ((inv_.points[k].position - point).norm() <= 1e-9 * scale) return static_cast<int>(k);
  }
  return -1;
}

void FfrBody2d::checkAttachmentPoint(const Vec2& point, const std::string& user) const {
  if (findPoint(point) >= 0) return;
  std::ostringstream os;
  os << user << ": flexible body '" << name() << "' has no node at (" << point.x() << ", " << point.y()
     << "); joints and forces attach to nodes (";
  for (size_t k = 0; k < inv_.points.size() && k < 6; ++k) {
    os << (k ? ", " : "") << "(" << inv_.points[k].position.x() << ", " << inv_.points[k].position.y() << ")";
  }
  os << (inv_.points.size() > 6 ? ", ...)" : ")");
  throw InputError(os.str());
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const Vec2& point, bool withHessians) const {
  const int k = findPoint(point);
  if (k < 0) checkAttachmentPoint(point, "attachment");
  return pointKinematics(q, inv_.points[k], withHessians);
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const FfrPoint& pt, bool withHessians) const {
  // r = R + A u,  u = u0 + N qf;  dr/dtheta = S A u;  dr/dqf = A N;
  // d2r/dtheta2 = -A u;  d2r/dtheta dqf = S A N;  phi = theta + Nphi qf.
  const int nf = numElastic(), n = 3 + nf;
  const Mat2 A = rotation(q[2]);
  const Vec2 Au = A * (pt.position + pt.shape * q.tail(nf));
  const Mat2X AN = A * pt.shape;
  PointKinematics p;
  p.r = q.head<2>() + Au;
  p.phi = q[2] + pt.rotationShape.dot(q.tail(nf));
  p.Jr = Mat2X::Zero(2, n);
  p.Jr(0, 0) = p.Jr(1, 1) = 1.0;
  p.Jr.col(2) = perp(Au);
  p.Jr.rightCols(nf) = AN;
  p.Jphi = RowVecX::Zero(n);
  p.Jphi[2] = 1.0;
  p.Jphi.tail(nf) = pt.rotationShape;
  if (!withHessians) return p;
  p.Hrx = MatX::Zero(n, n);
  p.Hry = MatX::Zero(n, n);
  p.Hrx(2, 2) = -Au.x();
  p.Hry(2, 2) = -Au.y();
  for (int k = 0; k < nf; ++k) {
    const Vec2 s = perp(AN.col(k));
    p.Hrx(2, 3 + k) = p.Hrx(3 + k, 2) = s.x();
    p.Hry(2, 3 + k) = p.Hry(3 + k, 2) = s.y();
  }
  p.Hphi = MatX::Zero(n, n);
  return p;
}

Vec2 FfrBody2d::centreOfMass(const ConstVecRef& q) const {
  return q.head<2>() + rotation(q[2]) * (inv_.firstMoment + inv_.sBar * q.tail(numElastic())) / inv_.mass;
}

}  // namespace flexmbd
