// Unit tests of the spatial floating-frame-of-reference body FfrBody3d (Shabana, Dynamics
// of Multibody Systems, ch. 5): r = R + A(p) (u0 + N q_f), v = (R' world, w body, q_f').
// The invariants are assembled here from BeamElement3d (tests/ffr3d_test_models.hpp):
//  - the mass matrix equals a direct volume quadrature of int rho J^T J (J = dr'/dv), so
//    1/2 v^T M v is the kinetic energy;
//  - the quadratic velocity forces equal d'Alembert's inertia forces -int rho J^T (J' v)
//    (Kane's form of the equations for the quasi-velocities w), with J' v by central
//    differences along the motion, and satisfy the power identity v.Q_v = -1/2 v^T M' v;
//  - every analytic derivative against central differences;
//  - a free flexible body conserves energy and momentum under the engine's integrator;
//  - a very stiff body moves as the RigidBody3d of the same inertia;
//  - input checks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/errors.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "core/system.hpp"
#include "ffr3d_test_models.hpp"
#include "simulation/simulation.hpp"
#include "joints/spatial_joint.hpp"
#include "free_body_drift.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::test3d;
using namespace flexmbd::testsupport;

namespace {

constexpr double kWidthY = 0.03, kHeightZ = 0.018;
const BeamSection3d kSteel = rectangularSection3d(kWidthY, kHeightZ, 2.1e11, 8.1e10, 7850.0, 0.0);
const Vec3 kHint(1.0, -1.0, 0.3);

// Tolerances. Quadrature: the tensor Gauss rule is exact for these polynomial integrands,
// so the comparison is at round-off of sums of O(10) terms: 1e-11 relative. Central
// differences with relative steps h = 1e-6 (1 + |x|): truncation O(h^2 f''') ~ 1e-12 and
// round-off eps |f| / h ~ 1e-10 relative: 1e-7 leaves margin for the largest entries.
constexpr double kQuadTol = 1e-11;
constexpr double kFdStep = 1e-6;
constexpr double kFdTol = 1e-7;
// Kane's inertia forces by central differences in time, step 1e-5 s: O(h^2) ~ 1e-10
// relative for motions at ~10 rad/s, round-off eps / h ~ 1e-11.
constexpr double kKaneTol = 1e-7;

void gaussRule(int n, std::vector<double>& xi, std::vector<double>& w) {
  MatX J = MatX::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
  const Eigen::SelfAdjointEigenSolver<MatX> es(J);
  xi.resize(n);
  w.resize(n);
  for (int k = 0; k < n; ++k) {
    xi[k] = 0.5 * (es.eigenvalues()[k] + 1.0);
    w[k] = es.eigenvectors()(0, k) * es.eigenvectors()(0, k);
  }
}

/// A material point of the body for volume quadrature: u0, N and the weight rho dV.
struct MassPoint {
  Vec3 u0;
  Mat3X N;
  double w;
  Mat3 C;        ///< the element's axes (body frame)
  Vec3 section;  ///< (0, y, z): the point's offset in its section, element axes
  Mat3X rotation;  ///< the section's rotation phi = rotation q_f (element axes)
};

/// 6 (along) x 4 x 4 (section) Gauss points per element: exact for the degree-6
/// polynomials in x and degree-2 in y, z of these integrands.
std::vector<MassPoint> massPoints(const BeamChain3d& c) {
  std::vector<double> gx, wx, gs, ws;
  gaussRule(6, gx, wx);
  gaussRule(4, gs, ws);
  std::vector<MassPoint> pts;
  for (int e = 0; e < static_cast<int>(c.elements.size()); ++e) {
    const double l = c.elements[e].length(), rho = c.elements[e].section().density;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k) {
          const double y = (gs[j] - 0.5) * kWidthY, z = (gs[k] - 0.5) * kHeightZ;
          const BeamElement3d& el = c.elements[e];
          pts.push_back({c.pointPosition(e, gx[i], y, z), c.pointShape(e, gx[i], y, z),
                         rho * wx[i] * ws[j] * ws[k] * l * kWidthY * kHeightZ, el.rotation(), Vec3(0, y, z),
                         c.sectionRotation(e, gx[i])});
        }
  }
  return pts;
}

/// J = dr'/dv (3 x nv) of a material point: [I, -A u~, A N].
MatX pointJacobian(const ConstVecRef& q, const MassPoint& p, int nf) {
  const Mat3 A = FfrBody3d::rotationOf(q);
  const Vec3 u = p.u0 + p.N * q.tail(nf);
  MatX J(3, 6 + nf);
  J << Mat3::Identity(), -A * skew(u), A * p.N;
  return J;
}

FrameState3d someFrame() {
  FrameState3d s;
  s.position = Vec3(0.3, -0.2, 1.1);
  s.orientation = quaternionRotation(Vec4(0.8, 0.3, -0.4, 0.25));
  s.velocity = Vec3(0.2, -0.1, 0.3);
  s.angularVelocity = Vec3(1.5, -2.0, 3.0);
  return s;
}

