// Unit tests of the planar floating-frame-of-reference body (document 003; Shabana,
// Dynamics of Multibody Systems, ch. 5-7): r = R + A(theta) (u0 + N q_f).
//  - the invariants a beam mesh generates (FfrBeamModel) against closed forms of
//    slender rods, for straight and bent meshes, with and without the first node at
//    the frame origin;
//  - the key independent check of every invariant formula: the mass matrix equals
//    the direct quadrature of int rho J^T J (J = dr/dq at a material point), hence
//    1/2 v^T M v equals 1/2 int rho |rdot|^2, for nodal and modal models;
//  - the quadratic velocity forces against Lagrange's equations (-(dM/dt) v + dT/dq);
//  - every analytic derivative of FfrBody2d against central finite differences;
//  - rigid-body displacements give no elastic force;
//  - natural frequencies of straight beams against the Euler-Bernoulli closed forms,
//    with the O(h^4) convergence of cubic Hermite elements;
//  - modal reduction, and the input checks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "problems/ffr_test_models.hpp"
#include "bodies/ffr_invariants.hpp"
#include "core/errors.hpp"
#include "core/system_evaluation.hpp"
#include "elements/beam_element_2d.hpp"
#include "tests/test_support.hpp"

namespace flexmbd {
namespace {

using namespace testsupport;

// Fixed seed: the random configurations are the same on every run (reproducible).
constexpr unsigned kSeed = 20240611u;
// Random configurations per case: enough to visit every quadrant of the frame angle.
constexpr int kSamples = 6;

// Invariants vs closed forms, and quadrature vs the mass matrix: both sides are sums
// of a few hundred products of O(1) numbers (nodes within 1.5 m, rho A ~ 1 kg/m), each
// exact in exact arithmetic (the quadratures are exact for the polynomial degrees
// involved): roundoff <= ~1e-14 relative. 1e-12 bounds that with a margin; a wrong
// term (a missing factor 2, a transposed S~, a wrong sign of J0) is O(1e-3..1).
constexpr double kExactTol = 1e-12;
// Symmetry of assembled matrices: T^T M T per element in a different order of the
// floating-point additions for (i, j) and (j, i): a few ulps.
constexpr double kSymmetryTol = 1e-14;

// Central differences with respect to q: frame coordinates h = kFdRelStep (1 + |x|):
// truncation h^2/6 |f'''| / |f| ~ 2e-13 (trigonometric in theta), roundoff eps |f| / h ~
// 2e-10 relative. Elastic coordinates h = kFdElasticStep * (the largest |q_f| of the
// sample): they are small (nodal ~1e-2 m, modal ~1e-3) and, with stiffening, their
// nonlinearity scale is their own size (v'^2/2 competes with u'), so a step relative
// to 1 would be far too coarse; a step much smaller than 1e-4 |q_f| would in turn let
// the roundoff eps |U| / h of the large axial energy swamp the small slope rows.
// Truncation (h / |q_f|)^2 / 6 ~ 2e-9 of the nonlinear part; roundoff eps |f| / h ~
// 1e-14 |f| / |q_f|, relative <~ 1e-10. Everything else is at most quadratic in q_f.
constexpr double kFdRelStep = 1e-6;
constexpr double kFdElasticStep = 1e-4;
// With respect to v: every force is at most quadratic in v, so the central difference
// is exact up to roundoff, and a large step keeps the roundoff of the large elastic
// force in the elastic rows (eps |K q_f| / h) small: h = kFdVelocityStep (1 + |v|).
constexpr double kFdVelocityStep = 1e-2;
// Analytic vs FD, per row, relative to max(1, largest entry of that row): measured
// <= ~1e-8. A wrong inertia term in an elastic row (entries ~ w^2 m_ff ~ 1 against
// stiffness entries ~ 4e4, ratio 2.5e-5) still shows up as >= 1e-5 relative.
constexpr double kFdTol = 1e-7;
// Lagrange consistency: differences (along v for dM/dt, along each q_k for dT/dq) with
// h = kLagrangeStep (1 + |x|) of functions trigonometric in theta and quadratic in q_f
// (so exact in q_f): truncation ~ h^2/6 ~ 2e-11, roundoff eps T / h ~ 2e-11 T,
// relative to the force scale T / size.
constexpr double kLagrangeStep = 1e-5;
constexpr double kLagrangeTol = 1e-8;

/// Steps for differences with respect to the coordinates q = (x, y, theta, q_f).
VecX coordinateSteps(const VecX& q) {
  VecX h(q.size());
  const double qfScale = q.size() > 3 ? q.tail(q.size() - 3).cwiseAbs().maxCoeff() : 1.0;
  for (int k = 0; k < q.size(); ++k) h[k] = k < 3 ? kFdRelStep * (1.0 + std::abs(q[k])) : kFdElasticStep * qfScale;
  return h;
}

/// Steps for differences with respect to the velocities (functions quadratic in v).
VecX velocitySteps(const VecX& v) { return kFdVelocityStep * (VecX::Ones(v.size()) + v.cwiseAbs()); }

/// Gauss-Legendre rule with n points on [0, 1] (Golub-Welsch), exact to degree 2n-1.
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

// ----- models ---------------------------------------------------------------------------

/// A soft aluminium-like rod: rho A = 1 kg/m, EA = 1e4 N, EI = 1 N m^2 (A/I = 1e4, a
/// ~3.5 cm square). Soft enough that the inertia terms of the elastic equations are
/// not lost against the stiffness in the derivative checks.
BeamSection softSection(double damping = 0.0) {
  BeamSection s;
  s.area = 1e-3;
  s.inertia = 1e-7;
  s.youngsModulus = 1e7;
  s.density = 1000.0;
  s.damping = damping;
  s.shearModulus = 4e6;      // Timoshenko elements only (phi ~ 0.06 on 0.25 m elements)
  s.shearFactor = 5.0 / 6.0;
  return s;
}

/// A second section for bent frames (different rho A on the second leg).
BeamSection heavySection(double damping = 0.0) {
  BeamSection s = softSection(damping);
  s.area = 1.5e-3;
  s.inertia = 2e-7;
  s.density = 1200.0;
  return s;
}

/// L-shaped frame: (0,0)-(0.3,0)-(0.3,0.2) shifted by `offset`, `perLeg` elements on
/// each leg; the second leg has another section.
BeamMesh2d lFrame(int perLeg, const Vec2& offset = Vec2::Zero(), double damping = 0.0) {
  BeamMesh2d m;
  const Vec2 P0(0, 0), P1(0.3, 0), P2(0.3, 0.2);
  for (int i = 0; i <= perLeg; ++i) m.nodes.push_back(offset + P0 + (P1 - P0) * double(i) / perLeg);
  for (int i = 1; i <= perLeg; ++i) m.nodes.push_back(offset + P1 + (P2 - P1) * double(i) / perLeg);
  for (int i = 0; i < perLeg; ++i) m.elements.push_back({i, i + 1, softSection(damping)});
  for (int i = perLeg; i < 2 * perLeg; ++i) m.elements.push_back({i, i + 1, heavySection(damping)});
  return m;
}

FfrBeamOptions options(ReferenceConditions::Type type, int modes = 0, bool stiffening = false, int nodeA = 0,
                       int nodeB = -1, BeamTheory theory = BeamTheory::EulerBernoulli) {
  FfrBeamOptions o;
  o.theory = theory;
  o.reference.type = type;
  o.reference.nodeA = nodeA;
  o.reference.nodeB = nodeB;
  o.modes = modes;
  o.geometricStiffening = stiffening;
  return o;
}

using RC = ReferenceConditions::Type;

struct NamedModel {
  std::string name;
  std::shared_ptr<const FfrBeamModel> model;
  double size;  ///< characteristic size of the body (m), for the deformation scale
};

std::shared_ptr<const FfrBeamModel> makeModel(BeamMesh2d mesh, const FfrBeamOptions& o) {
  return std::make_shared<const FfrBeamModel>(std::move(mesh), o, "body 'test'");
}

/// Nodal and modal models of straight beams and bent frames under each reference
/// condition, with damping and geometric stiffening in some of them.
std::vector<NamedModel> testModels() {
  const double beta = 2e-3;  // stiffness-proportional damping, s
  std::vector<NamedModel> v;
  v.push_back({"straight pinned_pinned nodal, stiffening, damping",
               makeModel(BeamMesh2d::straight(1.0, 4, softSection(beta)), options(RC::PinnedPinned, 0, true)), 1.0});
  v.push_back({"straight pinned_pinned nodal, linear",
               makeModel(BeamMesh2d::straight(1.0, 3, softSection()), options(RC::PinnedPinned)), 1.0});
  v.push_back({"straight clamped nodal, stiffening",
               makeModel(BeamMesh2d::straight(0.8, 3, softSection(beta), Vec2(0.1, -0.05)),
                         options(RC::Clamped, 0, true)),
               0.8});
  v.push_back({"straight free_free nodal, linear, damping",
               makeModel(BeamMesh2d::straight(1.0, 4, softSection(beta)), options(RC::FreeFree)), 1.0});
  v.push_back({"straight free_free modal(3), stiffening",
               makeModel(BeamMesh2d::straight(1.0, 4, softSection()), options(RC::FreeFree, 3, true)), 1.0});
  v.push_back({"L frame clamped nodal, stiffening, damping",
               makeModel(lFrame(2, Vec2::Zero(), beta), options(RC::Clamped, 0, true)), 0.3});
  v.push_back({"L frame clamped modal(3)", makeModel(lFrame(2), options(RC::Clamped, 3)), 0.3});
  v.push_back({"offset L frame pinned_pinned nodal, linear",
               makeModel(lFrame(3, Vec2(-0.12, 0.25)), options(RC::PinnedPinned, 0, false, 1, 5)), 0.3});
  v.push_back({"offset L frame free_free modal(4), stiffening, damping",
               makeModel(lFrame(2, Vec2(0.2, 0.1), beta), options(RC::FreeFree, 4, true)), 0.3});
  // Rayleigh and Timoshenko elements (the sections' rotary inertia, shear)
  v.push_back({"straight clamped nodal Rayleigh, stiffening",
               makeModel(BeamMesh2d::straight(0.8, 3, softSection(beta), Vec2(0.1, -0.05)),
                         options(RC::Clamped, 0, true, 0, -1, BeamTheory::Rayleigh)),
               0.8});
  v.push_back({"L frame pinned_pinned nodal Timoshenko, damping",
               makeModel(lFrame(3, Vec2(-0.12, 0.25), beta), options(RC::PinnedPinned, 0, false, 1, 5, BeamTheory::Timoshenko)),
               0.3});
  v.push_back({"L frame free_free modal(4) Timoshenko, stiffening",
               makeModel(lFrame(2, Vec2(0.2, 0.1)), options(RC::FreeFree, 4, true, 0, -1, BeamTheory::Timoshenko)), 0.3});
  return v;
}

/// Largest nodal translation (not slope) of the nodal displacements basis * qf.
double maxNodalTranslation(const FfrBeamModel& model, const VecX& qf) {
  const VecX u = model.basis() * qf;
  double m = 0.0;
  for (int k = 0; k < u.size(); ++k) {
    if (k % 3 != 2) m = std::max(m, std::abs(u[k]));
  }
  return m;
}

/// Random coordinates: frame anywhere, elastic coordinates such that the largest
/// nodal displacement is `defo` times the body size.
VecX randomCoordinates(Random& rnd, const FfrBeamModel& model, double size, double defo = 0.02) {
  const int nf = model.numElastic();
  VecX q(3 + nf);
  q.head<3>() << rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-kPi, kPi);
  VecX qf = rnd.vector(nf, -1.0, 1.0);
  qf *= defo * size / maxNodalTranslation(model, qf);
  q.tail(nf) = qf;
  return q;
}

/// Random velocities: frame velocities ~1 m/s, 1..3 rad/s (either sign), elastic rates
/// such that the largest nodal velocity relative to the frame is 0.5 m/s.
VecX randomVelocities(Random& rnd, const FfrBeamModel& model, double size) {
  const int nf = model.numElastic();
  VecX v(3 + nf);
  v.head<3>() << rnd.uniform(-1, 1), rnd.uniform(-1, 1), (rnd.uniform(0, 1) < 0.5 ? -1 : 1) * rnd.uniform(1, 3);
  VecX p = rnd.vector(nf, -1.0, 1.0);
  p *= 0.5 * size / maxNodalTranslation(model, p);
  v.tail(nf) = p;
  return v;
}

// ----- invariants against closed forms --------------------------------------------------

/// Mass, first moment and polar moment of a slender rod (no rotary inertia of the
/// section) from P to Q with mass per length mu: int over s in [0, 1] of
/// mu L |P + s (Q - P)|^2 ds = mu L (|P|^2 + P.Q + |Q|^2) / 3.
struct RodInertia {
  double m = 0.0;
  Vec2 s = Vec2::Zero();
  double I0 = 0.0;
  void add(const Vec2& P, const Vec2& Q, double mu) {
    const double L = (Q - P).norm();
    m += mu * L;
    s += mu * L * 0.5 * (P + Q);
    I0 += mu * L * (P.squaredNorm() + P.dot(Q) + Q.squaredNorm()) / 3.0;
  }
};

void checkInvariantProperties(const FfrInvariants& sparse, const std::string& what) {
  struct {
    MatX mff, sTilde, kff;
    int numElastic() const { return static_cast<int>(mff.rows()); }
  } inv{MatX(sparse.mff), MatX(sparse.sTilde), MatX(sparse.kff)};
  const double mscale = inv.mff.cwiseAbs().maxCoeff();
  EXPECT_LE((inv.mff - inv.mff.transpose()).cwiseAbs().maxCoeff(), kSymmetryTol * mscale) << what << ": m_ff symmetric";
  const Eigen::SelfAdjointEigenSolver<MatX> es(inv.mff, Eigen::EigenvaluesOnly);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0) << what << ": m_ff positive definite";
  EXPECT_LE((inv.sTilde + inv.sTilde.transpose()).cwiseAbs().maxCoeff(), kSymmetryTol * mscale)
      << what << ": S~ skew";
  if (inv.numElastic() > 3) {
    // (with a single straight free-free element the three deformation shapes happen
    // to have S~ = 0; with more coordinates the axial-transverse coupling shows)
    EXPECT_GT(inv.sTilde.cwiseAbs().maxCoeff(), 1e-3 * mscale) << what << ": S~ unexpectedly zero";
  }
  EXPECT_LE((inv.kff - inv.kff.transpose()).cwiseAbs().maxCoeff(), kSymmetryTol * inv.kff.cwiseAbs().maxCoeff())
      << what << ": K_ff symmetric";
}

