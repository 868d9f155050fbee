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

/// x^T S y without temporaries.
template <class X, class Y>
double bilinear(const SpMat& S, const X& x, const Y& y) {
  double sum = 0.0;
  for (int j = 0; j < S.outerSize(); ++j) {
    double col = 0.0;
    for (SpMat::InnerIterator it(S, j); it; ++it) col += x[it.row()] * it.value();
    sum += col * y[j];
  }
  return sum;
}

/// (column k of S) . x, i.e. (S^T x)_k.
template <class X>
double columnDot(const SpMat& S, int k, const X& x) {
  double sum = 0.0;
  for (SpMat::InnerIterator it(S, k); it; ++it) sum += it.value() * x[it.row()];
  return sum;
}

}  // namespace

FfrBody2d::FfrBody2d(std::string name, FfrInvariants invariants, const FrameState2d& initial)
    : Body(std::move(name)), ownInvariants_(std::move(invariants)), inv_(ownInvariants_), initial_(initial) {
  inv_.validate("body '" + this->name() + "'");
  polar_ = inv_.polarQuadratic();
  checkFrame("body '" + this->name() + "'", initial);
}

FfrBody2d::FfrBody2d(std::string name, std::shared_ptr<const FfrBeamModel> model, const FrameState2d& initial)
    : Body(std::move(name)), model_(std::move(model)), inv_(requireModel(model_, this->name()).invariants()),
      polar_(inv_.polarQuadratic()), initial_(initial) {
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

namespace {

/// The frame-frame mass block at the rotation A = A(theta) the caller has computed.
/// `polar`: m_ff + R, the quadratic part of int rho |u0 + u|^2 dV.
template <class Qf>
Eigen::Matrix3d frameMassAt(const FfrInvariants& inv, const SpMat& polar, const Mat2& A, const Qf& qf) {
  // m_RR = m I, m_R theta = S A s, m_theta theta = I0 + 2 I1.qf + qf^T (m_ff + R) qf (Shabana2005, ch. 5)
  const Vec2 sas = perp(A * (inv.firstMoment + inv.sBar * qf));
  Eigen::Matrix3d M;
  M << inv.mass, 0.0, sas.x(),  //
      0.0, inv.mass, sas.y(),   //
      sas.x(), sas.y(), inv.polarMoment + 2.0 * inv.i1.dot(qf) + bilinear(polar, qf, qf);
  return M;
}

}  // namespace

Eigen::Vector3d FfrBody2d::frameElasticMassColumn(const Mat2& A, const ConstVecRef& qf, int k) const {
  // m_Rf = A S-bar, m_theta f = J0^T + qf^T S~ (column k; Shabana2005, ch. 5)
  Eigen::Vector3d c;
  c.head<2>() = A * inv_.sBar.col(k);
  c[2] = inv_.j0[k] + columnDot(inv_.sTilde, k, qf);
  return c;
}

void FfrBody2d::addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const {
  const int nf = numElastic();
  const auto qf = q.tail(nf);
  const Mat2 A = rotation(q[2]);
  M.addBlock(0, 0, frameMassAt(inv_, polar_, A, qf));
  for (int k = 0; k < nf; ++k) M.addBlock(0, 3 + k, frameElasticMassColumn(A, qf, k));
  for (int j = 0; j < 3; ++j) {
    M.addColumn(3, j, nf, [&](int k) { return frameElasticMassColumn(A, qf, k)[j]; });
  }
  M.addSparse(3, 3, inv_.mff);
}

void FfrBody2d::addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const {
  const int nf = numElastic();
  const auto qf = q.tail(nf), af = a.tail(nf);
  const Mat2 A = rotation(q[2]);
  const double at = a[2];
  // frame rows: M_rr a_r + M_rf a_f with M_rf a_f = (A S-bar a_f, J0.a_f + qf^T S~ a_f) (Shabana2005, ch. 5)
  Eigen::Vector3d mrf;
  mrf.head<2>() = A * (inv_.sBar * af);
  mrf[2] = inv_.j0.dot(af) + bilinear(inv_.sTilde, qf, af);
  out.head<3>() += frameMassAt(inv_, polar_, A, qf) * a.head<3>() + mrf;
  // elastic rows: M_fr a_r + m_ff a_f = S-bar^T A^T a_R + (J0 + S~^T qf) a_t + m_ff a_f (Shabana2005, ch. 5)
  auto of = out.tail(nf);
  of.noalias() += inv_.sBar.transpose() * (A.transpose() * a.head<2>());
  of += at * inv_.j0;
  of.noalias() += at * (inv_.sTilde.transpose() * qf);
  of.noalias() += inv_.mff * af;
}

void FfrBody2d::addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a, const MatrixSink& K) const {
  // d(M(q) a)/dq; m_ff and S~ are (skew-)symmetric (validated), so their rows are
  // read as (negated) columns.
  const int nf = numElastic();
  const auto qf = q.tail(nf), af = a.tail(nf);
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Vec2 aR = a.head<2>();
  const double at = a[2];
  auto SASb = [&](int k) -> Vec2 { return perp(A * inv_.sBar.col(k)); };  // S A S-bar, column k
  // row R: (S A s) a_t + A S-bar a_f
  K.addBlock(0, 2, Vec2(-As * at + perp(A * (inv_.sBar * af))));
  for (int k = 0; k < nf; ++k) K.addBlock(0, 3 + k, Vec2(SASb(k) * at));
  // row theta: (S A s)^T a_R + m_tt a_t + m_tf a_f
  K.add(2, 2, -As.dot(aR));
  for (int k = 0; k < nf; ++k) {
    K.add(2, 3 + k,
          aR.dot(SASb(k)) + 2.0 * at * (inv_.i1[k] + columnDot(polar_, k, qf)) - columnDot(inv_.sTilde, k, af));
  }
  // rows f: S-bar^T A^T a_R + m_ft a_t + m_ff a_f;  d(S~^T qf a_t)/dqf = S~^T a_t = -S~ a_t
  K.addColumn(3, 2, nf, [&](int k) { return SASb(k).dot(aR); });
  K.addSparse(3, 3, inv_.sTilde, -at);
}