struct Fixture {
  explicit Fixture(BeamTheory theory = BeamTheory::EulerBernoulli)
      : chain(makeBeamChain(bentNodes(), kSteel, kHint, 1.0, theory)), body("flex", chain.inv, someFrame()), nf(chain.nf) {}
  BeamChain3d chain;
  FfrBody3d body;
  int nf;
};

constexpr BeamTheory kTheories[] = {BeamTheory::EulerBernoulli, BeamTheory::Rayleigh, BeamTheory::Timoshenko};
const char* theoryName(BeamTheory t) {
  return t == BeamTheory::Rayleigh ? "Rayleigh" : t == BeamTheory::Timoshenko ? "Timoshenko" : "Euler-Bernoulli";
}

/// A generic state: p of length 1.3 (the gauge is free), elastic coordinates of scale
/// `elastic` (displacements, m) and 10 x that for rotations.
void genericState(Random& rnd, int nf, double elastic, VecX& q, VecX& v, double pLength = 1.3) {
  q.resize(7 + nf);
  v.resize(6 + nf);
  q.head<3>() = rnd.vector(3, -1.0, 1.0);
  q.segment<4>(3) = pLength * rnd.vector(4, -1.0, 1.0).normalized();
  for (int k = 0; k < nf; ++k) q[7 + k] = (k % 6 < 3 ? 1.0 : 10.0) * rnd.uniform(-elastic, elastic);
  v.head<3>() = rnd.vector(3, -1.0, 1.0);
  v.segment<3>(3) = rnd.vector(3, -5.0, 5.0);
  for (int k = 0; k < nf; ++k) v[6 + k] = (k % 6 < 3 ? 1.0 : 10.0) * rnd.uniform(-elastic, elastic) * 20.0;
}

VecX internalForces(const Body& b, const VecX& q, const VecX& v) {
  VecX Q = VecX::Zero(b.numVelocities());
  b.addInternalForces(q, v, Q);
  return Q;
}

std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2e", x);
  return buf;
}

}  // namespace

TEST(FfrBody3d, MassMatrixIsTheVolumeQuadratureOfTheKineticEnergy) {
  // T = 1/2 int rho |r'|^2 dV of the first-order field u0 + N q_f, plus the rotational
  // inertia of the sections' second-order rotation (int rho (w x u0).(w x u2) dV,
  // BeamElement3d::sectionRotationMoment) and its coupling w . int rho u0 x u2' dV
  // (sectionRotationCoupling), all by volume quadrature; Euler-Bernoulli and Rayleigh.
  for (BeamTheory theory : kTheories) {
  SCOPED_TRACE(theoryName(theory));
  Fixture f(theory);
  const auto pts = massPoints(f.chain);
  Random rnd(11);
  double worst = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    VecX q, v;
    genericState(rnd, f.nf, 2e-2, q, v, 1.0);  // large deformations: the q_f-quadratic terms show
    MatX Mq = MatX::Zero(6 + f.nf, 6 + f.nf);
    double T = 0.0;
    Mat3 dJ = Mat3::Zero();               // int rho (u0 u2^T + u2 u0^T) dV
    MatX Yh = MatX::Zero(3, f.nf);         // int rho u0~ du2/dq_f dV
    for (const auto& p : pts) {
      const MatX J = pointJacobian(q, p, f.nf);
      Mq += p.w * J.transpose() * J;
      T += 0.5 * p.w * (J * v).squaredNorm();
      // the section's second-order rotation u2 = (1/2) phi~ phi~ r = (phi (phi.r) - |phi|^2 r) / 2
      const Vec3 phi = p.rotation * q.tail(f.nf), r = p.section;
      const Vec3 u2 = p.C * (0.5 * (phi * phi.dot(r) - phi.squaredNorm() * r));
      const Mat3 du2 = p.C * (0.5 * (phi * r.transpose() + phi.dot(r) * Mat3::Identity() - 2.0 * r * phi.transpose()));
      dJ += p.w * (p.u0 * u2.transpose() + u2 * p.u0.transpose());
      Yh += p.w * skew(p.u0) * du2 * p.rotation;
    }
    // it adds (tr dJ) 1 - dJ to the rotational inertia (1/2 w^T (.) w to T) and
    // w . Yh qf' to T (the theta-f coupling)
    const Mat3 dI = dJ.trace() * Mat3::Identity() - dJ;
    Mq.block<3, 3>(3, 3) += dI;
    Mq.block(3, 6, 3, f.nf) += Yh;
    Mq.block(6, 3, f.nf, 3) += Yh.transpose();
    T += 0.5 * v.segment<3>(3).dot(dI * v.segment<3>(3)) + v.segment<3>(3).dot(Yh * v.tail(f.nf));
    const MatX M = f.body.massMatrix(q);
    worst = std::max(worst, expectMatrixNear(M, Mq, kQuadTol, "mass matrix vs quadrature"));
    EXPECT_NEAR(0.5 * v.dot(M * v), T, kQuadTol * T);
    // addMassTimes agrees with the matrix
    VecX Ma = VecX::Zero(6 + f.nf);
    f.body.addMassTimes(q, v, Ma);
    expectMatrixNear(Ma, M * v, 1e-13, "addMassTimes");
    EXPECT_NEAR(f.body.mass(), [&] { double m = 0; for (const auto& p : pts) m += p.w; return m; }(), 1e-12);
  }
  std::printf("[ figures ] %s: mass matrix vs volume quadrature: max relative error %s\n", theoryName(theory),
              sci(worst).c_str());
  }
}