TEST(FfrBeamModel, InvariantsOfStraightBeamMatchSlenderRod) {
  const BeamSection s = softSection();
  const double mu = s.massPerLength();
  for (const Vec2& origin : {Vec2(0, 0), Vec2(0.25, -0.4)}) {
    for (const int n : {1, 3, 8}) {
      for (const RC rc : {RC::PinnedPinned, RC::Clamped, RC::FreeFree}) {
        const FfrBeamModel model(BeamMesh2d::straight(1.2, n, s, origin), options(rc), "body 'rod'");
        const FfrInvariants& inv = model.invariants();
        RodInertia ref;
        ref.add(origin, origin + Vec2(1.2, 0), mu);
        const std::string what = "straight, " + std::to_string(n) + " elements, origin (" +
                                 std::to_string(origin.x()) + ", " + std::to_string(origin.y()) + ")";
        EXPECT_NEAR(inv.mass, ref.m, kExactTol * ref.m) << what;
        expectMatrixNear(inv.firstMoment, ref.s, kExactTol, what + ": first moment");
        EXPECT_NEAR(inv.polarMoment, ref.I0, kExactTol * ref.I0) << what;
        EXPECT_EQ(inv.numElastic(), 3 * (n + 1) - 3) << what;
        EXPECT_EQ(inv.points.size(), size_t(n + 1)) << what;
        checkInvariantProperties(inv, what);
      }
    }
  }
}