void FfrBody2d::addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const {
  const int nf = numElastic();
  const auto qf = q.tail(nf), p = v.tail(nf);
  const double w = v[2];
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Vec2 ASbp = A * (inv_.sBar * p);
  // Quadratic velocity vector Q_v = -int rho (dr/dq)^T (-A u w^2 + 2 S A N p w) dV (Shabana2005,
  // ch. 5), with
  // iu = I1 + (m_ff + R) qf = int rho N^T u dV (+ R qf: half the gradient of the
  // sections' second-order rotation in the polar moment)
  Q.head<2>() += As * w * w - 2.0 * perp(ASbp) * w;
  Q[2] += -2.0 * w * (inv_.i1.dot(p) + bilinear(polar_, p, qf));
  auto Qf = Q.tail(nf);
  Qf += (w * w) * inv_.i1;
  Qf.noalias() += (w * w) * (polar_ * qf);
  Qf.noalias() += (2.0 * w) * (inv_.sTilde * p);
  // elastic and damping forces
  if (model_ && model_->geometricStiffening()) {
    Qf -= model_->strainEnergyGradient(qf);
  } else {
    Qf.noalias() -= inv_.kff * qf;
  }
  Qf.noalias() -= inv_.dff * p;
}

void FfrBody2d::addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                          const MatrixSink& dQdv) const {
  // m_ff symmetric and S~ skew (validated): rows read as (negated) columns.
  const int nf = numElastic();
  const auto qf = q.tail(nf), p = v.tail(nf);
  const double w = v[2];
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * qf);
  const Vec2 ASbp = A * (inv_.sBar * p);
  auto ASb = [&](int k) -> Vec2 { return A * inv_.sBar.col(k); };
  auto iu = [&](int k) { return inv_.i1[k] + columnDot(polar_, k, qf); };  // I1 + (m_ff + R) qf
  // Q_R = A s w^2 - 2 S A S-bar p w
  dQdq.addBlock(0, 2, Vec2(perp(As) * w * w + 2.0 * ASbp * w));
  dQdv.addBlock(0, 2, Vec2(2.0 * As * w - 2.0 * perp(ASbp)));
  for (int k = 0; k < nf; ++k) {
    dQdq.addBlock(0, 3 + k, Vec2(ASb(k) * w * w));
    dQdv.addBlock(0, 3 + k, Vec2(-2.0 * w * perp(ASb(k))));
  }
  // Q_theta = -2 w iu^T p (Shabana2005, ch. 5)
  dQdv.add(2, 2, -2.0 * (inv_.i1.dot(p) + bilinear(polar_, p, qf)));
  for (int k = 0; k < nf; ++k) {
    dQdq.add(2, 3 + k, -2.0 * w * columnDot(polar_, k, p));
    dQdv.add(2, 3 + k, -2.0 * w * iu(k));
  }
  // Q_f = w^2 iu + 2 w S~ p - dU/dqf - D p (Shabana2005, ch. 5)
  dQdq.addSparse(3, 3, polar_, w * w);
  if (model_ && model_->geometricStiffening()) {
    dQdq.addSparse(3, 3, model_->strainEnergyHessian(qf), -1.0);
  } else {
    dQdq.addSparse(3, 3, inv_.kff, -1.0);
  }
  dQdv.addColumn(3, 2, nf, [&](int k) { return 2.0 * w * iu(k) - 2.0 * columnDot(inv_.sTilde, k, p); });
  dQdv.addSparse(3, 3, inv_.sTilde, 2.0 * w);
  dQdv.addSparse(3, 3, inv_.dff, -1.0);
}

