#include "bodies/ffr_body_3d.hpp"

#include <algorithm>
#include <sstream>

#include "bodies/euler_frame_rates.hpp"
#include "core/errors.hpp"

namespace flexmbd {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

/// (S^T x)_k = (column k of S) . x.
template <class X>
double columnDot(const SpMat& S, int k, const X& x) {
  double sum = 0.0;
  for (SpMat::InnerIterator it(S, k); it; ++it) sum += it.value() * x[it.row()];
  return sum;
}

/// x^T S y without temporaries.
template <class X, class Y>
double bilinear(const SpMat& S, const X& x, const Y& y) {
  double sum = 0.0;
  for (int j = 0; j < S.outerSize(); ++j) sum += columnDot(S, j, x) * y[j];
  return sum;
}

/// out += c S x, by sparse iteration (no temporary).
template <class X, class Out>
void addProduct(const SpMat& S, const X& x, double c, Out&& out) {
  for (int j = 0; j < S.outerSize(); ++j) {
    const double xj = c * x[j];
    for (SpMat::InnerIterator it(S, j); it; ++it) out[it.row()] += it.value() * xj;
  }
}

/// Entry (i, j) of T+ (velocity i, coordinate j) for the rotation block Rinv.
double tinvEntry(const Mat34& Rinv, int i, int j) {
  if (i < 3) return j == i ? 1.0 : 0.0;
  if (i < 6) return (j >= 3 && j < 7) ? Rinv(i - 3, j - 3) : 0.0;
  return j == i + 1 ? 1.0 : 0.0;
}

}  // namespace

namespace {
const FfrBeamModel3d& requireModel(const std::shared_ptr<const FfrBeamModel3d>& model, const std::string& name) {
  if (!model) throw InputError("body '" + name + "': no beam model given");
  return *model;
}
}  // namespace

FfrBody3d::FfrBody3d(std::string name, std::shared_ptr<const FfrBeamModel3d> model, const FrameState3d& initial,
                     VecX qf0, VecX qf0dot)
    : Body(std::move(name)), model_(std::move(model)), inv_(requireModel(model_, this->name()).invariants()),
      initial_(initial), qf0_(std::move(qf0)), qf0dot_(std::move(qf0dot)) {
  setUp();  // the model's invariants, shared, not copied (their point shapes are nf wide per node)
}

FfrBody3d::FfrBody3d(std::string name, FfrInvariants3d invariants, const FrameState3d& initial, VecX qf0,
                     VecX qf0dot)
    : Body(std::move(name)), ownInvariants_(std::move(invariants)), inv_(ownInvariants_), initial_(initial),
      qf0_(std::move(qf0)), qf0dot_(std::move(qf0dot)) {
  const int nf = ownInvariants_.numElastic();
  if (ownInvariants_.dff.size() == 0) ownInvariants_.dff.resize(nf, nf);  // undamped
  setUp();
}

void FfrBody3d::setUp() {
  const std::string who = "body '" + this->name() + "'";
  nf_ = inv_.numElastic();
  inv_.validate(who);
  // initial state
  const FrameState3d& initial = initial_;
  for (int k = 0; k < 3; ++k) {
    requireFinite(initial.position[k], who + ": position[" + std::to_string(k) + "]");
    requireFinite(initial.velocity[k], who + ": velocity[" + std::to_string(k) + "]");
    requireFinite(initial.angularVelocity[k], who + ": angular_velocity[" + std::to_string(k) + "]");
  }
  const Mat3& R = initial.orientation;
  if (!R.allFinite() || !((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) ||
      !(R.determinant() > 0.0)) {
    throw InputError(who + ": orientation: not a rotation matrix (expected orthonormal columns, determinant +1)");
  }
  if (qf0_.size() == 0) qf0_ = VecX::Zero(nf_);
  if (qf0dot_.size() == 0) qf0dot_ = VecX::Zero(nf_);
  if (qf0_.size() != nf_ || qf0dot_.size() != nf_) {
    throw InputError(who + ": initial elastic state must have " + std::to_string(nf_) + " entries, got " +
                     std::to_string(qf0_.size()) + " and " + std::to_string(qf0dot_.size()));
  }
  if (!qf0_.allFinite() || !qf0dot_.allFinite()) throw InputError(who + ": initial elastic state is not finite");

  // constants: X0 = int rho u0~ N dV (rows: u0 x N), from positionShape (row l of
  // positionShape[k] = int rho u0_k N_l dV)
  const auto& P = inv_.positionShape;
  x0_.resize(3, nf_);
  x0_.row(0) = P[1].row(2) - P[2].row(1);
  x0_.row(1) = P[2].row(0) - P[0].row(2);
  x0_.row(2) = P[0].row(1) - P[1].row(0);
  // W_i exactly skew: S_ab - S_ab^T
  const auto& S = inv_.sKL;
  w_[0] = S[1][2] - SpMat(S[1][2].transpose());
  w_[1] = S[2][0] - SpMat(S[2][0].transpose());
  w_[2] = S[0][1] - SpMat(S[0][1].transpose());
  for (auto& w : w_) w.makeCompressed();
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      const SpMat& R = inv_.rKL[k][l];
      if (R.size() != 0 && R.nonZeros() > 0) sectionRotation_.push_back({k, l, R});
    }
  }
  for (auto& t : sectionRotation_) t.R.makeCompressed();
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      const SpMat& G = inv_.spinStiffness[k][l];
      if (G.size() != 0 && G.nonZeros() > 0) spinStiffening_.push_back({k, l, G});
    }
  }
  for (auto& t : spinStiffening_) t.R.makeCompressed();
  for (int i = 0; i < 3; ++i) {
    if (inv_.hI[i].size() != 0 && inv_.hI[i].nonZeros() > 0) {
      h_[i] = inv_.hI[i];
      hasCoupling_ = true;
    } else {
      h_[i].resize(nf_, nf_);
    }
    h_[i].makeCompressed();
  }
  for (const FfrPoint3d& p : inv_.points) nodeSupport_.push_back(FfrInvariants3d::support(p));
}

