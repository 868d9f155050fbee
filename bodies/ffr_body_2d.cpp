#include "bodies/ffr_body_2d.hpp"

#include <numeric>
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

Eigen::Matrix3d FfrBody2d::frameMass(const ConstVecRef& q) const {
  // m_RR = m I, m_R theta = S A s, m_theta theta = I0 + 2 I1.qf + qf^T m_ff qf
  const auto qf = q.tail(numElastic());
  const Vec2 sas = perp(rotation(q[2]) * (inv_.firstMoment + inv_.sBar * qf));
  Eigen::Matrix3d M;
  M << inv_.mass, 0.0, sas.x(),  //
      0.0, inv_.mass, sas.y(),   //
      sas.x(), sas.y(), inv_.polarMoment + 2.0 * inv_.i1.dot(qf) + qf.dot(inv_.mff * qf);
  return M;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> FfrBody2d::frameElasticMass(const ConstVecRef& q) const {
  // m_Rf = A S-bar, m_theta f = J0^T + qf^T S~
  const int nf = numElastic();
  Eigen::Matrix<double, 3, Eigen::Dynamic> M(3, nf);
  M.topRows<2>() = rotation(q[2]) * inv_.sBar;
  M.row(2) = inv_.j0.transpose() + (inv_.sTilde.transpose() * q.tail(nf)).transpose();
  return M;
}

void FfrBody2d::addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const {
  const auto Mrf = frameElasticMass(q);
  M.addBlock(0, 0, frameMass(q));
  M.addBlock(0, 3, Mrf);
  M.addBlock(3, 0, Mrf.transpose());
  M.addSparse(3, 3, inv_.mff);
}

void FfrBody2d::addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const {
  const int nf = numElastic();
  const auto Mrf = frameElasticMass(q);
  out.head<3>() += frameMass(q) * a.head<3>() + Mrf * a.tail(nf);
  out.tail(nf) += Mrf.transpose() * a.head<3>() + inv_.mff * a.tail(nf);
}

void FfrBody2d::addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a, const MatrixSink& K) const {
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
  K.addBlock(0, 2, Vec2(-As * at + SASb * af));
  K.addBlock(0, 3, SASb * at);
  // row theta: (S A s)^T a_R + m_tt a_t + m_tf a_f
  K.add(2, 2, -As.dot(aR));
  K.addBlock(2, 3, RowVecX(aR.transpose() * SASb + 2.0 * at * (inv_.i1 + inv_.mff * qf).transpose() +
                           (inv_.sTilde * af).transpose()));
  // rows f: S-bar^T A^T a_R + m_ft a_t + m_ff a_f;  d(S~^T qf a_t)/dqf = S~^T a_t = -S~ a_t
  K.addBlock(3, 2, VecX(SASb.transpose() * aR));
  K.addSparse(3, 3, inv_.sTilde, -at);
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

void FfrBody2d::addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                          const MatrixSink& dQdv) const {
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
  dQdq.addBlock(0, 2, Vec2(perp(As) * w * w + 2.0 * ASbp * w));
  dQdq.addBlock(0, 3, ASb * w * w);
  dQdv.addBlock(0, 2, Vec2(2.0 * As * w - 2.0 * perp(ASbp)));
  dQdv.addBlock(0, 3, -2.0 * SASb * w);
  // Q_theta = -2 w iu^T p
  dQdq.addBlock(2, 3, RowVecX(-2.0 * w * (inv_.mff * p).transpose()));
  dQdv.add(2, 2, -2.0 * iu.dot(p));
  dQdv.addBlock(2, 3, RowVecX(-2.0 * w * iu.transpose()));
  // Q_f = w^2 iu + 2 w S~ p - dU/dqf - D p
  dQdq.addSparse(3, 3, inv_.mff, w * w);
  dQdq.addSparse(3, 3, model_ ? model_->strainEnergyHessian(qf) : inv_.kff, -1.0);
  dQdv.addBlock(3, 2, VecX(2.0 * w * iu + 2.0 * (inv_.sTilde * p)));
  dQdv.addSparse(3, 3, inv_.sTilde, 2.0 * w);
  dQdv.addSparse(3, 3, inv_.dff, -1.0);
}