TEST(FfrBeamModel, InvariantsOfBentFramesMatchSlenderRods) {
  const double mu1 = softSection().massPerLength(), mu2 = heavySection().massPerLength();
  for (const Vec2& offset : {Vec2(0, 0), Vec2(-0.12, 0.25), Vec2(0.4, 0.1)}) {
    for (const int perLeg : {2, 3, 5}) {
      RodInertia ref;
      ref.add(offset + Vec2(0, 0), offset + Vec2(0.3, 0), mu1);
      ref.add(offset + Vec2(0.3, 0), offset + Vec2(0.3, 0.2), mu2);
      for (const auto& [rc, modes] : {std::pair<RC, int>{RC::Clamped, 0}, {RC::PinnedPinned, 0}, {RC::FreeFree, 0},
                                      {RC::Clamped, 3}}) {
        const FfrBeamModel model(lFrame(perLeg, offset), options(rc, modes), "body 'frame'");
        const FfrInvariants& inv = model.invariants();
        const std::string what = "L frame, " + std::to_string(perLeg) + " per leg, offset (" +
                                 std::to_string(offset.x()) + ", " + std::to_string(offset.y()) + "), modes " +
                                 std::to_string(modes);
        EXPECT_NEAR(inv.mass, ref.m, kExactTol * ref.m) << what;
        expectMatrixNear(inv.firstMoment, ref.s, kExactTol, what + ": first moment");
        EXPECT_NEAR(inv.polarMoment, ref.I0, kExactTol * ref.I0) << what;
        checkInvariantProperties(inv, what);
      }
    }
  }
  // the numbers themselves, for the record (offset 0): m = 0.3 + 1.8 * 0.2 = 0.66 kg,
  // s = (0.3 * 0.15 + 0.36 * 0.3, 0.36 * 0.1) = (0.153, 0.036),
  // I0 = 0.3^3 / 3 + 0.36 (0.09 + 0.04 / 3) = 0.009 + 0.0372 = 0.0462
  const FfrBeamModel model(lFrame(2), options(RC::Clamped), "body 'frame'");
  EXPECT_NEAR(model.invariants().mass, 0.66, 1e-14);
  expectMatrixNear(model.invariants().firstMoment, Vec2(0.153, 0.036), 1e-13, "first moment of the L frame");
  EXPECT_NEAR(model.invariants().polarMoment, 0.0462, 1e-14);
}

// ----- the mass matrix against the direct quadrature of the kinetic energy --------------

/// Quadrature of int rho J^T J dV, J = dr/dq = [I, S A u, A N] (2 x n), over every
/// element with a Gauss rule of `points` points (the integrand has degree 6 in xi).
/// Also returns the kinetic energy 1/2 int rho |rdot|^2 for the velocity v.
/// Rayleigh and Timoshenko elements turn their sections by psi: the section points
/// y = +-sqrt(I/A) across the axis (weights A/2: int dA = A, int y^2 dA = I, exact for
/// the quadratics here) move by -y psi along the axis, and the second-order rotation
/// u2 = -(1/2) psi^2 y n adds int rho 2 u0.u2 = -rho y^2 psi^2 to the polar moment
/// (m_theta theta and its kinetic energy; BeamElement2d::sectionRotationMoment).
MatX quadratureMassMatrix(const FfrBeamModel& model, const VecX& q, const VecX& v, int points, double& kinetic) {
  const int nf = model.numElastic(), n = 3 + nf;
  const VecX qf = q.tail(nf), qfdot = v.tail(nf);
  const Mat2 A = rotation(q[2]);
  std::vector<double> xi, w;
  gaussRule(points, xi, w);
  MatX M = MatX::Zero(n, n);
  kinetic = 0.0;
  for (int e = 0; e < int(model.elements().size()); ++e) {
    const BeamElement2d& el = model.elements()[e];
    const double mu = el.section().massPerLength(), l = el.length();
    const bool turns = el.theory() != BeamTheory::EulerBernoulli;
    const double r = turns ? std::sqrt(el.section().inertia / el.section().area) : 0.0;
    const Vec2 t = rotation(el.angle()).col(0), nrm = perp(t);  // element axis and normal, body frame
    for (size_t g = 0; g < xi.size(); ++g) {
      const FfrPoint p = model.materialPoint(e, xi[g]);
      for (double y : turns ? std::vector<double>{-r, r} : std::vector<double>{0.0}) {
        const Mat2X N = p.shape - y * t * p.rotationShape;  // + psi e_z x (y n) = -y psi t
        const Vec2 u = p.position + y * nrm + N * qf;
        const Vec2 SAu = perp(A * u);
        Mat2X J = Mat2X::Zero(2, n);
        J(0, 0) = J(1, 1) = 1.0;
        J.col(2) = SAu;
        J.rightCols(nf) = A * N;
        const double dm = mu * l * w[g] / (turns ? 2.0 : 1.0);
        M += dm * J.transpose() * J;
        const double psi = p.rotationShape.dot(qf), polar2 = -dm * y * y * psi * psi;  // int rho 2 u0.u2
        M(2, 2) += polar2;
        const Vec2 rdot = v.head<2>() + SAu * v[2] + A * (N * qfdot);
        kinetic += 0.5 * dm * rdot.squaredNorm() + 0.5 * polar2 * v[2] * v[2];
      }
    }
  }
  return M;
}

TEST(FfrBody2d, MassMatrixEqualsQuadratureOfKineticEnergy) {
  Random rnd(kSeed);
  double worstM = 0.0, worstT = 0.0;
  for (const NamedModel& nm : testModels()) {
    const FfrBody2d body("flex", nm.model, FrameState2d{});
    for (int s = 0; s < kSamples; ++s) {
      const VecX q = randomCoordinates(rnd, *nm.model, nm.size);
      const VecX v = randomVelocities(rnd, *nm.model, nm.size);
      const std::string what = nm.name + ", sample " + std::to_string(s);
      const MatX M = body.massMatrix(q);
      double T6 = 0.0, T9 = 0.0;
      const MatX Mq = quadratureMassMatrix(*nm.model, q, v, 7, T6);
      quadratureMassMatrix(*nm.model, q, v, 9, T9);
      // the quadrature is exact: a higher rule changes nothing beyond roundoff
      EXPECT_NEAR(T6, T9, kExactTol * T9) << what;
      worstM = std::max(worstM, expectMatrixNear(M, Mq, kExactTol, what + ": M vs int rho J^T J"));
      // row by row as well (the elastic rows of modal models are ~1, the frame ones ~m)
      expectRowsNear(M, Mq, kExactTol * 10, what + ": M vs int rho J^T J, by rows");
      const double T = 0.5 * v.dot(M * v);
      EXPECT_NEAR(T, T6, kExactTol * T6) << what;
      worstT = std::max(worstT, std::abs(T - T6) / T6);
      // the deformation is not negligible in these checks: M depends on q_f
      VecX q0 = q;
      q0.tail(body.numElastic()).setZero();
      EXPECT_GT((body.massMatrix(q0) - M).cwiseAbs().maxCoeff(), 1e-5 * M.cwiseAbs().maxCoeff()) << what;
    }
  }
  std::printf("mass matrix vs quadrature: worst relative error %.2e; kinetic energy %.2e\n", worstM, worstT);
}

// ----- quadratic velocity forces against Lagrange's equations ----------------------------