std::vector<std::string> FfrBody3d::coordinateNames() const {
  std::vector<std::string> n = {"x", "y", "z", "e0", "e1", "e2", "e3"};
  for (int k = 1; k <= nf_; ++k) n.push_back("q" + std::to_string(k));
  return n;
}

std::vector<std::string> FfrBody3d::velocityNames() const {
  std::vector<std::string> n = {"x_dot", "y_dot", "z_dot", "wx", "wy", "wz"};
  for (int k = 1; k <= nf_; ++k) n.push_back("q" + std::to_string(k) + "_dot");
  return n;
}

std::vector<CoordinateKind> FfrBody3d::coordinateKinds() const {
  std::vector<CoordinateKind> k(numCoordinates(), CoordinateKind::Elastic);
  for (int i = 0; i < 3; ++i) k[i] = CoordinateKind::Position;
  for (int i = 3; i < 7; ++i) k[i] = CoordinateKind::Angle;
  return k;
}

std::vector<CoordinateKind> FfrBody3d::velocityKinds() const {
  std::vector<CoordinateKind> k(numVelocities(), CoordinateKind::Elastic);
  for (int i = 0; i < 3; ++i) k[i] = CoordinateKind::Position;
  for (int i = 3; i < 6; ++i) k[i] = CoordinateKind::Angle;
  return k;
}

VecX FfrBody3d::initialCoordinates() const {
  VecX q(numCoordinates());
  q.head<3>() = initial_.position;
  q.segment<4>(3) = quaternionFromRotation(initial_.orientation);
  q.tail(nf_) = qf0_;
  return q;
}

VecX FfrBody3d::initialVelocities() const {
  VecX v(numVelocities());
  v.head<3>() = initial_.velocity;
  v.segment<3>(3) = initial_.angularVelocity;
  v.tail(nf_) = qf0dot_;
  return v;
}

bool FfrBody3d::isDissipative() const {
  return inv_.dff.nonZeros() > 0 && inv_.dff.coeffs().cwiseAbs().maxCoeff() > 0.0;
}

// ----- kinematic equation -------------------------------------------------------------

void FfrBody3d::addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const {
  addEulerFrameRateMatrix(q, nf_, T);
}

void FfrBody3d::addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const {
  addEulerFrameRateInverse(q, nf_, Tinv);
}

void FfrBody3d::addCoordinateRate(const ConstVecRef& q, const ConstVecRef& w, Eigen::Ref<VecX> out) const {
  out.head<3>() += w.head<3>();
  out.segment<4>(3) += 0.5 * quaternionL(q.segment<4>(3)).transpose() * w.segment<3>(3);
  out.tail(nf_) += w.tail(nf_);
}

void FfrBody3d::addCoordinateRateJacobian(const ConstVecRef&, const ConstVecRef& w, const MatrixSink& K) const {
  K.addBlock(3, 3, 0.5 * quaternionLTransposeJacobian(w.segment<3>(3)));
}

void FfrBody3d::applyIncrement(const ConstVecRef& q, const ConstVecRef& dv, Eigen::Ref<VecX> out) const {
  // as RigidBody3d: p (x) exp(dpi / 2), renormalised; elastic coordinates add
  out.head<3>() = q.head<3>() + dv.head<3>();
  const Vec3 dpi = dv.segment<3>(3);
  const double angle = dpi.norm();
  const Vec4 dp = angle > 0.0 ? quaternionFromAxisAngle(dpi / angle, angle) : Vec4(1.0, 0.0, 0.0, 0.0);
  out.segment<4>(3) = quaternionProduct(q.segment<4>(3), dp).normalized();
  out.tail(nf_) = q.tail(nf_) + dv.tail(nf_);
}

std::vector<int> FfrBody3d::coordinatesOfVelocities(const std::vector<int>& vcols) const {
  std::vector<int> out;
  bool rotation = false;
  for (int c : vcols) {
    if (c < 3) out.push_back(c);
    if (c >= 3 && c < 6) rotation = true;
  }
  if (rotation) {
    for (int c = 3; c < 7; ++c) out.push_back(c);
  }
  for (int c : vcols) {
    if (c >= 6) out.push_back(c + 1);
  }
  return out;
}

// ----- inertia ---------------------------------------------------------------------

Vec3 FfrBody3d::firstMomentAt(const ConstVecRef& q) const {
  return inv_.firstMoment + inv_.sBar * q.tail(nf_);
}

namespace {
/// The skew pair of W_i = S_ab - S_ba: for the stored upper S_kl (k < l), the index i of
/// the W it forms and the sign (W_x = S_yz - S_zy, W_y = -(S_xz - S_zx), W_z = S_xy - S_yx).
struct SkewPair {
  int index;
  double sign;
};
constexpr SkewPair skewPairOf(int k, int l) {
  return k == 0 ? (l == 1 ? SkewPair{2, 1.0} : SkewPair{1, -1.0}) : SkewPair{0, 1.0};
}
}  // namespace