TEST(FfrBody3d, QuadraticVelocityForcesAreDAlembertsInertiaForces) {
  // Kane / d'Alembert for the quasi-velocities (R', w, q_f'): M v' = Q_v + Q with
  // Q_v = -int rho J^T (J' v) dV, J' v = d/dt (J(q(t)) v) at fixed v along q' = T v.
  // applyIncrement(q, h v) is exactly the motion at constant v over h (R + h R',
  // p (x) exp(h w / 2), q_f + h q_f'), so J' v = (J(q (+) h v) - J(q (+) -h v)) v / 2h.
  // These are the forces of the first-order field u0 + N q_f: the body `first` without
  // the sections' second-order rotation (R_kl); the power identity holds for all, the
  // Rayleigh body's too (rotary inertia, R_kl and H_i).
  Fixture f;
  FfrInvariants3d firstOrder = f.chain.inv;
  for (auto& row : firstOrder.rKL)
    for (SpMat& R : row) R = SpMat();
  const FfrBody3d first("first order", firstOrder, someFrame());
  const Fixture rayleigh(BeamTheory::Rayleigh);  // same nodes: the same coordinates
  const Fixture timoshenko(BeamTheory::Timoshenko);
  const auto pts = massPoints(f.chain);
  Random rnd(12);
  double worst = 0.0, worstPower = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    VecX q, v;
    genericState(rnd, f.nf, 1e-2, q, v, 1.0);
    const double h = 1e-5;
    VecX qp(q.size()), qm(q.size());
    f.body.applyIncrement(q, h * v, qp);
    f.body.applyIncrement(q, -h * v, qm);
    VecX Qref = VecX::Zero(6 + f.nf);
    for (const auto& p : pts) {
      const Vec3 acc = (pointJacobian(qp, p, f.nf) * v - pointJacobian(qm, p, f.nf) * v) / (2.0 * h);
      Qref -= p.w * pointJacobian(q, p, f.nf).transpose() * acc;
    }
    // the quadratic velocity forces: the internal forces less the elastic ones (D_ff = 0)
    const VecX Q1 = internalForces(first, q, v) - internalForces(first, q, VecX::Zero(v.size()));
    worst = std::max(worst, expectMatrixNear(Q1, Qref, kKaneTol, "quadratic velocity forces vs d'Alembert"));
    // power: v.Q_v = -1/2 v^T (dM/dt) v (the quadratic velocity forces do no work on the
    // kinetic energy other than through dM/dt)
    for (const FfrBody3d* b : std::initializer_list<const FfrBody3d*>{&first, &f.body, &rayleigh.body, &timoshenko.body}) {
      const VecX Q = internalForces(*b, q, v) - internalForces(*b, q, VecX::Zero(v.size()));
      const double dMdt = (v.dot(b->massMatrix(qp) * v) - v.dot(b->massMatrix(qm) * v)) / (2.0 * h);
      const double power = v.dot(Q), scale = std::abs(dMdt) + Q.cwiseAbs().maxCoeff() * v.norm();
      EXPECT_NEAR(power, -0.5 * dMdt, kKaneTol * scale) << b->name();
      worstPower = std::max(worstPower, std::abs(power + 0.5 * dMdt) / scale);
    }
  }
  std::printf("[ figures ] Q_v vs d'Alembert quadrature: %s; power identity: %s\n", sci(worst).c_str(),
              sci(worstPower).c_str());
}