TEST(FfrBody2d, QuadraticVelocityForcesFollowFromLagrange) {
  // Lagrange: d/dt (M v) - dT/dq = Q  =>  M v' = Q - (dM/dt) v + dT/dq, so the
  // quadratic velocity vector is Q_v = -(dM/dt) v + dT/dq with T = 1/2 v^T M(q) v.
  // Body::addInternalForces returns Q_v - dU/dq_f - D q_f', so the elastic and damping
  // parts are added back explicitly.
  Random rnd(kSeed + 1);
  double worst = 0.0;
  for (const NamedModel& nm : testModels()) {
    const FfrBody2d body("flex", nm.model, FrameState2d{});
    const int n = body.numCoordinates(), nf = body.numElastic();
    for (int s = 0; s < kSamples; ++s) {
      const VecX q = randomCoordinates(rnd, *nm.model, nm.size);
      const VecX v = randomVelocities(rnd, *nm.model, nm.size);
      VecX Q = VecX::Zero(n);
      body.addInternalForces(q, v, Q);
      Q.tail(nf) += nm.model->strainEnergyGradient(q.tail(nf)) + body.invariants().dff * v.tail(nf);
      const double h = kLagrangeStep;
      const VecX Mdot_v = (body.massMatrix(q + h * v) - body.massMatrix(q - h * v)) * v / (2.0 * h);
      const double T = 0.5 * v.dot(body.massMatrix(q) * v);
      const VecX dTdq = fdGradient([&](const VecX& z) { return 0.5 * v.dot(body.massMatrix(z) * v); }, q,
                                   kLagrangeStep * (VecX::Ones(n) + q.cwiseAbs()));
      const VecX lagrange = -Mdot_v + dTdq;
      const std::string what = nm.name + ", sample " + std::to_string(s);
      // compared relative to the force scale T / size (the roundoff of dT/dq is
      // eps T / h), or to the largest force if larger
      worst = std::max(worst, expectMatrixNear(Q, lagrange, kLagrangeTol, what + ": Q_v vs Lagrange", T / nm.size));
      EXPECT_GT(lagrange.cwiseAbs().maxCoeff(), 1e-2 * T / nm.size) << what << ": trivial check";
    }
  }
  std::printf("quadratic velocity forces vs Lagrange: worst relative error %.2e\n", worst);
}

// ----- derivatives of FfrBody2d against central differences -----------------------------

TEST(FfrBody2d, DerivativesMatchFiniteDifferences) {
  Random rnd(kSeed + 2);
  const Vec3 g(0.7, -9.81, 0.0);
  double worst = 0.0;
  for (const NamedModel& nm : testModels()) {
    const FfrBody2d body("flex", nm.model, FrameState2d{});
    const int n = body.numCoordinates(), nf = body.numElastic();
    for (int s = 0; s < kSamples; ++s) {
      const VecX q = randomCoordinates(rnd, *nm.model, nm.size);
      const VecX v = randomVelocities(rnd, *nm.model, nm.size);
      const VecX a = rnd.vector(n, -3.0, 3.0);
      const std::string what = nm.name + ", sample " + std::to_string(s);

      // d(M a)/dq
      MatX K = MatX::Zero(n, n);
      body.addMassMatrixDerivative(q, a, K);
      const VecX hq = coordinateSteps(q), hv = velocitySteps(v);
      const MatX KFd = fdJacobian([&](const VecX& z) { return VecX(body.massMatrix(z) * a); }, q, hq);
      worst = std::max(worst, expectRowsNear(K, KFd, kFdTol, what + ": dM a/dq"));

      // internal forces
      auto internal = [&](const VecX& z, const VecX& zd) {
        VecX Q = VecX::Zero(n);
        body.addInternalForces(z, zd, Q);
        return Q;
      };
      MatX dQdq = MatX::Zero(n, n), dQdv = MatX::Zero(n, n);
      body.addInternalForceJacobians(q, v, dQdq, dQdv);
      worst = std::max(worst, expectRowsNear(dQdq, fdJacobian([&](const VecX& z) { return internal(z, v); }, q, hq),
                                             kFdTol, what + ": dQ/dq"));
      worst = std::max(worst, expectRowsNear(dQdv, fdJacobian([&](const VecX& z) { return internal(q, z); }, v, hv),
                                             kFdTol, what + ": dQ/dv"));

      // at rest the internal forces are the elastic ones: Q = -dU/dq (frame rows zero)
      const VecX Q0 = internal(q, VecX::Zero(n));
      const VecX gradU = fdGradient([&](const VecX& z) { return body.internalPotential(z); }, q, hq);
      // (gradients of a scalar: compared on the scale of the whole vector, as the FD
      // error, eps |U| / h + h^2 |U'''| / 6, is common to all components)
      worst = std::max(worst, expectMatrixNear(Q0, -gradU, kFdTol, what + ": elastic force = -dU/dq", 1.0));
      EXPECT_EQ(Q0.head<3>().cwiseAbs().maxCoeff(), 0.0) << what;
      EXPECT_NEAR(body.internalPotential(q), nm.model->strainEnergy(q.tail(nf)), 1e-14 * body.internalPotential(q));

      // gravity
      auto gravity = [&](const VecX& z) {
        VecX Q = VecX::Zero(n);
        body.addGravityForce(z, g, Q);
        return Q;
      };
      MatX Kg = MatX::Zero(n, n);
      body.addGravityJacobian(q, g, Kg);
      worst = std::max(worst, expectRowsNear(Kg, fdJacobian(gravity, q, hq), kFdTol, what + ": gravity Jacobian"));
      worst = std::max(worst, expectMatrixNear(gravity(q),
                                             -fdGradient([&](const VecX& z) { return body.gravityPotential(z, g); }, q, hq),
                                             kFdTol, what + ": gravity force = -dV/dq", 1.0));
      // the gravity force is the integral of rho g over the deformed body: total m g
      EXPECT_NEAR(gravity(q).head<2>().x(), body.mass() * g.x(), 1e-14 * body.mass() * g.norm());

      // point kinematics at every node
      for (size_t k = 0; k < body.invariants().points.size(); ++k) {
        const Vec2 node = body.invariants().points[k].position;
        const std::string where = what + ", node " + std::to_string(k);
        const PointKinematics pk = body.pointKinematics(q, node);
        auto rOf = [&](const VecX& z) { return VecX(body.pointKinematics(z, node).r); };
        auto phiOf = [&](const VecX& z) { return body.pointKinematics(z, node).phi; };
        auto JrRow = [&](int r) {
          return [&, r](const VecX& z) { return VecX(body.pointKinematics(z, node).Jr.row(r).transpose()); };
        };
        worst = std::max(worst, expectRowsNear(pk.Jr, fdJacobian(rOf, q, hq), kFdTol, where + ": Jr"));
        worst = std::max(worst, expectRowsNear(pk.Jphi, fdGradient(phiOf, q, hq).transpose(), kFdTol, where + ": Jphi"));
        worst = std::max(worst, expectRowsNear(pk.Hrx, fdJacobian(JrRow(0), q, hq), kFdTol, where + ": Hrx"));
        worst = std::max(worst, expectRowsNear(pk.Hry, fdJacobian(JrRow(1), q, hq), kFdTol, where + ": Hry"));
        worst = std::max(
            worst, expectRowsNear(pk.Hphi,
                                  fdJacobian([&](const VecX& z) { return VecX(body.pointKinematics(z, node).Jphi.transpose()); },
                                             q, hq),
                                  kFdTol, where + ": Hphi"));
        // and the position itself: R + A (u0 + N q_f) through the model's nodal basis
        const Vec2 u = node + nm.model->basis().middleRows(3 * k, 2) * q.tail(nf);
        expectMatrixNear(pk.r, Vec2(q.head<2>() + rotation(q[2]) * u), 1e-14, where + ": r", 1.0);
        EXPECT_NEAR(pk.phi, q[2] + nm.model->basis().row(3 * k + 2).dot(q.tail(nf)), 1e-14) << where;
        // over the node's support (what joints use): the same entries, none outside it
        const std::vector<int> cols = body.pointSupport(lift(node), body.resolvePoint(lift(node), "test"));
        const PointKinematics pc = body.pointKinematics(q, node, cols, true);
        std::vector<bool> inSupport(n, false);
        for (size_t a = 0; a < cols.size(); ++a) {
          inSupport[cols[a]] = true;
          EXPECT_TRUE(pc.Jr.col(a) == pk.Jr.col(cols[a]) && pc.Jphi[a] == pk.Jphi[cols[a]]) << where << ", col " << cols[a];
          for (size_t b = 0; b < cols.size(); ++b) {
            EXPECT_TRUE(pc.Hrx(a, b) == pk.Hrx(cols[a], cols[b]) && pc.Hry(a, b) == pk.Hry(cols[a], cols[b]))
                << where << ", Hessian (" << cols[a] << ", " << cols[b] << ")";
          }
        }
        for (int c = 0; c < n; ++c) {
          if (inSupport[c]) continue;
          EXPECT_EQ(pk.Jr.col(c).norm() + std::abs(pk.Jphi[c]) + pk.Hrx.col(c).norm() + pk.Hry.col(c).norm(), 0.0)
              << where << ": coordinate " << c << " outside the support moves the node";
        }
        // pinned and clamped nodal meshes: B2 keeps unit columns, a node moves with its
        // own (at most 3) coordinates; mean-axis (free_free) conditions couple them all
        if (nm.name.find("nodal") != std::string::npos && nm.name.find("free_free") == std::string::npos) {
          EXPECT_LE(static_cast<int>(cols.size()), 3 + 3) << where << ": support " << cols.size();
        }
      }
    }
  }
  std::printf("FfrBody2d derivatives vs central differences: worst row-relative error %.2e\n", worst);
}