Mat3 FfrBody3d::secondMomentAt(const ConstVecRef& qf) const {
  // J = int rho (u0 + N qf)(u0 + N qf)^T dV = J0 + P + P^T + (qf^T S_kl qf)_kl,
  // P_kl = int rho u0_k N_l dV qf = positionShape[k].row(l) qf
  // (the six stored S_kl with k <= l; S_lk = S_kl^T is validated)
  Mat3 quadratic = Mat3::Zero();
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) quadratic(k, l) = bilinear(inv_.sKL[k][l], qf, qf);
  }
  addSectionRotationMoment(qf, quadratic);
  return secondMomentFrom(qf, quadratic);
}

void FfrBody3d::addSectionRotationMoment(const ConstVecRef& qf, Mat3& quadratic) const {
  for (const PairTerm& t : sectionRotation_) quadratic(t.k, t.l) += bilinear(t.R, qf, qf);
}

Mat3 FfrBody3d::secondMomentFrom(const ConstVecRef& qf, const Mat3& quadratic) const {
  Mat3 J = inv_.secondMoment;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      const double pkl = inv_.positionShape[k].row(l).dot(qf);
      J(k, l) += pkl + quadratic(std::min(k, l), std::max(k, l));  // qf^T S_lk qf = qf^T S_kl qf
      J(l, k) += pkl;
    }
  }
  return J;
}

Mat3 FfrBody3d::secondMomentDerivative(const ConstVecRef& qf, int c) const {
  // dJ_kl/dqf_c = P[k](l, c) + P[l](k, c) + (S_kl^T qf)_c + (S_lk^T qf)_c
  Mat3 D;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      D(k, l) = inv_.positionShape[k](l, c) + inv_.positionShape[l](k, c) + columnDot(inv_.sKL[k][l], c, qf) +
                columnDot(inv_.sKL[l][k], c, qf);
    }
  }
  // d(qf^T R_kl qf)/dqf_c = 2 (R_kl qf)_c (R_kl symmetric), at (k, l) and (l, k)
  for (const PairTerm& t : sectionRotation_) {
    const double d = 2.0 * columnDot(t.R, c, qf);
    D(t.k, t.l) += d;
    if (t.k != t.l) D(t.l, t.k) += d;
  }
  return D;
}

Mat3 FfrBody3d::inertiaAt(const ConstVecRef& q) const {
  const Mat3 J = secondMomentAt(q.tail(nf_));
  return J.trace() * Mat3::Identity() - J;  // int rho u~^T u~ dV = tr(J) 1 - J (Shabana2005, eq. 5.110)
}

Vec3 FfrBody3d::skewShapeColumn(const ConstVecRef& qf, int k) const {
  // Y = int rho u~ N dV (Shabana2005, ch. 5) = X0 + int rho (N qf)~ N dV; column k: X0_k + (qf^T W_i e_k)_i
  // + (qf^T H_i e_k)_i = (H_i qf)_k, the sections' second-order rotation (H symmetric)
  return x0_.col(k) + Vec3(columnDot(w_[0], k, qf) + columnDot(h_[0], k, qf),
                           columnDot(w_[1], k, qf) + columnDot(h_[1], k, qf),
                           columnDot(w_[2], k, qf) + columnDot(h_[2], k, qf));
}

void FfrBody3d::addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const {
  const auto qf = q.tail(nf_);
  const Mat3 A = rotationOf(q);
  const Vec3 s = firstMomentAt(q);
  // Shabana2005, eqs. 5.108-5.117: m_RR = m I, m_Rtheta = -A s~, m_thetatheta = I(qf)
  Eigen::Matrix<double, 6, 6> mrr;
  mrr << inv_.mass * Mat3::Identity(), -A * skew(s), skew(s) * A.transpose(), inertiaAt(q);  // (-A s~)^T = s~ A^T
  M.addBlock(0, 0, mrr);
  // m_Rf = A S-bar, m_thetaf = Y (columns), and their transposes (Shabana2005, eqs. 5.108-5.117)
  for (int k = 0; k < nf_; ++k) {
    Vec6 c;
    c << A * inv_.sBar.col(k), skewShapeColumn(qf, k);
    M.addBlock(0, 6 + k, c);
  }
  for (int j = 0; j < 3; ++j) {
    M.addColumn(6, j, nf_, [&](int k) { return A.row(j).dot(inv_.sBar.col(k)); });
  }
  for (int j = 0; j < 3; ++j) {
    M.addColumn(6, 3 + j, nf_, [&](int k) { return x0_(j, k) + columnDot(w_[j], k, qf) + columnDot(h_[j], k, qf); });
  }
  M.addSparse(6, 6, inv_.mff);
}