TEST(FfrBody3d, AnalyticDerivativesMatchCentralDifferences) {
  for (BeamTheory theory : kTheories) {
  SCOPED_TRACE(theoryName(theory));
  Fixture f(theory);
  // with damping, so that D_ff enters the velocity Jacobian, and spin stiffening G_kl
  // (symmetric, G_lk = G_kl) so that it enters both
  FfrInvariants3d inv = f.chain.inv;
  inv.dff = 1e-4 * inv.kff;
  for (int k = 0; k < 3; ++k)
    for (int l = k; l < 3; ++l) inv.spinStiffness[k][l] = inv.spinStiffness[l][k] = (0.3 + k + 2 * l) * 1e-3 * inv.mff;
  const FfrBody3d body("damped", inv, someFrame());
  const int nq = 7 + f.nf, nv = 6 + f.nf;
  Random rnd(13);
  VecX q, v;
  genericState(rnd, f.nf, 1e-3, q, v);
  const VecX a = rnd.vector(nv, -1.0, 1.0);
  const Vec3 g(0.3, -1.2, -9.81);
  const VecX hq = relativeSteps(q, kFdStep), hv = relativeSteps(v, kFdStep);
  std::vector<std::pair<std::string, double>> figures;
  auto check = [&](const MatX& an, const MatX& fd, const std::string& what) {
    figures.push_back({what, expectMatrixNear(an, fd, kFdTol, what)});
  };
  {
    MatX K = MatX::Zero(nv, nq);
    body.addMassMatrixDerivative(q, a, K);
    check(K, fdJacobian([&](const VecX& x) { VecX o = VecX::Zero(nv); body.addMassTimes(x, a, o); return o; }, q, hq),
          "d(M a)/dq");
  }
  {
    MatX Kq = MatX::Zero(nv, nq), Kv = MatX::Zero(nv, nv);
    body.addInternalForceJacobians(q, v, Kq, Kv);
    check(Kq, fdJacobian([&](const VecX& x) { return internalForces(body, x, v); }, q, hq), "dQ/dq");
    check(Kv, fdJacobian([&](const VecX& x) { return internalForces(body, q, x); }, v, hv), "dQ/dv");
  }
  {
    MatX K = MatX::Zero(nv, nq);
    body.addGravityJacobian(q, g, K);
    auto grav = [&](const VecX& x) { VecX Q = VecX::Zero(nv); body.addGravityForce(x, g, Q); return Q; };
    check(K, fdJacobian(grav, q, hq), "d(gravity)/dq");
    // Q_g = -T^T dV/dq
    MatX T;
    body.coordinateRateMatrix(q, T);
    const VecX dV = fdGradient([&](const VecX& x) { return body.gravityPotential(x, g); }, q, hq);
    check(grav(q), -T.transpose() * dV, "gravity force = -T^T dV/dq");
    const VecX dU = fdGradient([&](const VecX& x) { return body.internalPotential(x); }, q, hq);
    VecX Qe = VecX::Zero(nv);
    body.addInternalForces(q, VecX::Zero(nv), Qe);
    check(Qe, -T.transpose() * dU, "elastic force = -T^T dU/dq (v = 0)");
  }
  {
    MatX K = MatX::Zero(nq, nq);
    body.addCoordinateRateJacobian(q, v, K);
    auto rate = [&](const VecX& x) { VecX o = VecX::Zero(nq); body.addCoordinateRate(x, v, o); return o; };
    check(K, fdJacobian(rate, q, hq), "d(T v)/dq");
    MatX T, Ti;
    body.coordinateRateMatrix(q, T);
    body.coordinateRateInverse(q, Ti);
    check(Ti * T, MatX::Identity(nv, nv), "T+ T = I");
    check(rate(q), T * v, "addCoordinateRate = T v");
  }
  for (const auto& [what, err] : figures) {
    std::printf("[ figures ] %s: %-40s FD relative error %s\n", theoryName(theory), what.c_str(), sci(err).c_str());
  }
  }
}

/// The fixture's chain as a beam mesh model (clamped at node 0, nodal coordinates).
std::shared_ptr<const FfrBeamModel3d> chainModel(bool stiffening) {
  BeamMesh3d mesh;
  mesh.nodes = bentNodes();
  for (int e = 0; e + 1 < static_cast<int>(mesh.nodes.size()); ++e) mesh.elements.push_back({e, e + 1, kSteel, kHint});
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  o.geometricStiffening = stiffening;
  return std::make_shared<const FfrBeamModel3d>(mesh, o, "body 'flex'");
}

TEST(FfrBody3d, ChainOracleEqualsTheBeamModel) {
  // The test-local chain (tests/ffr3d_test_models.hpp) and FfrBeamModel3d assemble the
  // same invariants by separate code: equal to round-off (1e-12 of each matrix's largest
  // entry: sums of a few element terms).
  Fixture f;
  const FfrInvariants3d& a = f.chain.inv;
  const auto model = chainModel(false);
  const FfrInvariants3d& b = model->invariants();
  ASSERT_EQ(b.numElastic(), f.nf);
  constexpr double kTol = 1e-12;
  auto near = [&](const MatX& x, const MatX& y, const std::string& what) {
    expectMatrixNear(x, y, kTol, what, y.cwiseAbs().maxCoeff());
  };
  EXPECT_NEAR(a.mass, b.mass, kTol * b.mass);
  near(a.firstMoment, b.firstMoment, "first moment");
  near(a.secondMoment, b.secondMoment, "second moment");
  near(a.sBar, b.sBar, "S-bar");
  near(MatX(a.mff), MatX(b.mff), "m_ff");
  near(MatX(a.kff), MatX(b.kff), "K_ff");
  for (int k = 0; k < 3; ++k) {
    near(a.positionShape[k], b.positionShape[k], "position shape " + std::to_string(k));
    for (int l = 0; l < 3; ++l) {
      near(MatX(a.sKL[k][l]), MatX(b.sKL[k][l]), "S_" + std::to_string(k) + std::to_string(l));
      near(MatX(a.rKL[k][l]), MatX(b.rKL[k][l]), "R_" + std::to_string(k) + std::to_string(l));
    }
  }
}