TEST(FfrBody2d, CentreOfMassAndInitialState) {
  const auto model = makeModel(lFrame(2, Vec2(0.1, 0.2)), options(RC::Clamped));
  FrameState2d init;
  init.position = Vec2(1.0, -2.0);
  init.angle = 0.3;
  init.velocity = Vec2(0.5, 0.25);
  init.angularVelocity = -1.5;
  const FfrBody2d body("flex", model, init);
  const VecX q = body.initialCoordinates(), v = body.initialVelocities();
  ASSERT_EQ(q.size(), 3 + body.numElastic());
  EXPECT_EQ(q.head<3>(), Eigen::Vector3d(1.0, -2.0, 0.3));
  EXPECT_EQ(v.head<3>(), Eigen::Vector3d(0.5, 0.25, -1.5));
  EXPECT_EQ(q.tail(body.numElastic()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(body.numFrameCoordinates(), 3);
  EXPECT_EQ(body.coordinateNames().size(), size_t(body.numCoordinates()));
  // centre of mass of the deformed body = quadrature of int rho r / m
  Random rnd(kSeed + 3);
  const VecX qr = randomCoordinates(rnd, *model, 0.3);
  std::vector<double> xi, w;
  gaussRule(4, xi, w);  // r is cubic in xi
  Vec2 c = Vec2::Zero();
  const int nf = body.numElastic();
  for (int e = 0; e < int(model->elements().size()); ++e) {
    const auto& el = model->elements()[e];
    for (size_t k = 0; k < xi.size(); ++k) {
      const FfrPoint p = model->materialPoint(e, xi[k]);
      c += el.section().massPerLength() * el.length() * w[k] *
           (qr.head<2>() + rotation(qr[2]) * (p.position + p.shape * qr.tail(nf)));
    }
  }
  expectMatrixNear(body.planarCentreOfMass(qr), c / body.mass(), kExactTol, "centre of mass", 1.0);
}

TEST(FfrBody2d, DeflectionOutputsFromTheBodysOwnCoordinates) {
  // What io reads of a flexible body (deflection outputs, VTK) comes from the body, given
  // its own coordinates: u = N q_f (body axes), N and M of the model, r = R + A (u0 + u).
  const auto model = makeModel(lFrame(2, Vec2(0.1, 0.2)), options(RC::Clamped));
  const FfrBody2d body("flex", model, FrameState2d{});
  Random rnd(kSeed + 4);
  const VecX qr = randomCoordinates(rnd, *model, 0.3);
  const VecX qf = qr.tail(body.numElastic());
  const Mat2 A = rotation(qr[2]);
  for (int e = 0; e < int(model->elements().size()); ++e) {
    for (double xi : {0.0, 0.3, 1.0}) {
      const FfrBody2d::BeamDeflection d = body.beamDeflection(qr, e, xi);
      const FfrPoint p = model->materialPoint(e, xi);
      const Vec2 u = p.shape * qf;
      EXPECT_EQ(d.displacement, u);
      EXPECT_EQ(d.sectionForces, model->sectionForces(qf, e, xi));
      EXPECT_EQ(d.worldDisplacement, A * u);
      expectMatrixNear(d.position, body.pointKinematics(qr, p, false).r, kExactTol, "deformed position", 1.0);
    }
  }
  // a body given by its invariants: displacements of its points, no section forces
  const FfrBody2d direct("direct", model->invariants(), FrameState2d{});
  for (const FfrPoint& p : direct.invariants().points) {
    EXPECT_EQ(direct.worldElasticDisplacement(qr, p), A * (p.shape * qf));
  }
  expectInputError([&] { direct.beamDeflection(qr, 0, 0.5); }, {"body 'direct'", "beam mesh"});
}

// ----- rigid-body displacements store no strain energy ------------------------------------

TEST(FfrBeamModel, RigidDisplacementsGiveNoElasticForce) {
  // Element level, body frame: T^T K T times the nodal displacements of a rigid
  // motion (translation (a, b), small rotation w about a point P: u = (a, b) + w S (X - P),
  // psi = w) is zero for elements at any angle.
  const BeamSection s = softSection();
  Random rnd(kSeed + 4);
  for (const double deg : {0.0, 30.0, 90.0, 135.0, 180.0, -60.0, -97.5}) {
    const Vec2 X1(0.2, -0.1), X2 = X1 + 0.35 * Vec2(std::cos(deg * kPi / 180), std::sin(deg * kPi / 180));
    const BeamElement2d el(X1, X2, s, "element");
    const BeamElement2d::Mat6 Kb = el.transformation().transpose() * el.stiffness() * el.transformation();
    for (int k = 0; k < 4; ++k) {
      const double a = rnd.uniform(-1e-3, 1e-3), b = rnd.uniform(-1e-3, 1e-3), w = rnd.uniform(-1e-2, 1e-2);
      const Vec2 P = Vec2(rnd.uniform(-1, 1), rnd.uniform(-1, 1));
      BeamElement2d::Vec6 u;
      u << Vec2(a, b) + w * perp(X1 - P), w, Vec2(a, b) + w * perp(X2 - P), w;
      // K u sums entries of size |K| |u| that cancel exactly: roundoff ~ 10 eps |K| |u|
      EXPECT_LE((Kb * u).cwiseAbs().maxCoeff(), 1e-13 * Kb.cwiseAbs().maxCoeff() * u.cwiseAbs().maxCoeff())
          << "element at " << deg << " degrees";
      // with geometric stiffening, a rigid translation of any size has no strain energy
      BeamElement2d::Vec6 t;
      t << Vec2(a, b) * 100.0, 0.0, Vec2(a, b) * 100.0, 0.0;
      EXPECT_LE(std::abs(el.strainEnergy(el.transformation() * t, true)),
                1e-13 * Kb.cwiseAbs().maxCoeff() * t.squaredNorm());
    }
  }
  // body level: the undeformed state stores no energy and has no elastic force
  for (const bool stiff : {false, true}) {
    const FfrBeamModel m(lFrame(2), options(RC::Clamped, 0, stiff), "body 'frame'");
    const VecX zero = VecX::Zero(m.numElastic());
    EXPECT_EQ(m.strainEnergy(zero), 0.0);
    EXPECT_EQ(m.strainEnergyGradient(zero).cwiseAbs().maxCoeff(), 0.0);
  }
}

// ----- natural frequencies ------------------------------------------------------------

/// Aluminium-like rod, A/I = 1e4: the first axial frequency lies above the third
/// bending frequency for all three support types, so the three lowest frequencies are
/// the bending ones (checked: each is matched to its closed form within 10% for N >= 4).
BeamSection frequencySection() {
  BeamSection s;
  s.area = 1e-3;
  s.inertia = 1e-7;
  s.youngsModulus = 7e10;
  s.density = 2700.0;
  return s;
}

struct FrequencyCase {
  std::string name;
  RC type;
  std::vector<double> betaL;  ///< omega_n = (beta_n L)^2 sqrt(EI / (rho A L^4))
};

std::vector<FrequencyCase> frequencyCases() {
  return {{"pinned_pinned (simply supported)", RC::PinnedPinned, {kPi, 2 * kPi, 3 * kPi}},
          {"clamped (cantilever)", RC::Clamped, {1.875104068711961, 4.694091132974175, 7.854757438237613}},
          {"free_free", RC::FreeFree, {4.730040744862704, 7.853204624095838, 10.995607838001671}}};
}

// Frequency error of cubic Hermite elements with the consistent mass: eigenvalue error
// O(h^{2(p+1-m)}) = O(h^4) for p = 3, m = 2, from above (Rayleigh-Ritz, conforming
// C1 elements). To leading order omega_h / omega - 1 = C (beta h)^4 with C = 1/1440
// (lambda_h / lambda - 1 = (beta h)^4 / 720); measured C at N = 16: 6.7e-4 .. 6.94e-4.
// The asymptotic range needs elements no longer than a quarter wavelength,
// beta h <= pi/2: e.g. the free-free first mode at N = 2 (beta h = 2.37) is
// fortuitously accurate (2.2e-3 instead of ~2e-2) and gives an order of ~1 from N = 2 to 4.
constexpr double kAsymptoticBetaH = 1.6;
// Round-off floor of the generalized eigenvalue solver: ~ eps lambda_max / lambda_1
// ~ 1e-16 * 1e6 = 1e-10 relative for N = 16, so orders are only measured while the
// error is above 1e-8.
constexpr double kRoundoffFloor = 1e-8;

TEST(FfrBeamModel, NaturalFrequenciesConvergeAtFourthOrder) {
  const BeamSection sec = frequencySection();
  const double L = 1.0, base = std::sqrt(sec.bendingStiffness() / (sec.massPerLength() * std::pow(L, 4)));
  for (const FrequencyCase& fc : frequencyCases()) {
    std::vector<std::vector<double>> err;  // [mesh][mode]
    const std::vector<int> meshes = {2, 4, 8, 16};
    for (const int N : meshes) {
      const FfrBeamModel model(BeamMesh2d::straight(L, N, sec), options(fc.type), "body 'rod'");
      const VecX w = model.naturalFrequencies();
      ASSERT_GE(w.size(), 3);
      std::vector<double> e;
      for (int k = 0; k < 3; ++k) {
        const double exact = fc.betaL[k] * fc.betaL[k] * base;
        e.push_back(w[k] / exact - 1.0);
        // the lowest three are the bending modes (coarse N = 2 is off by up to ~45%)
        EXPECT_LT(std::abs(e.back()), N == 2 ? 0.5 : 0.1) << fc.name << " N = " << N << " mode " << k + 1 << ": " << w[k]
                                           << " vs " << exact;
        // Rayleigh-Ritz with the consistent mass: the discrete frequency is an upper bound
        EXPECT_GT(e.back(), -1e-10) << fc.name << " N = " << N << " mode " << k + 1;
      }
      std::printf("%-34s N = %2d: omega = %.10g %.10g %.10g rad/s, rel. errors %.3e %.3e %.3e\n", fc.name.c_str(),
                  N, w[0], w[1], w[2], e[0], e[1], e[2]);
      err.push_back(e);
    }
    for (size_t i = 0; i + 1 < meshes.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        if (err[i + 1][k] < kRoundoffFloor) continue;
        const double order = std::log2(err[i][k] / err[i + 1][k]);
        std::printf("  %s mode %d: observed order N = %d -> %d: %.3f\n", fc.name.c_str(), k + 1, meshes[i],
                    meshes[i + 1], order);
        if (fc.betaL[k] / meshes[i] <= kAsymptoticBetaH) {
          EXPECT_GE(order, 3.5) << fc.name << " mode " << k + 1 << " N = " << meshes[i];
          EXPECT_LE(order, 4.5) << fc.name << " mode " << k + 1 << " N = " << meshes[i];
        }
      }
    }
    // N = 16: error = C (beta_n h)^4 with C -> 1/1440 from below (the next term of the
    // expansion is negative here): bounded by (beta h)^4 / 1200 (20% margin on the
    // leading term), and not suspiciously small: >= (beta h)^4 / 2000.
    for (int k = 0; k < 3; ++k) {
      const double bh4 = std::pow(fc.betaL[k] / 16.0, 4);
      EXPECT_LE(err.back()[k], bh4 / 1200.0) << fc.name << " mode " << k + 1;
      EXPECT_GE(err.back()[k], bh4 / 2000.0) << fc.name << " mode " << k + 1;
      const double bh = fc.betaL[k] / 16.0;
      std::printf("  %s mode %d: N = 16 error constant C = err / (beta h)^4 = %.3e\n", fc.name.c_str(), k + 1,
                  err.back()[k] / std::pow(bh, 4));
    }
  }
}

TEST(FfrBeamModel, ModalReductionKeepsTheLowestModes) {
  const BeamSection sec = frequencySection();
  for (const FrequencyCase& fc : frequencyCases()) {
    const FfrBeamModel nodal(BeamMesh2d::straight(1.0, 8, sec), options(fc.type), "body 'rod'");
    const VecX wn = nodal.naturalFrequencies();
    for (const int n : {1, 3, 6}) {
      const FfrBeamModel modal(BeamMesh2d::straight(1.0, 8, sec), options(fc.type, n), "body 'rod'");
      const std::string what = fc.name + ", " + std::to_string(n) + " modes";
      ASSERT_EQ(modal.numElastic(), n) << what;
      const VecX wm = modal.naturalFrequencies();
      for (int k = 0; k < n; ++k) EXPECT_NEAR(wm[k], wn[k], 1e-10 * wn[k]) << what << " mode " << k + 1;
      // mass-normalised modes: m_ff = I, K_ff = diag(omega^2)
      const FfrInvariants& inv = modal.invariants();
      expectMatrixNear(inv.mff, MatX::Identity(n, n), 1e-12, what + ": modal m_ff == I");
      MatX Kd = MatX::Zero(n, n);
      for (int k = 0; k < n; ++k) Kd(k, k) = wn[k] * wn[k];
      expectMatrixNear(inv.kff, Kd, 1e-10, what + ": modal K_ff == diag(omega^2)");
      // the modes are the nodal eigenvectors: K phi = omega^2 M phi on the nodal model
      // (nodal basis: q_nodal-reduced = B^T..., compare through the strain energy)
      for (int k = 0; k < n; ++k) {
        VecX e = VecX::Zero(n);
        e[k] = 1.0;
        EXPECT_NEAR(2.0 * modal.strainEnergy(e), wn[k] * wn[k], 1e-10 * wn[k] * wn[k]) << what;
      }
      // points carry the modal shapes: the nodal displacements of mode k
      for (size_t p = 0; p < inv.points.size(); ++p) {
        expectMatrixNear(inv.points[p].shape, modal.basis().middleRows(3 * p, 2), 0.0, what + ": point shapes", 1.0);
      }
    }
    // a chosen set of modes
    FfrBeamOptions o = options(fc.type);
    o.modeSet = {2, 4};
    const FfrBeamModel chosen(BeamMesh2d::straight(1.0, 8, sec), o, "body 'rod'");
    const VecX wc = chosen.naturalFrequencies();
    ASSERT_EQ(wc.size(), 2);
    EXPECT_NEAR(wc[0], wn[1], 1e-10 * wn[1]) << fc.name;
    EXPECT_NEAR(wc[1], wn[3], 1e-10 * wn[3]) << fc.name;
  }
}

// ----- input checks ---------------------------------------------------------------------

TEST(FfrBeamModel, RejectsBadMeshesAndReferences) {
  const BeamSection s = softSection();
  const std::string owner = "body 'rod'";
  auto build = [&](BeamMesh2d m, FfrBeamOptions o = options(RC::PinnedPinned)) {
    return [m, o, owner] {
      const FfrBeamModel model(m, o, owner);
      (void)model;
    };
  };
  BeamMesh2d m;
  expectInputError(build(m), {owner, "no elements"});

  m.nodes = {Vec2(0, 0), Vec2(0.5, 0), Vec2(0.5, 0)};
  m.elements = {{0, 1, s}, {1, 2, s}};
  expectInputError(build(m), {owner, "element 1", "zero length"});

  BeamSection bad = s;
  bad.area = 0.0;
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 1, bad}}}), {owner, "element 0", "area"});
  bad = s;
  bad.inertia = -1e-8;
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 1, bad}}}), {owner, "inertia"});
  bad = s;
  bad.youngsModulus = 0.0;
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 1, bad}}}), {owner, "youngs_modulus"});
  bad = s;
  bad.density = -1.0;
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 1, bad}}}), {owner, "density"});
  bad = s;
  bad.damping = -0.1;
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 1, bad}}}), {owner, "damping"});

  // disconnected: two separate rods
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)}, {{0, 1, s}, {2, 3, s}}}),
                   {owner, "not connected", "node 2"});
  // node index out of range, and a node that belongs to no element
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{0, 2, s}}}), {owner, "node 2 does not exist"});
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{-1, 1, s}}}), {owner, "node -1 does not exist"});
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)}, {{0, 1, s}}}),
                   {owner, "node 2 belongs to no element"});
  expectInputError(build(BeamMesh2d{{Vec2(0, 0), Vec2(1, 0)}, {{1, 1, s}}}), {owner, "both ends"});

  // reference nodes
  const BeamMesh2d rod = BeamMesh2d::straight(1.0, 3, s);
  expectInputError(build(rod, options(RC::PinnedPinned, 0, false, 7)), {owner, "reference node 7 does not exist"});
  expectInputError(build(rod, options(RC::PinnedPinned, 0, false, 0, 9)), {owner, "reference node 9"});
  expectInputError(build(rod, options(RC::Clamped, 0, false, -2)), {owner, "reference node -2"});
  expectInputError(build(rod, options(RC::PinnedPinned, 0, false, 2, 2)), {owner, "two different nodes"});
  // nodeB = -1 is the last node: the same model as naming it
  EXPECT_NO_THROW(FfrBeamModel(rod, options(RC::PinnedPinned, 0, false, 0, 3), owner));

  // modes that do not exist (the rod has 3 * 4 - 3 = 9)
  expectInputError(build(rod, options(RC::Clamped, 10)), {owner, "mode 10 does not exist", "1..9"});
  FfrBeamOptions o = options(RC::Clamped);
  o.modeSet = {1, 0};
  expectInputError(build(rod, o), {owner, "mode 0 does not exist"});
  o.modeSet = {12};
  expectInputError(build(rod, o), {owner, "mode 12 does not exist"});
  EXPECT_NO_THROW(FfrBeamModel(rod, options(RC::Clamped, 9), owner));

  // BeamMesh2d::straight
  expectInputError([&] { BeamMesh2d::straight(1.0, 0, s); }, {"elements"});
  expectInputError([&] { BeamMesh2d::straight(0.0, 2, s); }, {"length"});
}