void FfrBody2d::addGravityForce(const ConstVecRef& q, const Vec2& g, VecX& Q) const {
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  Q.head<2>() += inv_.mass * g;
  Q[2] += perp(As).dot(g);
  Q.tail(nf) += (A * inv_.sBar).transpose() * g;
}

void FfrBody2d::addGravityJacobian(const ConstVecRef& q, const Vec2& g, const MatrixSink& K) const {
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  const Mat2X ASb = A * inv_.sBar;
  Mat2X SASb(2, nf);
  for (int k = 0; k < nf; ++k) SASb.col(k) = perp(ASb.col(k));
  K.add(2, 2, -As.dot(g));
  K.addBlock(2, 3, RowVecX(g.transpose() * SASb));
  K.addBlock(3, 2, VecX(SASb.transpose() * g));
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

std::vector<int> FfrBody2d::pointSupport(const Vec2& point) const {
  const int k = findPoint(point);
  if (k < 0) checkAttachmentPoint(point, "attachment");
  std::vector<int> cols = {0, 1, 2};
  for (int e : FfrInvariants::support(inv_.points[k])) cols.push_back(3 + e);
  return cols;
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const Vec2& point, bool withHessians) const {
  const int k = findPoint(point);
  if (k < 0) checkAttachmentPoint(point, "attachment");
  return pointKinematics(q, inv_.points[k], withHessians);
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const Vec2& point, const std::vector<int>& cols,
                                           bool withHessians) const {
  const int k = findPoint(point);
  if (k < 0) checkAttachmentPoint(point, "attachment");
  return kinematicsOn(q, inv_.points[k], cols, withHessians);
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const FfrPoint& pt, bool withHessians) const {
  std::vector<int> all(numCoordinates());
  std::iota(all.begin(), all.end(), 0);
  return kinematicsOn(q, pt, all, withHessians);
}

PointKinematics FfrBody2d::kinematicsOn(const ConstVecRef& q, const FfrPoint& pt, const std::vector<int>& cols,
                                        bool withHessians) const {
  // r = R + A u,  u = u0 + N qf;  dr/dtheta = S A u;  dr/dqf = A N;
  // d2r/dtheta2 = -A u;  d2r/dtheta dqf = S A N;  phi = theta + Nphi qf.
  const int nf = numElastic(), n = static_cast<int>(cols.size());
  const Mat2 A = rotation(q[2]);
  const Vec2 Au = A * (pt.position + pt.shape * q.tail(nf));
  PointKinematics p;
  p.r = q.head<2>() + Au;
  p.phi = q[2] + pt.rotationShape.dot(q.tail(nf));
  p.Jr = Mat2X::Zero(2, n);
  p.Jphi = RowVecX::Zero(n);
  int thetaCol = -1;
  for (int a = 0; a < n; ++a) {
    const int c = cols[a];
    if (c < 2) {
      p.Jr(c, a) = 1.0;
    } else if (c == 2) {
      p.Jr.col(a) = perp(Au);
      p.Jphi[a] = 1.0;
      thetaCol = a;
    } else {
      p.Jr.col(a) = A * pt.shape.col(c - 3);
      p.Jphi[a] = pt.rotationShape[c - 3];
    }
  }
  if (!withHessians) return p;
  p.Hrx = MatX::Zero(n, n);
  p.Hry = MatX::Zero(n, n);
  p.Hphi = MatX::Zero(n, n);
  if (thetaCol < 0) return p;
  p.Hrx(thetaCol, thetaCol) = -Au.x();
  p.Hry(thetaCol, thetaCol) = -Au.y();
  for (int a = 0; a < n; ++a) {
    if (cols[a] < 3) continue;
    const Vec2 s = perp(p.Jr.col(a));  // S A N_k
    p.Hrx(thetaCol, a) = p.Hrx(a, thetaCol) = s.x();
    p.Hry(thetaCol, a) = p.Hry(a, thetaCol) = s.y();
  }
  return p;
}

Vec2 FfrBody2d::centreOfMass(const ConstVecRef& q) const {
  return q.head<2>() + rotation(q[2]) * (inv_.firstMoment + inv_.sBar * q.tail(numElastic())) / inv_.mass;
}

}  // namespace flexmbd