TEST(FfrBody3d, GeometricStiffeningForcesAndJacobianFromTheBeamModel) {
  // A body made from the beam model with stiffening: its elastic force is -dU/dq of the
  // model's nonlinear strain energy (central differences, kFdTol) and its Jacobian the FD
  // of the force; at elastic displacements of 1e-2 m the stiffening changes the elastic
  // force by far more than the FD error (asserted > 1e-4 relative), so the check sees it.
  const FfrBody3d lin("flex", chainModel(false), someFrame()), stiff("flex", chainModel(true), someFrame());
  const int nf = stiff.numElastic(), nq = 7 + nf, nv = 6 + nf;
  Random rnd(29);
  VecX q, v;
  genericState(rnd, nf, 1e-2, q, v);
  const VecX hq = relativeSteps(q, kFdStep);
  const VecX zero = VecX::Zero(nv);
  MatX T;
  stiff.coordinateRateMatrix(q, T);
  const VecX dU = fdGradient([&](const VecX& x) { return stiff.internalPotential(x); }, q, hq);
  const VecX Qs = internalForces(stiff, q, zero), Ql = internalForces(lin, q, zero);
  const double e1 = expectMatrixNear(Qs, -T.transpose() * dU, kFdTol, "elastic force = -T^T dU/dq");
  EXPECT_GT((Qs - Ql).norm(), 1e-4 * Ql.norm()) << "stiffening has no effect";
  MatX Kq = MatX::Zero(nv, nq), Kv = MatX::Zero(nv, nv);
  stiff.addInternalForceJacobians(q, v, Kq, Kv);
  const double e2 =
      expectMatrixNear(Kq, fdJacobian([&](const VecX& x) { return internalForces(stiff, x, v); }, q, hq), kFdTol, "dQ/dq");
  std::printf("[ figures ] stiffening: force vs -dU/dq %s, dQ/dq %s, |Q_stiff - Q_lin| / |Q_lin| %s\n", sci(e1).c_str(),
              sci(e2).c_str(), sci((Qs - Ql).norm() / Ql.norm()).c_str());
}