void FfrBody3d::addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const {
  const auto qf = q.tail(nf_), af = a.tail(nf_);
  const Mat3 A = rotationOf(q);
  const Vec3 s = firstMomentAt(q);
  const Vec3 aR = a.head<3>(), aw = a.segment<3>(3);
  const Vec3 bR = A.transpose() * aR;
  auto of = out.tail(nf_);
  // One walk over the six stored S_kl (k <= l; S_lk = S_kl^T, validated): the
  // quadratic part of J (for I aw), Y af = X0 af + (qf^T W_i af)_i and the rows f' part
  // Y^T aw = X0^T aw + sum_i aw_i W_i^T qf, W_i = sign (S_kl - S_kl^T) (skewPairOf)
  Mat3 quadratic = Mat3::Zero();
  Vec3 yaf = x0_ * af;
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      const SpMat& S = inv_.sKL[k][l];
      if (k == l) {
        quadratic(k, l) = bilinear(S, qf, qf);
        continue;
      }
      const SkewPair wp = skewPairOf(k, l);
      const double cw = wp.sign * aw[wp.index];
      double jq = 0.0, y = 0.0;
      for (int j = 0; j < S.outerSize(); ++j) {
        const double qj = qf[j], aj = af[j];
        double sq = 0.0;  // (S^T qf)_j
        for (SpMat::InnerIterator it(S, j); it; ++it) {
          const int i = static_cast<int>(it.row());
          const double sv = it.value();
          jq += qf[i] * sv * qj;
          y += sv * (qf[i] * aj - af[i] * qj);
          of[i] -= cw * sv * qj;
          sq += sv * qf[i];
        }
        of[j] += cw * sq;
      }
      quadratic(k, l) = jq;
      yaf[wp.index] += wp.sign * y;
    }
  }
  addSectionRotationMoment(qf, quadratic);
  if (hasCoupling_) {
    // Y af gains (qf^T H_i af)_i, rows f Y^T aw gains sum_i aw_i H_i qf
    for (int i = 0; i < 3; ++i) {
      yaf[i] += bilinear(h_[i], qf, af);
      addProduct(h_[i], qf, aw[i], of);
    }
  }
  const Mat3 J = secondMomentFrom(qf, quadratic);
  // row R: m aR - A s~ aw + A S-bar af
  out.head<3>() += inv_.mass * aR + A * (aw.cross(s) + inv_.sBar * af);
  // row theta: s~ A^T aR + I aw + Y af, I = tr(J) 1 - J (Shabana2005, eq. 5.110)
  out.segment<3>(3) += s.cross(bR) + (J.trace() * aw - J * aw) + yaf;
  // rows f: S-bar^T A^T aR + Y^T aw + m_ff af
  of.noalias() += inv_.sBar.transpose() * bR + x0_.transpose() * aw;
  addProduct(inv_.mff, af, 1.0, of);
}

void FfrBody3d::addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a, const MatrixSink& K) const {
  // d(M(q) a)/dq. Rotations: d(A c)/dpi = -A c~, d(A^T c)/dpi = (A^T c)~ for a body-axes
  // rotation dpi = Rinv dp (Rinv = 2 L(p) / |p|^2, zero along p: the gauge).
  const auto qf = q.tail(nf_), af = a.tail(nf_);
  const Mat3 A = rotationOf(q);
  const Mat34 Rinv = eulerRateInverse(q);
  const Vec3 s = firstMomentAt(q);
  const Vec3 aR = a.head<3>(), aw = a.segment<3>(3);
  const Vec3 bR = A.transpose() * aR;
  const Mat3 bRs = skew(bR), awS = skew(aw);
  // row R = m aR + A (aw~ s + S-bar af) (Shabana2005, eqs. 5.108-5.117)
  const Vec3 c = aw.cross(s) + inv_.sBar * af;
  K.addBlock(0, 3, Mat34(-A * skew(c) * Rinv));
  // row theta = s~ A^T aR + I aw + Y af (Shabana2005, eqs. 5.108-5.117)
  K.addBlock(3, 3, Mat34(skew(s) * bRs * Rinv));
  for (int k = 0; k < nf_; ++k) {
    const Vec3 sk = inv_.sBar.col(k);
    const Mat3 Dk = secondMomentDerivative(qf, k);
    // d(Y af)/dqf_k = (W_i af)_k = -(W_i^T af)_k (W_i skew)
    // and (H_i af)_k (H_i symmetric)
    const Vec3 dY(-columnDot(w_[0], k, af) + columnDot(h_[0], k, af), -columnDot(w_[1], k, af) + columnDot(h_[1], k, af),
                  -columnDot(w_[2], k, af) + columnDot(h_[2], k, af));
    Vec6 col;
    col << A * (awS * sk), -bRs * sk + Dk.trace() * aw - Dk * aw + dY;
    K.addBlock(0, 7 + k, col);
  }
  // rows f = S-bar^T A^T aR + Y^T aw + m_ff af (Shabana2005, eqs. 5.108-5.117)
  const Mat34 B = bRs * Rinv;  // d(A^T aR)/dp
  for (int j = 0; j < 4; ++j) {
    K.addColumn(6, 3 + j, nf_, [&](int k) { return inv_.sBar.col(k).dot(B.col(j)); });
  }
  // d(Y^T aw)/dqf = sum_i aw_i W_i^T = -sum_i aw_i W_i
  for (int i = 0; i < 3; ++i) K.addSparse(6, 7, w_[i], -aw[i]);
  // + sum_i aw_i H_i
  if (hasCoupling_) {
    for (int i = 0; i < 3; ++i) K.addSparse(6, 7, h_[i], aw[i]);
  }
}

// ----- forces ------------------------------------------------------------------------