TEST(FfrBody2d, RejectsInvalidInvariants) {
  const FfrBeamModel model(BeamMesh2d::straight(1.0, 3, softSection()), options(RC::PinnedPinned), "body 'rod'");
  const FfrInvariants good = model.invariants();
  EXPECT_NO_THROW(FfrBody2d("direct", good, FrameState2d{}));
  auto direct = [](const FfrInvariants& inv) { return [inv] { FfrBody2d("direct", inv, FrameState2d{}); }; };

  // a stiffness with a rigid-body mode (reference conditions that do not fix the frame)
  FfrInvariants inv = good;
  MatX k = MatX(good.kff);
  k.row(0).setZero();
  k.col(0).setZero();
  inv.kff = k.sparseView();
  expectInputError(direct(inv), {"body 'direct'", "k_ff", "rigid-body mode"});
  inv = good;
  inv.kff *= -1.0;
  expectInputError(direct(inv), {"body 'direct'", "rigid-body mode"});

  // m_ff not symmetric / not positive definite
  inv = good;
  inv.mff.coeffRef(0, 1) += 0.1 * MatX(good.mff).cwiseAbs().maxCoeff();
  expectInputError(direct(inv), {"body 'direct'", "m_ff", "not symmetric"});
  inv = good;
  inv.mff.coeffRef(2, 2) = -inv.mff.coeff(2, 2);
  expectInputError(direct(inv), {"body 'direct'", "m_ff", "positive definite"});

  // S~ not skew
  inv = good;
  inv.sTilde.coeffRef(1, 1) = 0.05;
  expectInputError(direct(inv), {"body 'direct'", "s_tilde", "skew"});
  inv = good;
  inv.sTilde.coeffRef(0, 2) += 0.05;
  expectInputError(direct(inv), {"body 'direct'", "s_tilde"});

  // other invariants
  inv = good;
  inv.mass = 0.0;
  expectInputError(direct(inv), {"body 'direct'", "mass"});
  inv = good;
  inv.polarMoment = 0.5 * good.firstMoment.squaredNorm() / good.mass;
  expectInputError(direct(inv), {"body 'direct'", "polar_moment"});
  inv = good;
  inv.dff = -good.kff;
  expectInputError(direct(inv), {"body 'direct'", "d_ff"});
  inv = good;
  inv.kff.coeffRef(0, 1) += 1.0;
  expectInputError(direct(inv), {"body 'direct'", "k_ff", "not symmetric"});
  inv = good;
  inv.j0.conservativeResize(inv.j0.size() - 1);
  expectInputError(direct(inv), {"body 'direct'", "j0", "wrong size"});
  inv = good;
  inv.points[1].shape = Mat2X::Zero(2, 2);
  expectInputError(direct(inv), {"body 'direct'", "point 1"});
  inv = good;
  inv.i1[0] = std::nan("");
  expectInputError(direct(inv), {"body 'direct'", "i1"});

  // no model
  expectInputError([] { FfrBody2d("nomodel", std::shared_ptr<const FfrBeamModel>(), FrameState2d{}); },
                   {"body 'nomodel'", "no beam model"});
  FrameState2d badFrame;
  badFrame.angle = std::nan("");
  expectInputError([&] { FfrBody2d("frame", good, badFrame); }, {"body 'frame'", "angle"});

  // the body given by invariants and by the model are the same body
  const auto shared = std::make_shared<const FfrBeamModel>(BeamMesh2d::straight(1.0, 3, softSection()),
                                                           options(RC::PinnedPinned), "body 'rod'");
  const FfrBody2d a("a", good, FrameState2d{}), b("b", shared, FrameState2d{});
  Random rnd(kSeed + 5);
  const VecX q = randomCoordinates(rnd, model, 1.0), v = randomVelocities(rnd, model, 1.0);
  expectMatrixNear(a.massMatrix(q), b.massMatrix(q), 0.0, "M of invariants vs model body");
  VecX Qa = VecX::Zero(q.size()), Qb = VecX::Zero(q.size());
  a.addInternalForces(q, v, Qa);
  b.addInternalForces(q, v, Qb);
  expectMatrixNear(Qa, Qb, 1e-14, "internal forces of invariants vs model body (linear)");
  EXPECT_EQ(a.beamModel(), nullptr);
  EXPECT_EQ(b.beamModel(), shared.get());
}