TEST(FfrBody3d, NodeFrameKinematicsAndCurvature) {
  Fixture f;
  const FfrBody3d& body = f.body;
  const int nq = 7 + f.nf, nv = 6 + f.nf;
  Random rnd(14);
  VecX q, v;
  genericState(rnd, f.nf, 1e-3, q, v);
  const Vec3 wr = rnd.vector(3, -1.0, 1.0), ww = rnd.vector(3, -1.0, 1.0);
  double worstJr = 0.0, worstJw = 0.0, worstCurv = 0.0;
  for (int node = 0; node < 4; ++node) {
    const Vec3 point = f.chain.nodes[node];
    const int id = body.resolvePoint(point, "test");
    ASSERT_EQ(id, node);
    FrameKinematics fk;
    body.frameKinematics(q, point, id, nullptr, nullptr, fk);
    // Jr, Jw along velocity directions: q (+) h e_i
    MatX Jr(3, nv), dA(9, nv);
    for (int i = 0; i < nv; ++i) {
      const double h = kFdStep;
      VecX e = VecX::Zero(nv), qp(nq), qm(nq);
      e[i] = h;
      body.applyIncrement(q, e, qp);
      body.applyIncrement(q, -e, qm);
      FrameKinematics kp, km;
      body.frameKinematics(qp, point, id, nullptr, nullptr, kp);
      body.frameKinematics(qm, point, id, nullptr, nullptr, km);
      Jr.col(i) = (kp.r - km.r) / (2.0 * h);
      const Mat3 d = (kp.A - km.A) / (2.0 * h);
      dA.col(i) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(d.data());
    }
    worstJr = std::max(worstJr, expectMatrixNear(fk.Jr, Jr, kFdTol, "Jr, node " + std::to_string(node)));
    // Jw: dA_node = (Jw e_i)~ A_node + O(|theta|) (A_node first order in theta)
    const double theta = (f.chain.inv.points[node].rotationShape * q.tail(f.nf)).norm();
    MatX wAn(9, nv);
    for (int i = 0; i < nv; ++i) {
      const Mat3 d = skew(fk.Jw.col(i)) * fk.A;
      wAn.col(i) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(d.data());
    }
    worstJw = std::max(worstJw, expectMatrixNear(wAn, dA, kFdTol + 4.0 * theta, "Jw, node " + std::to_string(node)));
    // the frame columns exactly
    expectMatrixNear(wAn.leftCols(6), dA.leftCols(6), kFdTol, "Jw frame columns, node " + std::to_string(node));
    // curvature d(Jr^T wr + Jw^T ww)/dq, over all columns and over the support only
    auto weighted = [&](const VecX& x) {
      FrameKinematics k;
      body.frameKinematics(x, point, id, nullptr, nullptr, k);
      return VecX(k.Jr.transpose() * wr + k.Jw.transpose() * ww);
    };
    const MatX Cfd = fdJacobian(weighted, q, relativeSteps(q, kFdStep));
    MatX C = MatX::Zero(nv, nq);
    body.addFrameCurvature(q, point, id, nullptr, nullptr, wr, ww, C);
    worstCurv = std::max(worstCurv, expectMatrixNear(C, Cfd, kFdTol, "curvature, node " + std::to_string(node)));
    const std::vector<int> cols = body.pointSupport(point, id), qcols = body.coordinatesOfVelocities(cols);
    EXPECT_EQ(cols.size(), node == 0 ? 6u : 12u);
    MatX Cs = MatX::Zero(cols.size(), qcols.size());
    body.addFrameCurvature(q, point, id, &cols, &qcols, wr, ww, Cs);
    FrameKinematics ks;
    body.frameKinematics(q, point, id, &cols, &qcols, ks);
    MatX Ti;
    body.coordinateRateInverse(q, Ti);
    for (size_t i = 0; i < cols.size(); ++i) {
      EXPECT_EQ(ks.Jr.col(i), fk.Jr.col(cols[i]));
      EXPECT_EQ(ks.Jw.col(i), fk.Jw.col(cols[i]));
      for (size_t j = 0; j < qcols.size(); ++j) {
        EXPECT_EQ(Cs(i, j), C(cols[i], qcols[j]));
        EXPECT_EQ(ks.Tinv(i, j), Ti(cols[i], qcols[j]));
      }
    }
    // columns outside the support are zero
    for (int i = 0; i < nv; ++i) {
      if (std::find(cols.begin(), cols.end(), i) != cols.end()) continue;
      EXPECT_EQ(fk.Jr.col(i).norm() + fk.Jw.col(i).norm(), 0.0);
    }
  }
  std::printf("[ figures ] node frames: Jr %s, Jw %s (first order in theta), curvature %s\n", sci(worstJr).c_str(),
              sci(worstJw).c_str(), sci(worstCurv).c_str());
}

TEST(FfrBody3d, FreeFlexibleBodyConservesEnergyAndMomentum) {
  // No gravity, no damping: energy, linear momentum and angular momentum about the world
  // origin, H = R x L + A (M v)_w (L = (M v)_R), are constants of the motion.
  Fixture f;
  VecX qf0 = VecX::Zero(f.nf), qf0dot = VecX::Zero(f.nf);
  for (int k = 0; k < f.nf; ++k) qf0dot[k] = (k % 6 < 3 ? 0.02 : 0.1) * std::sin(1.0 + k);  // vibrating
  SolverSettings st;
  st.rtol = 1e-9;
  st.atol = 1e-11;
  st.tEnd = 0.3;
  st.outputStep = 0.01;
  const testsupport::FreeBodyDrift d =
      testsupport::freeBodyDrift(std::make_unique<FfrBody3d>("flex", f.chain.inv, someFrame(), qf0, qf0dot), st);
  ASSERT_TRUE(d.summary.ok) << d.summary.message;
  ASSERT_GT(d.outputs, 10u);
  // BDF at rtol 1e-9 over ~30 vibration periods of the first modes: drift well below 1e-6
  EXPECT_LT(d.energy, 1e-6);
  EXPECT_LT(d.momentum, 1e-6);
  EXPECT_LT(d.angularMomentum, 1e-6);
  std::printf("[ figures ] free flexible body, 0.3 s, rtol 1e-9: energy drift %s, |dL|/|L| %s, |dH|/|H| %s, %d steps\n",
              sci(d.energy).c_str(), sci(d.momentum).c_str(), sci(d.angularMomentum).c_str(),
              static_cast<int>(d.summary.stats.steps));
}