void FfrBody3d::addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const {
  // Q_v = -int rho (dr'/dv)^T A (w~ w~ u + 2 w~ N qf') dV (Shabana2005, eqs. 5.120-5.127):
  //   Q_R = -A (w~ w~ s + 2 w~ S-bar qf'),
  //   Q_theta = -w~ I w - 2 (tr(G) w - G w),   G = int rho (N qf') u^T dV,
  //   Q_f = -sum_kl (w~ w~)_kl int rho N_k^T u_l dV + 2 sum_i w_i W_i qf'.
  const auto qf = q.tail(nf_), pf = v.tail(nf_);
  const Mat3 A = rotationOf(q);
  const Vec3 s = firstMomentAt(q);
  const Vec3 w = v.segment<3>(3);
  const Mat3 ws = skew(w), Om = ws * ws;
  const Vec3 sp = inv_.sBar * pf;
  Q.head<3>() -= A * (Om * s + 2.0 * ws * sp);
  auto Qf = Q.tail(nf_);
  // One walk over the six stored S_kl (k <= l; S_lk = S_kl^T, validated): the
  // quadratic parts of J (qf^T S_kl qf) and G (qf'^T S_kl qf), and into Q_f -Om_kl S_kl qf
  // (with S_lk qf = S_kl^T qf; Om symmetric) and the Coriolis term 2 w_i W_i qf'.
  Mat3 quadratic = Mat3::Zero(), Gq = Mat3::Zero();
  for (int k = 0; k < 3; ++k) {
    for (int l = k; l < 3; ++l) {
      const SpMat& S = inv_.sKL[k][l];
      const double om = Om(k, l);
      double jq = 0.0, gkl = 0.0, glk = 0.0;
      if (k == l) {
        for (int j = 0; j < S.outerSize(); ++j) {
          const double qj = qf[j];
          for (SpMat::InnerIterator it(S, j); it; ++it) {
            const int i = static_cast<int>(it.row());
            const double t = it.value() * qj;
            jq += qf[i] * t;
            gkl += pf[i] * t;
            Qf[i] -= om * t;
          }
        }
      } else {
        const SkewPair wp = skewPairOf(k, l);
        const double c = 2.0 * w[wp.index] * wp.sign;  // 2 w_i (S_kl - S_kl^T) qf'
        for (int j = 0; j < S.outerSize(); ++j) {
          const double qj = qf[j], pj = pf[j];
          double fj = 0.0;  // into Q_f[j]: -(om S^T qf)_j - (c S^T qf')_j
          for (SpMat::InnerIterator it(S, j); it; ++it) {
            const int i = static_cast<int>(it.row());
            const double sv = it.value(), qi = qf[i], pi = pf[i];
            jq += qi * sv * qj;
            gkl += pi * sv * qj;
            glk += qi * sv * pj;  // qf'^T S_lk qf = qf^T S_kl qf'
            Qf[i] += sv * (c * pj - om * qj);
            fj -= sv * (om * qi + c * pi);
          }
          Qf[j] += fj;
        }
      }
      quadratic(k, l) = jq;
      Gq(k, l) = gkl;
      if (k != l) Gq(l, k) = glk;
    }
  }
  // The sections' second-order rotation: J_kl = J_lk gains qf^T R_kl qf, so G_kl = G_lk
  // gains qf'^T R_kl qf, and Q_f -sum_kl Om_kl R_kl qf (the term dT/dqf of
  // T = -(1/2) sum_kl Om_kl J_kl, as for S_kl)
  for (const PairTerm& t : sectionRotation_) {
    const double om = (t.k == t.l ? 1.0 : 2.0) * Om(t.k, t.l);
    double jq = 0.0, g = 0.0;
    for (int j = 0; j < t.R.outerSize(); ++j) {
      double rq = 0.0;  // (R qf)_j
      for (SpMat::InnerIterator it(t.R, j); it; ++it) rq += it.value() * qf[it.row()];
      jq += qf[j] * rq;
      g += pf[j] * rq;
      Qf[j] -= om * rq;
    }
    quadratic(t.k, t.l) += jq;
    Gq(t.k, t.l) += g;
    if (t.k != t.l) Gq(t.l, t.k) += g;
  }
  const Mat3 J = secondMomentFrom(qf, quadratic);
  Mat3 G;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) G(k, l) = inv_.positionShape[l].row(k).dot(pf) + Gq(k, l);
  }
  Q.segment<3>(3) -= w.cross(J.trace() * w - J * w) + 2.0 * (G.trace() * w - G * w);
  if (hasCoupling_) {
    // T gains w . b, b_i = qf^T H_i qf': d/dt b + w x b, the qf'' part in the mass matrix
    Vec3 b, c;
    for (int i = 0; i < 3; ++i) {
      b[i] = bilinear(h_[i], qf, pf);
      c[i] = bilinear(h_[i], pf, pf);
    }
    Q.segment<3>(3) -= c + w.cross(b);
  }
  // int rho N_k^T u_l dV = positionShape[l].row(k)^T + S_kl qf: the constant part
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) Qf.noalias() -= Om(k, l) * inv_.positionShape[l].row(k).transpose();
  }
  // elastic and damping forces
  if (model_) {
    model_->addStrainEnergyGradient(qf, -1.0, Qf);  // -dU/dq_f (K_ff q_f when linear)
  } else {
    addProduct(inv_.kff, qf, -1.0, Qf);
  }
  addProduct(inv_.dff, pf, -1.0, Qf);
  for (const PairTerm& t : spinStiffening_) {  // centrifugal stiffening: -w_k w_l G_kl qf
    addProduct(t.R, qf, -(t.k == t.l ? 1.0 : 2.0) * w[t.k] * w[t.l], Qf);
  }
}