TEST(FfrBody2d, AttachmentOnlyAtNodes) {
  const auto model = makeModel(lFrame(2), options(RC::Clamped));
  const FfrBody2d body("frame", model, FrameState2d{});
  for (const FfrPoint& p : body.invariants().points) EXPECT_EQ(body.invariants().points[body.resolvePoint(lift(p.position), "joint 'j'")].position, p.position);
  // a point inside an element, and a point off the beam
  for (const Vec2& bad : {Vec2(0.1, 0.0), Vec2(0.2, 0.2)}) {
    expectInputError([&] { body.resolvePoint(lift(bad), "joint 'j'"); },
                     {"joint 'j'", "flexible body 'frame'", "no node", "(0, 0)", "(0.15, 0)", "(0.3, 0.1)"});
    expectInputError([&] { body.pointKinematics(body.initialCoordinates(), bad); }, {"flexible body 'frame'", "no node"});
  }
  // a node found within the tolerance (1e-9 relative)
  EXPECT_NO_THROW(body.resolvePoint(Vec3(0.3 + 1e-12, 0.1, 0.0), "joint 'j'"));
  // out of the plane: no node there
  expectInputError([&] { body.resolvePoint(Vec3(0.3, 0.1, 0.01), "joint 'j'"); }, {"joint 'j'", "no node", "0.01"});
  // locate and materialPoint agree with the element geometry
  int e = -1;
  double xi = -1;
  ASSERT_TRUE(model->locate(Vec2(0.3, 0.05), e, xi));
  EXPECT_EQ(e, 2);
  EXPECT_NEAR(xi, 0.5, 1e-14);
  EXPECT_FALSE(model->locate(Vec2(0.2, 0.2), e, xi));
  expectMatrixNear(model->materialPoint(2, 0.5).position, Vec2(0.3, 0.05), 1e-15, "material point", 1.0);
}