TEST(FfrBody3d, FlexiblePendulumOnASphericalJointConservesEnergy) {
  // The body hangs from a spherical joint at its clamped node 0 (frame kinematics, T+ and
  // the curvature enter the constraint Jacobians), gravity on, no damping: the energy
  // 1/2 v^T M v + U + V_g is conserved and the joint holds.
  Fixture f;
  System sys;
  sys.setGravity(Vec3(0.0, 0.0, -9.81));
  FrameState3d s = someFrame();
  s.velocity.setZero();
  s.angularVelocity = Vec3(0.5, -1.0, 0.8);
  s.velocity = -s.orientation * s.angularVelocity.cross(f.chain.nodes[0]);  // node 0 at rest
  auto body = std::make_unique<FfrBody3d>("flex", f.chain.inv, s);
  const FfrBody3d* b = body.get();
  const BodyIndex bi = sys.addBody(std::move(body));
  JointFrame g0, f0;
  g0.point = s.position + s.orientation * f.chain.nodes[0];
  f0.point = f.chain.nodes[0];
  sys.addConstraint(std::make_unique<SpatialJoint>("ball", SpatialJointType::Spherical, kGround, g0, bi, f0));
  sys.finalize();
  const int oq = sys.coordinateOffset(bi), ov = sys.velocityOffset(bi);
  std::vector<double> E;
  double T0 = 0.0;
  SolverSettings st;
  st.rtol = 1e-9;
  st.atol = 1e-11;
  st.tEnd = 0.3;
  st.outputStep = 0.01;
  st.progress = false;
  const SimulationSummary sum = simulate(sys, st, [&](const OutputSample& o) {
    const VecX q = o.q.segment(oq, 7 + f.nf), v = o.v.segment(ov, 6 + f.nf);
    VecX Mv = VecX::Zero(6 + f.nf);
    b->addMassTimes(q, v, Mv);
    if (E.empty()) T0 = 0.5 * v.dot(Mv);
    E.push_back(0.5 * v.dot(Mv) + b->internalPotential(q) + b->gravityPotential(q, sys.gravity()));
  });
  ASSERT_TRUE(sum.ok) << sum.message;
  double dE = 0.0;
  for (double e : E) dE = std::max(dE, std::abs(e - E[0]));
  const double scale = T0 + b->mass() * 9.81 * 0.5;  // kinetic energy + m g (a length of the body)
  EXPECT_LT(dE / scale, 1e-6);
  EXPECT_LT(sum.maxPositionViolation, 1e-8);
  std::printf("[ figures ] flexible pendulum, 0.3 s, rtol 1e-9: energy drift %s of %s J, joint violation %s m, %d steps\n",
              sci(dE / scale).c_str(), sci(scale).c_str(), sci(sum.maxPositionViolation).c_str(),
              static_cast<int>(sum.stats.steps));
}