void FfrBody2d::addGravityForce(const ConstVecRef& q, const Vec3& g3, VecX& Q) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  Q.head<2>() += inv_.mass * g;
  Q[2] += perp(As).dot(g);
  Q.tail(nf).noalias() += inv_.sBar.transpose() * (A.transpose() * g);
}

void FfrBody2d::addGravityJacobian(const ConstVecRef& q, const Vec3& g3, const MatrixSink& K) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  const int nf = numElastic();
  const Mat2 A = rotation(q[2]);
  const Vec2 As = A * (inv_.firstMoment + inv_.sBar * q.tail(nf));
  auto SASb = [&](int k) -> Vec2 { return perp(A * inv_.sBar.col(k)); };
  K.add(2, 2, -As.dot(g));
  for (int k = 0; k < nf; ++k) K.add(2, 3 + k, g.dot(SASb(k)));
  K.addColumn(3, 2, nf, [&](int k) { return SASb(k).dot(g); });
}

double FfrBody2d::gravityPotential(const ConstVecRef& q, const Vec3& g3) const {
  const Vec2 g = g3.head<2>();  // the plane carries the z component
  return -g.dot(inv_.mass * q.head<2>() + rotation(q[2]) * (inv_.firstMoment + inv_.sBar * q.tail(numElastic())));
}

double FfrBody2d::internalPotential(const ConstVecRef& q) const {
  const auto qf = q.tail(numElastic());
  return model_ ? model_->strainEnergy(qf) : 0.5 * bilinear(inv_.kff, qf, qf);
}

int FfrBody2d::findPoint(const Vec2& point) const {
  double scale = 1.0;
  for (const auto& p : inv_.points) scale = std::max(scale, p.position.norm());
  for (size_t k = 0; k < inv_.points.size(); ++k) {
    if ((inv_.points[k].position - point).norm() <= 1e-9 * scale) return static_cast<int>(k);
  }
  return -1;
}

int FfrBody2d::resolvePoint(const Vec3& point, const std::string& user) const {
  const int k = point.z() == 0.0 ? findPoint(point.head<2>()) : -1;
  if (k >= 0) return k;
  std::ostringstream os;
  os << user << ": flexible body '" << name() << "' has no node at (" << point.x() << ", " << point.y();
  if (point.z() != 0.0) os << ", " << point.z();
  os << "); joints and forces attach to nodes (";
  for (size_t j = 0; j < inv_.points.size() && j < 6; ++j) {
    os << (j ? ", " : "") << "(" << inv_.points[j].position.x() << ", " << inv_.points[j].position.y() << ")";
  }
  os << (inv_.points.size() > 6 ? ", ...)" : ")");
  throw InputError(os.str());
}