// Attachment points are resolved once, at finalize, into the bodies' identifiers:
// the joints of the elastic slider crank find the rod's nodes by index, and each index is
// the node at the joint's point, with the same kinematics as the search by coordinates.
TEST(FfrBody2d, AttachmentPointsResolvedAtFinalize) {
  const Scene scene = testmodels::elasticSliderCrank(4, 1.0, 0, 0.1, 1e-6, 1e-6);
  const System& sys = scene.system;
  const VecX q = sys.initialCoordinates();
  int resolvedNodes = 0;
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const ConstraintIndex ci(c);
    const BodyStates states = sys.constraintStates(ci, q.data());
    const std::vector<Attachment> att = sys.constraint(ci).attachments();
    for (size_t k = 0; k < att.size(); ++k) {
      const Body& body = sys.body(att[k].body);
      const int id = states.pointId(static_cast<int>(k));
      const auto* ffr = dynamic_cast<const FfrBody2d*>(&body);
      if (!ffr) {
        EXPECT_EQ(id, Body::kAnyPoint) << sys.constraint(ci).name();
        continue;
      }
      ASSERT_GE(id, 0) << sys.constraint(ci).name();
      EXPECT_EQ(lift(ffr->invariants().points[id].position), att[k].point) << sys.constraint(ci).name();
      const auto qb = q.segment(sys.coordinateOffset(att[k].body), body.numCoordinates());
      PointKinematics byId;
      body.pointKinematics(qb, att[k].point.head<2>(), id, nullptr, true, byId);
      const PointKinematics bySearch = body.pointKinematics(qb, Vec2(att[k].point.head<2>()), true);
      EXPECT_EQ(byId.r, bySearch.r);
      EXPECT_EQ(byId.Jr, bySearch.Jr);
      ++resolvedNodes;
    }
  }
  EXPECT_EQ(resolvedNodes, 2);  // the rod's two ends (crank pin and slider pin)
}

// The outputs' augmented matrix [M G^T; G 0] is assembled sparsely through the bodies'
// sinks: equal to the dense blocks to round-off of the sums (1e-14 relative:
// the same products, summed in another order), with only the structural non-zeros stored.
TEST(FfrBody2d, SparseAugmentedMatrixEqualsTheDenseBlocks) {
  const Scene scene = testmodels::elasticSliderCrank(16, 1.0, 0, 0.1, 1e-6, 1e-6);
  const System& sys = scene.system;
  const VecX q = sys.initialCoordinates();
  const int n = sys.numVelocities(), m = sys.numConstraintEquations();
  MatX G;
  evaluateConstraints(sys, q, 0.0, nullptr, &G);
  MatX dense = MatX::Zero(n + m, n + m);
  dense.topLeftCorner(n, n) = massMatrix(sys, q);
  dense.topRightCorner(n, m) = G.transpose();
  dense.bottomLeftCorner(m, n) = G;
  const SpMat A = augmentedMatrix(sys, q);
  EXPECT_LE((MatX(A) - dense).cwiseAbs().maxCoeff(), 1e-14 * dense.cwiseAbs().maxCoeff());
  EXPECT_LT(A.nonZeros(), (n + m) * (n + m) / 4);  // banded beam blocks: far from dense
}

// Planar Rayleigh and Timoshenko elements are the spatial ones restricted to the x-y
// plane (BeamElement2d): a planar beam's frequencies equal the spatial beam's in-plane
// ones (the x-z plane made 100 times stiffer, so the first in-plane modes are the
// lowest), to the eigensolvers' round-off (1e-9); and Timoshenko is softer than Rayleigh,
// Rayleigh softer than Euler-Bernoulli.
TEST(FfrBeamModel, PlanarRayleighAndTimoshenkoAreTheSpatialElementsInThePlane) {
  const double E = 2.1e11, G = 8.1e10, rho = 7850.0, b = 0.05, h = 0.05, L = 0.5;
  BeamSection s = rectangularSection(b, h, E, rho);
  s.shearModulus = G;
  s.shearFactor = rectangleShearFactor(E, G);
  BeamSection3d s3 = rectangularSection3d(h, b, E, G, rho);  // Iz = b h^3 / 12 in the x-y plane
  s3.inertiaY *= 100.0;
  s3.shearFactorY = s.shearFactor;
  double previous = 0.0;
  for (BeamTheory theory : {BeamTheory::EulerBernoulli, BeamTheory::Rayleigh, BeamTheory::Timoshenko}) {
    const FfrBeamModel planar(BeamMesh2d::straight(L, 6, s), options(RC::Clamped, 0, false, 0, -1, theory), "p");
    FfrBeamOptions3d o3;
    o3.theory = theory;
    const FfrBeamModel3d spatial(BeamMesh3d::straight(L, 6, s3), o3, "s");
    const VecX wp = planar.naturalFrequencies(), ws = spatial.naturalFrequencies();
    for (int k = 0; k < 3; ++k) {
      double best = ws[0];
      for (double x : ws) best = std::abs(x - wp[k]) < std::abs(best - wp[k]) ? x : best;
      EXPECT_NEAR(wp[k], best, 1e-9 * wp[k]) << "mode " << k + 1;
    }
    if (previous > 0.0) EXPECT_LT(wp[0], (1.0 - 1e-4) * previous);
    previous = wp[0];
  }
  BeamSection noShear = s;
  noShear.shearFactor = 0.0;
  expectInputError([&] { FfrBeamModel m(BeamMesh2d::straight(L, 2, noShear),
                                        options(RC::Clamped, 0, false, 0, -1, BeamTheory::Timoshenko), "body 'rod'"); },
                   {"body 'rod'", "element 0", "Timoshenko", "shear_factor"});
}

// The allocation-free strain-energy derivatives the planar model shares with the spatial
// one (FfrBeamModelT) equal the allocating ones, nodal and modal, with geometric stiffening.
TEST(FfrBeamModel, AllocationFreeStrainEnergyDerivativesMatch) {
  for (int modes : {0, 4}) {
    const FfrBeamModel model(BeamMesh2d::straight(1.0, 4, softSection()), options(RC::PinnedPinned, modes, true),
                             "rod");
    const int n = model.numElastic();
    const VecX qf = VecX::LinSpaced(n, -1e-3, 2e-3);
    VecX g = VecX::Zero(n);
    model.addStrainEnergyGradient(qf, 2.0, g);
    const VecX expected = 2.0 * model.strainEnergyGradient(qf);
    EXPECT_LE((g - expected).norm(), 1e-12 * expected.norm()) << modes << " modes";
    MatX K = MatX::Zero(n, n);
    model.addStrainEnergyHessian(qf, 1.0, MatrixSink(K), 0, 0);
    const MatX H = MatX(model.strainEnergyHessian(qf));
    EXPECT_LE((K - H).norm(), 1e-12 * H.norm()) << modes << " modes";
  }
}

}  // namespace
}  // namespace flexmbd