void FfrBody3d::addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                          const MatrixSink& dQdv) const {
  const auto qf = q.tail(nf_), pf = v.tail(nf_);
  const Mat3 A = rotationOf(q);
  const Mat34 Rinv = eulerRateInverse(q);
  const Vec3 s = firstMomentAt(q);
  const Vec3 w = v.segment<3>(3);
  const Mat3 ws = skew(w), Om = ws * ws;
  const Vec3 sp = inv_.sBar * pf;
  const Mat3 I = inertiaAt(q);
  Mat3 G;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) G(k, l) = inv_.positionShape[l].row(k).dot(pf) + bilinear(inv_.sKL[k][l], pf, qf);
  }
  for (const PairTerm& t : sectionRotation_) {
    const double g = bilinear(t.R, pf, qf);
    G(t.k, t.l) += g;
    if (t.k != t.l) G(t.l, t.k) += g;
  }
  // Q_R = -A c, c = w~ w~ s + 2 w~ S-bar qf' (Shabana2005, eqs. 5.120-5.127)
  const Vec3 c = Om * s + 2.0 * ws * sp;
  dQdq.addBlock(0, 3, Mat34(A * skew(c) * Rinv));
  // d(w x (w x s))/dw = w s^T + (w.s) 1 - 2 s w^T;  d(2 w x sp)/dw = -2 sp~
  dQdv.addBlock(0, 3,
                Mat3(-A * (w * s.transpose() + w.dot(s) * Mat3::Identity() - 2.0 * s * w.transpose() - 2.0 * skew(sp))));
  // Q_theta = -w~ I w - 2 (tr(G) w - G w) (Shabana2005, eqs. 5.120-5.127)
  Mat3 dQwdw = -(ws * I - skew(I * w)) - 2.0 * (G.trace() * Mat3::Identity() - G);
  if (hasCoupling_) {
    Vec3 b;  // b_i = qf^T H_i qf': d(-w x b)/dw = b~
    for (int i = 0; i < 3; ++i) b[i] = bilinear(h_[i], qf, pf);
    dQwdw += skew(b);
  }
  dQdv.addBlock(3, 3, dQwdw);
  for (int k = 0; k < nf_; ++k) {
    const Vec3 sk = inv_.sBar.col(k);
    const Mat3 Dk = secondMomentDerivative(qf, k);
    Mat3 Gq, Gp;  // dG/dqf_k, dG/dqf'_k
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        Gq(a, b) = columnDot(inv_.sKL[a][b], k, pf);
        Gp(a, b) = inv_.positionShape[b](a, k) + columnDot(inv_.sKL[b][a], k, qf);
      }
    }
    for (const PairTerm& t : sectionRotation_) {
      const double gq = columnDot(t.R, k, pf), gp = columnDot(t.R, k, qf);  // R symmetric
      Gq(t.k, t.l) += gq;
      Gp(t.k, t.l) += gp;
      if (t.k != t.l) {
        Gq(t.l, t.k) += gq;
        Gp(t.l, t.k) += gp;
      }
    }
    Vec6 cq, cv;
    cq << -A * (Om * sk), -ws * (Dk.trace() * w - Dk * w) - 2.0 * (Gq.trace() * w - Gq * w);
    cv << -2.0 * A * (ws * sk), -2.0 * (Gp.trace() * w - Gp * w);
    if (hasCoupling_) {
      // -(qf'^T H_i qf')_i - w x (qf^T H_i qf')_i by qf_k and qf'_k (H_i symmetric)
      const Vec3 hp(columnDot(h_[0], k, pf), columnDot(h_[1], k, pf), columnDot(h_[2], k, pf));
      const Vec3 hq(columnDot(h_[0], k, qf), columnDot(h_[1], k, qf), columnDot(h_[2], k, qf));
      cq.tail<3>() -= w.cross(hp);
      cv.tail<3>() -= 2.0 * hp + w.cross(hq);
    }
    dQdq.addBlock(0, 7 + k, cq);
    dQdv.addBlock(0, 6 + k, cv);
  }
  // Q_f = -sum_kl Om_kl (positionShape[l].row(k)^T + S_kl qf) + 2 sum_i w_i W_i qf' - K qf - D qf'
  // (Shabana2005, eqs. 5.120-5.127)
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) dQdq.addSparse(6, 7, inv_.sKL[k][l], -Om(k, l));
  }
  for (const PairTerm& t : sectionRotation_) {
    dQdq.addSparse(6, 7, t.R, -(t.k == t.l ? 1.0 : 2.0) * Om(t.k, t.l));
  }
  if (model_) {
    model_->addStrainEnergyHessian(qf, -1.0, dQdq, 6, 7);
  } else {
    dQdq.addSparse(6, 7, inv_.kff, -1.0);
  }
  for (const PairTerm& t : spinStiffening_) {
    dQdq.addSparse(6, 7, t.R, -(t.k == t.l ? 1.0 : 2.0) * w[t.k] * w[t.l]);
  }
  // dOm_kl/dw_j = d_kj w_l + w_k d_lj - 2 d_kl w_j
  for (int j = 0; j < 3; ++j) {
    Mat3 dOm = -2.0 * w[j] * Mat3::Identity();
    dOm.row(j) += w.transpose();
    dOm.col(j) += w;
    dQdv.addColumn(6, 3 + j, nf_, [&](int m) {
      double sum = 0.0;
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          // (S_kl qf)_m = (S_lk^T qf)_m
          sum -= dOm(k, l) * (inv_.positionShape[l](k, m) + columnDot(inv_.sKL[l][k], m, qf));
        }
      }
      for (const PairTerm& t : sectionRotation_) {
        sum -= (t.k == t.l ? 1.0 : 2.0) * dOm(t.k, t.l) * columnDot(t.R, m, qf);
      }
      for (const PairTerm& t : spinStiffening_) {  // d(w_k w_l)/dw_j = d_jk w_l + w_k d_jl
        const double dww = (j == t.k ? w[t.l] : 0.0) + (j == t.l ? w[t.k] : 0.0);
        sum -= (t.k == t.l ? 1.0 : 2.0) * dww * columnDot(t.R, m, qf);
      }
      return sum - 2.0 * columnDot(w_[j], m, pf);  // (W_j qf')_m = -(W_j^T qf')_m
    });
  }
  for (int i = 0; i < 3; ++i) dQdv.addSparse(6, 6, w_[i], 2.0 * w[i]);
  dQdv.addSparse(6, 6, inv_.dff, -1.0);
}