TEST(FfrBody3d, VeryStiffBodyMovesAsTheRigidBodyOfTheSameInertia) {
  // K_ff x 1e6 (and light stiffness-proportional damping that removes the start-up
  // transient): the elastic coordinates stay ~1e-6 of the flexible case, and the frame
  // follows a RigidBody3d with the same mass and the inertia about the centre of mass
  // (the rigid body's reference point is the centre of mass: c = first moment / m).
  const BeamChain3d chain = makeBeamChain(bentNodes(), kSteel, kHint, 1e6);
  FfrInvariants3d inv = chain.inv;
  inv.dff = 1e-5 * inv.kff;
  const FrameState3d frame = someFrame();
  const Vec3 c = inv.firstMoment / inv.mass;
  const Mat3 J0 = inv.secondMoment - inv.mass * c * c.transpose();  // about the centre of mass
  RigidBody3dProperties rp;
  rp.mass = inv.mass;
  rp.inertia = J0.trace() * Mat3::Identity() - J0;
  FrameState3d rs = frame;
  rs.position = frame.position + frame.orientation * c;
  rs.velocity = frame.velocity + frame.orientation * frame.angularVelocity.cross(c);
  System flex, rigid;
  flex.addBody(std::make_unique<FfrBody3d>("flex", inv, frame));
  rigid.addBody(std::make_unique<RigidBody3d>("rigid", rp, rs));
  flex.finalize();
  rigid.finalize();
  SolverSettings st;
  st.rtol = 1e-8;
  st.atol = 1e-10;
  st.tEnd = 1.0;
  st.outputStep = 0.1;
  st.progress = false;
  std::vector<VecX> qf, qr;
  ASSERT_TRUE(simulate(flex, st, [&](const OutputSample& o) { qf.push_back(o.q); }).ok);
  ASSERT_TRUE(simulate(rigid, st, [&](const OutputSample& o) { qr.push_back(o.q); }).ok);
  ASSERT_EQ(qf.size(), qr.size());
  const FfrBody3d& fb = dynamic_cast<const FfrBody3d&>(flex.body(BodyIndex(1)));
  double dPos = 0.0, dRot = 0.0, maxElastic = 0.0;
  for (size_t k = 0; k < qf.size(); ++k) {
    const VecX q = qf[k].segment(flex.coordinateOffset(BodyIndex(1)), 7 + chain.nf);
    const VecX r = qr[k].segment(rigid.coordinateOffset(BodyIndex(1)), 7);
    dPos = std::max(dPos, (fb.centreOfMass(q) - r.head<3>()).norm());
    dRot = std::max(dRot, (FfrBody3d::rotationOf(q) - RigidBody3d::rotationOf(r)).norm());
    maxElastic = std::max(maxElastic, q.tail(chain.nf).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(dPos, 1e-6);
  EXPECT_LT(dRot, 1e-5);
  std::printf("[ figures ] stiff vs rigid over 1 s: |d centre of mass| %s m, |d A| %s, max |q_f| %s\n",
              sci(dPos).c_str(), sci(dRot).c_str(), sci(maxElastic).c_str());
}

TEST(FfrBody3d, CoordinatesNamesAndStructure) {
  Fixture f;
  const FfrBody3d& b = f.body;
  EXPECT_EQ(b.numCoordinates(), 7 + 18);
  EXPECT_EQ(b.numVelocities(), 6 + 18);
  EXPECT_EQ(b.numFrameCoordinates(), 7);
  EXPECT_EQ(b.numFrameVelocities(), 6);
  EXPECT_EQ(b.coordinateNames()[3], "e0");
  EXPECT_EQ(b.coordinateNames()[7], "q1");
  EXPECT_EQ(b.velocityNames()[5], "wz");
  EXPECT_EQ(b.velocityNames()[6], "q1_dot");
  EXPECT_EQ(b.coordinateKinds()[6], CoordinateKind::Angle);
  EXPECT_EQ(b.coordinateKinds()[7], CoordinateKind::Elastic);
  EXPECT_EQ(b.velocityKinds()[5], CoordinateKind::Angle);
  EXPECT_EQ(b.velocityKinds()[6], CoordinateKind::Elastic);
  EXPECT_EQ(b.coordinatesOfVelocities({1, 4, 6, 9}), (std::vector<int>{1, 3, 4, 5, 6, 7, 10}));
  const VecX q = b.initialCoordinates();
  EXPECT_NEAR((FfrBody3d::rotationOf(q) - someFrame().orientation).norm(), 0.0, 1e-14);
  // mass matrix: symmetric positive definite; elastic block only where m_ff is
  Random rnd(15);
  VecX qq, v;
  genericState(rnd, f.nf, 1e-3, qq, v);
  const MatX M = b.massMatrix(qq);
  EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-12 * M.cwiseAbs().maxCoeff());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(M).eigenvalues().minCoeff(), 0.0);
  const MatX mff(f.chain.inv.mff);
  EXPECT_EQ((M.bottomRightCorner(f.nf, f.nf) - mff).cwiseAbs().maxCoeff(), 0.0);
  // centre of mass
  const Vec3 c = FfrBody3d::rotationOf(qq) * b.firstMomentAt(qq) / b.mass() + qq.head<3>();
  EXPECT_LT((b.centreOfMass(qq) - c).norm(), 1e-14);
  // an increment renormalises p and adds the rest
  VecX out(qq.size());
  VecX dv = VecX::Zero(6 + f.nf);
  dv[7] = 0.1;
  b.applyIncrement(qq, dv, out);
  EXPECT_NEAR(out.segment<4>(3).norm(), 1.0, 1e-15);
  EXPECT_EQ(out[8], qq[8] + 0.1);
}

TEST(FfrBody3d, InputErrors) {
  Fixture f;
  expectInputError([&] { f.body.resolvePoint(Vec3(1.0, 2.0, 3.0), "joint 'j'"); },
                   {"joint 'j'", "flexible body 'flex'", "no node at (1, 2, 3)", "(0.05, -0.02, 0.01)"});
  PointKinematics pk;
  expectInputError([&] { f.body.pointKinematics(f.body.initialCoordinates(), Vec2(0.0, 0.0), 0, nullptr, false, pk); },
                   {"spatial"});
  FfrInvariants3d bad = f.chain.inv;
  bad.sBar = Mat3X::Zero(3, 5);
  expectInputError([&] { FfrBody3d("b", bad, someFrame()); }, {"body 'b'", "s_bar", "3 x 18"});
  bad = f.chain.inv;
  bad.sKL[0][1].coeffRef(0, 0) += 1.0;
  expectInputError([&] { FfrBody3d("b", bad, someFrame()); }, {"body 'b'", "s_yx", "transpose of s_xy"});
  bad = f.chain.inv;
  bad.firstMoment[1] = NAN;
  expectInputError([&] { FfrBody3d("b", bad, someFrame()); }, {"body 'b'", "first_moment", "finite"});
  expectInputError([&] { FfrBody3d("b", f.chain.inv, someFrame(), VecX::Zero(3)); }, {"body 'b'", "18 entries"});
  FrameState3d s = someFrame();
  s.orientation(0, 0) = 2.0;
  expectInputError([&] { FfrBody3d("b", f.chain.inv, s); }, {"orientation"});
}