const FfrPoint& FfrBody2d::node(const Vec2& point, int pointId) const {
  if (pointId >= 0 && pointId < static_cast<int>(inv_.points.size())) return inv_.points[pointId];
  return inv_.points[resolvePoint(lift(point), "attachment")];  // not resolved: found by its coordinates
}

std::vector<int> FfrBody2d::pointSupport(const Vec3& point, int pointId) const {
  std::vector<int> cols = {0, 1, 2};
  for (int e : FfrInvariants::support(node(point.head<2>(), pointId))) cols.push_back(3 + e);
  return cols;
}

void FfrBody2d::pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                                bool withHessians, PointKinematics& out) const {
  kinematicsOn(q, node(point, pointId), cols, withHessians, out);
}

PointKinematics FfrBody2d::pointKinematics(const ConstVecRef& q, const FfrPoint& pt, bool withHessians) const {
  PointKinematics p;
  kinematicsOn(q, pt, nullptr, withHessians, p);
  return p;
}

void FfrBody2d::kinematicsOn(const ConstVecRef& q, const FfrPoint& pt, const std::vector<int>* cols,
                             bool withHessians, PointKinematics& p) const {
  // r = R + A u,  u = u0 + N qf (Shabana2005, ch. 5);  dr/dtheta = S A u;  dr/dqf = A N;
  // d2r/dtheta2 = -A u;  d2r/dtheta dqf = S A N;  phi = theta + Nphi qf.
  const int nf = numElastic(), n = cols ? static_cast<int>(cols->size()) : numCoordinates();
  const Mat2 A = rotation(q[2]);
  const Vec2 Au = A * (pt.position + pt.shape * q.tail(nf));
  p.r = q.head<2>() + Au;
  p.phi = q[2] + pt.rotationShape.dot(q.tail(nf));
  p.reset(n, withHessians);
  int thetaCol = -1;
  for (int a = 0; a < n; ++a) {
    const int c = cols ? (*cols)[a] : a;
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
  if (!withHessians || thetaCol < 0) return;
  p.Hrx(thetaCol, thetaCol) = -Au.x();
  p.Hry(thetaCol, thetaCol) = -Au.y();
  for (int a = 0; a < n; ++a) {
    if ((cols ? (*cols)[a] : a) < 3) continue;
    const Vec2 s = perp(p.Jr.col(a));  // S A N_k
    p.Hrx(thetaCol, a) = p.Hrx(a, thetaCol) = s.x();
    p.Hry(thetaCol, a) = p.Hry(a, thetaCol) = s.y();
  }
}

Vec3 FfrBody2d::centreOfMass(const ConstVecRef& q) const { return lift(planarCentreOfMass(q)); }

Vec2 FfrBody2d::planarCentreOfMass(const ConstVecRef& q) const {
  return q.head<2>() + rotation(q[2]) * (inv_.firstMoment + inv_.sBar * q.tail(numElastic())) / inv_.mass;
}

FfrBody2d::BeamDeflection FfrBody2d::beamDeflection(const ConstVecRef& q, int element, double xi) const {
  if (!model_) {
    throw InputError("body '" + name() + "': not made from a beam mesh; its deflection and section forces are unknown");
  }
  const VecX qf = q.tail(model_->numElastic());
  const FfrPoint p = model_->materialPoint(element, xi);
  BeamDeflection d;
  d.displacement = p.shape * qf;
  d.sectionForces = model_->sectionForces(qf, element, xi);
  const Mat2 A = rotation(q[2]);
  d.position = q.head<2>() + A * (p.position + d.displacement);
  d.worldDisplacement = A * d.displacement;
  return d;
}

Vec2 FfrBody2d::worldElasticDisplacement(const ConstVecRef& q, const FfrPoint& p) const {
  return rotation(q[2]) * (p.shape * q.tail(numElastic()));
}

}  // namespace flexmbd