void FfrBody3d::addGravityForce(const ConstVecRef& q, const Vec3& g, VecX& Q) const {
  // V = -g . (m R + A s): Q_R = m g, Q_theta = s x (A^T g), Q_f = S-bar^T A^T g (Shabana2005, ch. 5)
  const Mat3 A = rotationOf(q);
  const Vec3 gb = A.transpose() * g;
  Q.head<3>() += inv_.mass * g;
  Q.segment<3>(3) += firstMomentAt(q).cross(gb);
  Q.tail(nf_).noalias() += inv_.sBar.transpose() * gb;
}

void FfrBody3d::addGravityJacobian(const ConstVecRef& q, const Vec3& g, const MatrixSink& K) const {
  const Mat3 A = rotationOf(q);
  const Mat34 Rinv = eulerRateInverse(q);
  const Vec3 gb = A.transpose() * g;
  const Mat3 gs = skew(gb);
  K.addBlock(3, 3, Mat34(skew(firstMomentAt(q)) * gs * Rinv));
  for (int k = 0; k < nf_; ++k) K.addBlock(3, 7 + k, Vec3(-gs * inv_.sBar.col(k)));
  const Mat34 B = gs * Rinv;
  for (int j = 0; j < 4; ++j) {
    K.addColumn(6, 3 + j, nf_, [&](int k) { return inv_.sBar.col(k).dot(B.col(j)); });
  }
}

double FfrBody3d::gravityPotential(const ConstVecRef& q, const Vec3& g) const {
  return -g.dot(inv_.mass * q.head<3>() + rotationOf(q) * firstMomentAt(q));
}

double FfrBody3d::internalPotential(const ConstVecRef& q) const {
  const auto qf = q.tail(nf_);
  return model_ ? model_->strainEnergy(VecX(qf)) : 0.5 * bilinear(inv_.kff, qf, qf);
}

FfrBody3d::BeamDeflection FfrBody3d::beamDeflection(const ConstVecRef& q, int element, double xi) const {
  if (!model_) {
    throw InputError("body '" + name() + "': not made from a beam mesh; its deflection and section forces are unknown");
  }
  const VecX qf = q.tail(nf_);
  const FfrPoint3d p = model_->materialPoint(element, xi);
  BeamDeflection d;
  d.displacement = p.shape * qf;
  const Mat3 A = rotationOf(q);
  d.position = q.head<3>() + A * (p.position + d.displacement);  // r = R + A (u0 + N q_f) (Shabana2005, ch. 5)
  d.worldDisplacement = A * d.displacement;
  d.sectionForces = model_->sectionForces(qf, element, xi);
  return d;
}

Vec3 FfrBody3d::centreOfMass(const ConstVecRef& q) const {
  return q.head<3>() + rotationOf(q) * firstMomentAt(q) / inv_.mass;
}

// ----- points ------------------------------------------------------------------------

void FfrBody3d::pointKinematics(const ConstVecRef&, const Vec2&, int, const std::vector<int>*, bool,
                                PointKinematics&) const {
  throw InputError("body '" + name() + "' is spatial: planar joints and forces need planar bodies");
}

int FfrBody3d::resolvePoint(const Vec3& point, const std::string& user) const {
  double scale = 1.0;
  for (const auto& p : inv_.points) scale = std::max(scale, p.position.norm());
  // from the last: an FE body's interface frames follow its nodes and take precedence over
  // a node at the same place (docs/fe-import.md, "Interfaces")
  for (size_t k = inv_.points.size(); k-- > 0;) {
    if ((inv_.points[k].position - point).norm() <= 1e-9 * scale) return static_cast<int>(k);
  }
  std::ostringstream os;
  os << user << ": flexible body '" << name() << "' has no node at (" << point.x() << ", " << point.y() << ", "
     << point.z() << "); joints and forces attach to nodes (";
  for (size_t j = 0; j < inv_.points.size() && j < 6; ++j) {
    const Vec3& p = inv_.points[j].position;
    os << (j ? ", " : "") << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  }
  os << (inv_.points.size() > 6 ? ", ...)" : ")");
  throw InputError(os.str());
}

int FfrBody3d::nodeIndex(const Vec3& point, int pointId) const {
  if (pointId >= 0 && pointId < static_cast<int>(inv_.points.size())) return pointId;
  return resolvePoint(point, "attachment");  // not resolved: found by its coordinates
}

FfrBody3d::NodeMotion FfrBody3d::nodeMotion(const Vec3& point, int pointId, const ConstVecRef& qf) const {
  // u = u0 + N qf, theta = Ntheta qf over the node's support only (O(1) per node of a
  // nodal mesh, not O(nf))
  const int k = nodeIndex(point, pointId);
  const FfrPoint3d& pt = inv_.points[k];
  NodeMotion m{pt, pt.position, Vec3::Zero()};
  for (int c : nodeSupport_[k]) {
    m.u += pt.shape.col(c) * qf[c];
    m.theta += pt.rotationShape.col(c) * qf[c];
  }
  return m;
}

std::vector<int> FfrBody3d::pointSupport(const Vec3& point, int pointId) const {
  std::vector<int> cols = {0, 1, 2, 3, 4, 5};
  for (int e : nodeSupport_[nodeIndex(point, pointId)]) cols.push_back(6 + e);
  return cols;
}

void FfrBody3d::frameKinematics(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                                const std::vector<int>* qcols, FrameKinematics& out) const {
  // r = R + A u, u = u0 + N qf;  r' = R' - A u~ w + A N qf' (Shabana2005, ch. 5);
  // A_node = A (I + theta~), theta = Ntheta qf;  omega_node = A (w + Ntheta qf')  (first order)
  const auto qf = q.tail(nf_);
  const NodeMotion m = nodeMotion(point, pointId, qf);
  const FfrPoint3d& pt = m.point;
  const Vec3& u = m.u;
  const Vec3& theta = m.theta;
  const Mat3 A = rotationOf(q);
  out.r = q.head<3>() + A * u;
  out.A = A * (Mat3::Identity() + skew(theta));
  const int nv = cols ? static_cast<int>(cols->size()) : numVelocities();
  const int nq = qcols ? static_cast<int>(qcols->size()) : numCoordinates();
  out.Jr.resize(3, nv);
  out.Jw.resize(3, nv);
  const Mat3 Au = -A * skew(u);
  for (int a = 0; a < nv; ++a) {
    const int c = cols ? (*cols)[a] : a;
    if (c < 3) {
      out.Jr.col(a) = Vec3::Unit(c);
      out.Jw.col(a).setZero();
    } else if (c < 6) {
      out.Jr.col(a) = Au.col(c - 3);
      out.Jw.col(a) = A.col(c - 3);
    } else {
      out.Jr.col(a) = A * pt.shape.col(c - 6);
      out.Jw.col(a) = A * pt.rotationShape.col(c - 6);
    }
  }
  const Mat34 Rinv = eulerRateInverse(q);
  out.Tinv.resize(nv, nq);
  for (int i = 0; i < nv; ++i) {
    for (int j = 0; j < nq; ++j) out.Tinv(i, j) = tinvEntry(Rinv, cols ? (*cols)[i] : i, qcols ? (*qcols)[j] : j);
  }
}

void FfrBody3d::addFrameCurvature(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                                  const std::vector<int>* qcols, const Vec3& wr, const Vec3& ww,
                                  Eigen::Ref<MatX> out) const {
  // Jr^T wr + Jw^T ww = [wr; u~ br + bw; N^T br + Ntheta^T bw], br = A^T wr, bw = A^T ww;
  // d(A^T c)/dpi = (A^T c)~, dpi = Rinv dp; du/dqf = N.
  const auto qf = q.tail(nf_);
  const NodeMotion m = nodeMotion(point, pointId, qf);
  const FfrPoint3d& pt = m.point;
  const Vec3& u = m.u;
  const Mat3 A = rotationOf(q);
  const Mat34 Rinv = eulerRateInverse(q);
  const Vec3 br = A.transpose() * wr, bw = A.transpose() * ww;
  const Mat3 brs = skew(br), bws = skew(bw);
  const Mat34 rot = (skew(u) * brs + bws) * Rinv;  // rows theta, columns p
  const Mat34 B = brs * Rinv, Bw = bws * Rinv;      // d br/dp, d bw/dp
  const int nv = cols ? static_cast<int>(cols->size()) : numVelocities();
  const int nq = qcols ? static_cast<int>(qcols->size()) : numCoordinates();
  for (int i = 0; i < nv; ++i) {
    const int vi = cols ? (*cols)[i] : i;
    if (vi < 3) continue;
    for (int j = 0; j < nq; ++j) {
      const int qj = qcols ? (*qcols)[j] : j;
      if (qj < 3) continue;
      if (vi < 6) {
        if (qj < 7) {
          out(i, j) += rot(vi - 3, qj - 3);
        } else {
          out(i, j) -= brs.row(vi - 3).dot(pt.shape.col(qj - 7));  // -(br~ N)_(vi, k)
        }
      } else if (qj < 7) {
        out(i, j) += pt.shape.col(vi - 6).dot(B.col(qj - 3)) + pt.rotationShape.col(vi - 6).dot(Bw.col(qj - 3));
      }
    }
  }
}

}  // namespace flexmbd
