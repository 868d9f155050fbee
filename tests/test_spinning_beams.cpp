// Spinning spatial beams: the cross-sections' second-order rotation in
// the FFR kinetic energy (BeamElement3d::sectionRotationMoment, sectionRotationCoupling)
// and the Rayleigh beam's rotary inertia.
//  1. A twisted beam's inertia tensor against the exact one of rigidly turned sections:
//     third order in the twist with R_kl, second order without.
//  2. A shaft spinning about its own axis: its torsional frequencies do not depend on the
//     spin (pure twist keeps every section point on its circle); the first-order field
//     alone gives omega^2 = omega0^2 - Omega^2, unstable above omega0.
//  3. A blade spinning about a hub axis across it: the propeller moment stiffens torsion,
//     omega^2 = omega0^2 + Omega^2 (Iz - Iy) / Ip (rigid section, Iz = int y^2 dA the
//     section's moment about the chord direction in the plane of rotation).
//  4. The shaft in the engine (revolute joint, angle driver at 2 omega0): a torsional
//     mode keeps its amplitude and frequency.
//  5. A simply supported Rayleigh shaft: forward and backward whirl against the
//     continuum (the gyroscopic split the Euler-Bernoulli element cannot show).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "core/system.hpp"
#include "core/time_law.hpp"
#include "simulation/simulation.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"

using namespace flexmbd;

namespace {

/// A section with Iy != Iz and a small St Venant constant, so that torsion is the lowest
/// motion (below bending even at twice its frequency) and Omega up to 2 omega0 stays in
/// the stable range of the bending modes: L = 1 m, 8 elements.
BeamSection3d lowTorsionSection() {
  BeamSection3d s;
  s.area = 1e-3;
  s.inertiaY = 2e-8;  // int z^2 dA
  s.inertiaZ = 8e-8;  // int y^2 dA
  s.torsionConstant = 4e-12;
  s.youngsModulus = 2.1e11;
  s.shearModulus = 8.1e10;
  s.density = 7800.0;
  return s;
}

/// `modes` > 0: modal reduction to the lowest modes (R_kl carried through).
std::shared_ptr<const FfrBeamModel3d> cantilever(int elements = 8, int modes = 0) {
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  o.modes = modes;
  return std::make_shared<const FfrBeamModel3d>(BeamMesh3d::straight(1.0, elements, lowTorsionSection()), o,
                                                "body 'beam'");
}

/// The model's invariants with or without the sections' second-order rotation (R_kl).
FfrInvariants3d invariants(const FfrBeamModel3d& m, bool sectionRotation) {
  FfrInvariants3d inv = m.invariants();
  if (!sectionRotation) {
    for (auto& row : inv.rKL)
      for (SpMat& R : row) R = SpMat();
  }
  return inv;
}

/// Twist (rotation about the body x axis) of each nodal coordinate's column: row 3 of
/// every node in basis().
VecX twistWeights(const FfrBeamModel3d& m) {
  const int nn = static_cast<int>(m.mesh().nodes.size());
  VecX w = VecX::Zero(m.numElastic());
  const MatX B(m.basis());
  for (int n = 0; n < nn; ++n) w += B.row(6 * n + 3).transpose().cwiseAbs();
  return w;
}

/// The eigen-decomposition of the body's elastic equations m_ff q'' = Q_f(q, q')
/// linearised about q_f = 0 with its frame spinning at `w` (body axes) and held
/// (R'' = 0, w' = 0), first-order form [q; q'].
Eigen::EigenSolver<MatX> spinningLinearisation(const FfrBody3d& body, const Vec3& w) {
  const int nf = body.numElastic(), nq = 7 + nf, nv = 6 + nf;
  VecX q = body.initialCoordinates(), v = VecX::Zero(nv);
  v.segment<3>(3) = w;
  MatX dQdq = MatX::Zero(nv, nq), dQdv = MatX::Zero(nv, nv);
  body.addInternalForceJacobians(q, v, dQdq, dQdv);
  const MatX Minv = MatX(body.invariants().mff).inverse();
  MatX A = MatX::Zero(2 * nf, 2 * nf);
  A.topRightCorner(nf, nf).setIdentity();
  A.bottomLeftCorner(nf, nf) = Minv * dQdq.block(6, 7, nf, nf);
  A.bottomRightCorner(nf, nf) = Minv * dQdv.block(6, 6, nf, nf);
  return Eigen::EigenSolver<MatX>(A);
}

/// The torsional frequencies (rad/s, ascending) at spin `w` (spinningLinearisation): a
/// mode is torsional when its twist coordinates hold more than 99% of its norm; a
/// divergent one (real pair) reports -rate.
std::vector<double> torsionalFrequencies(const FfrBody3d& body, const VecX& twist, const Vec3& w) {
  const int nf = body.numElastic();
  const Eigen::EigenSolver<MatX> es = spinningLinearisation(body, w);
  std::vector<double> out;
  for (int k = 0; k < 2 * nf; ++k) {
    const std::complex<double> lam = es.eigenvalues()[k];
    const Eigen::VectorXd x = es.eigenvectors().col(k).head(nf).cwiseAbs();
    if (x.cwiseProduct(twist.cwiseMin(1.0)).squaredNorm() < 0.99 * x.squaredNorm()) continue;
    if (std::abs(lam.imag()) <= 1e-9 * std::abs(lam)) {
      if (lam.real() > 0) out.push_back(-lam.real());  // divergence
    } else if (lam.imag() > 0) {
      out.push_back(lam.imag());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Tolerances.
//  - kSameFrequency: with R_kl the spin terms of pure twist cancel in the matrices
//    themselves (S_yy + S_zz + R_yy + R_zz = 0 on the twist coordinates, to the round-off
//    of the 5-point quadrature sums); what is left is the eigensolver's round-off,
//    eps ||A|| / omega^2 ~ 1e-16 * 1e9 / 1e2 ~ 1e-9 relative in omega^2: 1e-7.
//  - kClosedForm: the rigid-section laws omega^2 = omega0^2 + c Omega^2 hold exactly for
//    the discrete model (the added stiffness c Omega^2 rho Ip int tx^T tx is proportional
//    to the torsional mass rho Ip int tx^T tx), so the same round-off bound applies.
constexpr double kSameFrequency = 1e-7;
constexpr double kClosedForm = 1e-7;

}  // namespace

TEST(SectionRotation, TwistedBeamInertiaIsExactToThirdOrder) {
  // Pure twist tx(x) = eps x (linear: the element's own field, so the only error is the
  // truncation of the rotation). The exact second moment of the turned sections,
  // per length: y' = y cos t - z sin t, z' = y sin t + z cos t, so
  //   int y'^2 = Iz c^2 + Iy s^2, int z'^2 = Iz s^2 + Iy c^2, int y' z' = (Iz - Iy) s c,
  // integrated along x by 40-point Gauss per element (round-off). The body's I(q_f) keeps
  // terms to second order in q_f: its error falls as eps^3 (the cubic term of s c) with
  // R_kl, as eps^2 without (the t^2 of c^2 and s^2 missing).
  const auto model = cantilever(4);
  const BeamSection3d s = lowTorsionSection();
  const FfrBody3d withR("with", invariants(*model, true), FrameState3d{});
  const FfrBody3d without("without", invariants(*model, false), FrameState3d{});
  const MatX B(model->basis());
  const int nn = static_cast<int>(model->mesh().nodes.size());
  auto errors = [&](double eps, double& eR, double& e1) {
    VecX nodal = VecX::Zero(6 * nn);
    for (int n = 0; n < nn; ++n) nodal[6 * n + 3] = eps * model->mesh().nodes[n].x();
    // nodal = B qf (B selects the free nodes' coordinates under the clamped reference)
    const VecX qf = (B.transpose() * B).ldlt().solve(B.transpose() * nodal);
    VecX q = withR.initialCoordinates();
    q.tail(qf.size()) = qf;
    // exact: J = int rho x x^T dV about the frame origin (node 0), then I = tr(J) 1 - J
    const double rho = s.density, L = 1.0;
    Mat3 J = Mat3::Zero();
    J(0, 0) = rho * s.area * L * L * L / 3;  // int rho x^2 dV, exactly
    const int ng = 160;
    for (int g = 0; g < ng; ++g) {  // midpoint rule refined: integrand smooth, 160 points
      const double x = (g + 0.5) * L / ng, w = L / ng, t = eps * x, c = std::cos(t), sn = std::sin(t);
      J(1, 1) += w * rho * (s.inertiaZ * c * c + s.inertiaY * sn * sn);
      J(2, 2) += w * rho * (s.inertiaZ * sn * sn + s.inertiaY * c * c);
      J(1, 2) += w * rho * (s.inertiaZ - s.inertiaY) * sn * c;
    }
    J(2, 1) = J(1, 2);
    const Mat3 I = J.trace() * Mat3::Identity() - J;
    const double scale = rho * (s.inertiaY + s.inertiaZ) * L;  // the sections' polar inertia

    eR = (withR.inertiaAt(q) - I).cwiseAbs().maxCoeff() / scale;
    e1 = (without.inertiaAt(q) - I).cwiseAbs().maxCoeff() / scale;
  };
  double a1, b1, a2, b2;
  errors(0.2, a1, b1);
  errors(0.1, a2, b2);
  std::printf("[ figures ] twisted beam inertia, error / (rho Ip L): eps 0.2: %.3e with R_kl, %.3e without; "
              "eps 0.1: %.3e, %.3e; orders %.2f and %.2f\n",
              a1, b1, a2, b2, std::log2(a1 / a2), std::log2(b1 / b2));
  // the midpoint rule's own error on the sections' terms, (L/ng)^2 eps^2 / 24 ~ 1e-6 eps^2
  // of rho Ip L: far below both
  EXPECT_NEAR(std::log2(a1 / a2), 3.0, 0.1);  // third order with R_kl
  EXPECT_NEAR(std::log2(b1 / b2), 2.0, 0.1);  // second order without
  EXPECT_LT(a2, 0.05 * b2);
}

TEST(SpinningShaft, TorsionalFrequenciesDoNotDependOnTheSpin) {
  const auto model = cantilever();
  const VecX twist = twistWeights(*model);
  const FfrBody3d withR("with", invariants(*model, true), FrameState3d{});
  const FfrBody3d without("without", invariants(*model, false), FrameState3d{});
  const std::vector<double> rest = torsionalFrequencies(withR, twist, Vec3::Zero());
  ASSERT_GE(rest.size(), 2u);
  const double w0 = rest[0];
  // the first clamped-free torsional frequency of the continuum: (pi / 2L) sqrt(GJ / rho Ip)
  const BeamSection3d s = lowTorsionSection();
  const double continuum = M_PI / 2 * std::sqrt(s.torsionStiffness() / (s.density * s.polarMoment()));
  std::printf("[ figures ] shaft torsion at rest: %.6f rad/s (continuum %.6f; linear twist, 8 elements)\n", w0,
              continuum);
  EXPECT_NEAR(w0 / continuum, 1.0, 3e-3);  // linear twist field, 8 elements: (pi/16)^2 / 12 ~ 3e-3
  for (double ratio : {0.5, 1.0, 1.5, 2.0}) {
    const Vec3 spin(ratio * w0, 0.0, 0.0);
    const std::vector<double> now = torsionalFrequencies(withR, twist, spin);
    const std::vector<double> before = torsionalFrequencies(without, twist, spin);
    ASSERT_GE(now.size(), 2u);
    ASSERT_GE(before.size(), 1u);
    std::printf("[ figures ] shaft spinning at %.1f omega0: torsion %.6f, %.6f rad/s (at rest %.6f, %.6f); "
                "first-order field %+.6f (omega0^2 - Omega^2 gives %+.6f)\n",
                ratio, now[0], now[1], rest[0], rest[1], before[0],
                ratio < 1 ? std::sqrt(w0 * w0 - spin.x() * spin.x()) : -std::sqrt(spin.x() * spin.x() - w0 * w0));
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(now[k] / rest[k], 1.0, kSameFrequency) << ratio;
    // the defect this fixes: the first-order field softens torsion by Omega^2
    const double expected = ratio < 1 ? std::sqrt(w0 * w0 - spin.x() * spin.x())
                                      : -std::sqrt(spin.x() * spin.x() - w0 * w0);
    if (ratio != 1.0) EXPECT_NEAR(before[0] / expected, 1.0, 1e-6) << ratio;
  }
}

TEST(SpinningBlade, PropellerMomentStiffensTorsion) {
  // Blade along body x from the hub axis (body z through node 0), chord along y in the
  // plane of rotation: omega^2 = omega0^2 + Omega^2 (Iz - Iy) / Ip.
  const auto model = cantilever();
  const VecX twist = twistWeights(*model);
  const BeamSection3d s = lowTorsionSection();
  const double c = (s.inertiaZ - s.inertiaY) / s.polarMoment(), c1 = -s.inertiaY / s.polarMoment();
  const FfrBody3d withR("with", invariants(*model, true), FrameState3d{});
  const FfrBody3d without("without", invariants(*model, false), FrameState3d{});
  const std::vector<double> rest = torsionalFrequencies(withR, twist, Vec3::Zero());
  ASSERT_GE(rest.size(), 1u);
  const double w0 = rest[0];
  for (double ratio : {0.5, 1.0, 2.0}) {
    const double Om = ratio * w0;
    const std::vector<double> now = torsionalFrequencies(withR, twist, Vec3(0, 0, Om));
    const std::vector<double> before = torsionalFrequencies(without, twist, Vec3(0, 0, Om));
    ASSERT_GE(now.size(), 1u);
    ASSERT_GE(before.size(), 1u);
    const double expected = std::sqrt(w0 * w0 + c * Om * Om), expected1 = std::sqrt(w0 * w0 + c1 * Om * Om);
    std::printf("[ figures ] blade spinning at %.1f omega0: torsion %.6f rad/s (closed form %.6f); first-order "
                "field %.6f (omega0^2 - Omega^2 Iy/Ip gives %.6f)\n",
                ratio, now[0], expected, before[0], expected1);
    EXPECT_NEAR(now[0] / expected, 1.0, kClosedForm) << ratio;
    EXPECT_NEAR(before[0] / expected1, 1.0, 1e-6) << ratio;
  }
}

TEST(SpinningShaft, TorsionalModeKeepsItsAmplitudeAndFrequencyInTheEngine) {
  // The shaft on a revolute joint about world x at node 0 with an angle driver at
  // constant speed 2 omega0 (above the old instability), started in its first torsional
  // mode (tip twist amplitude 1e-3 rad) and run over 6 periods at rtol 1e-8. Measured:
  // the tip twist's amplitude and its zero-crossing frequency. The body keeps its lowest
  // 12 modes (the reduction carries R_kl: FfrInvariants3d::transformed), which spares the
  // integrator the nodal model's axial modes (~1e5 rad/s).
  //  - kAmplitude 1e-3: the mode's nonlinear coupling (rotation of the sections by the
  //    twist, O(amplitude) = 1e-3 of its own terms... reaching the frame only at second
  //    order) and the integration error (rtol 1e-8 over 6 periods) stay below it.
  //  - kFrequency 1e-4 (the bound): crossings interpolated linearly at 200
  //    outputs per period, error ~ (2 pi / 200)^3 / 24 ~ 1e-6, plus the phase error.
  constexpr double kAmplitudeTol = 1e-3, kFrequencyTol = 1e-4, kAmplitude = 1e-3;
  const auto model = cantilever(8, 12);
  const VecX twist = twistWeights(*model);
  const FfrBody3d probe("probe", model, FrameState3d{});
  // the first torsional mode at rest: K phi = omega^2 m_ff phi on the twist coordinates
  const MatX K(probe.invariants().kff), M(probe.invariants().mff);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> ge(K, M);
  int mode = -1;
  for (int k = 0; k < ge.eigenvalues().size() && mode < 0; ++k) {
    const Eigen::VectorXd x = ge.eigenvectors().col(k).cwiseAbs();
    if (x.cwiseProduct(twist.cwiseMin(1.0)).squaredNorm() > 0.99 * x.squaredNorm()) mode = k;
  }
  ASSERT_GE(mode, 0);
  const double w0 = std::sqrt(ge.eigenvalues()[mode]);
  const MatX B(model->basis());
  const int tipTwist = 6 * (static_cast<int>(model->mesh().nodes.size()) - 1) + 3;
  VecX phi = ge.eigenvectors().col(mode);
  phi *= kAmplitude / (B.row(tipTwist) * phi)(0);
  const double Om = 2.0 * w0;

  System sys;
  FrameState3d s;
  s.angularVelocity = Vec3(Om, 0, 0);
  const BodyIndex bi = sys.addBody(std::make_unique<FfrBody3d>("shaft", model, s, phi, VecX::Zero(phi.size())));
  JointFrame axisX;  // joint axis (frame z) along the shaft (x)
  axisX.axes << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  sys.addConstraint(std::make_unique<SpatialJoint>("bearing", SpatialJointType::Revolute, kGround, axisX, bi, axisX));
  sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, axisX, bi, axisX,
                                                             makeConstantSpeedLaw(Om, 0.0)));
  sys.finalize();
  SolverSettings st;
  st.rtol = 1e-8;
  st.atol = 1e-10;
  const double period = 2 * M_PI / w0;
  st.tEnd = 6 * period;
  st.outputStep = period / 200;
  st.progress = false;
  const int oq = sys.coordinateOffset(bi) + 7;
  std::vector<double> t, u;
  const SimulationSummary r = simulate(sys, st, [&](const OutputSample& o) {
    t.push_back(o.t);
    u.push_back((B.row(tipTwist) * o.q.segment(oq, phi.size()))(0));
  });
  ASSERT_TRUE(r.ok) << r.message;
  double peak = 0;
  for (double x : u) peak = std::max(peak, std::abs(x));
  std::vector<double> tc;
  for (size_t k = 1; k < u.size(); ++k) {
    if ((u[k - 1] < 0) != (u[k] < 0)) tc.push_back(t[k - 1] + (t[k] - t[k - 1]) * u[k - 1] / (u[k - 1] - u[k]));
  }
  ASSERT_GE(tc.size(), 10u);
  const double measured = M_PI * (tc.size() - 1) / (tc.back() - tc.front());
  std::printf("[ figures ] shaft at 2 omega0 in the engine: tip twist peak %.6e rad (started %.1e), torsion "
              "%.6f rad/s (at rest %.6f), %ld steps\n",
              peak, kAmplitude, measured, w0, r.stats.steps);
  EXPECT_NEAR(peak / kAmplitude, 1.0, kAmplitudeTol);
  EXPECT_NEAR(measured / w0, 1.0, kFrequencyTol);
}

namespace {

/// The two lowest bending frequencies (rad/s, ascending) in the frame spinning at
/// Omega about x (positive imaginary parts of the linearised m_ff q'' = Q_f; bending: less
/// than 1% of the mode in twist and axial coordinates).
std::vector<double> bendingFrequencies(const FfrBody3d& body, const FfrBeamModel3d& m, double Omega) {
  const int nf = body.numElastic();
  const Eigen::EigenSolver<MatX> es = spinningLinearisation(body, Vec3(Omega, 0.0, 0.0));
  const MatX B(m.basis());
  const int nn = static_cast<int>(m.mesh().nodes.size());
  std::vector<double> out;
  for (int k = 0; k < 2 * nf; ++k) {
    const std::complex<double> lam = es.eigenvalues()[k];
    if (lam.imag() <= 1e-9 * std::abs(lam)) continue;
    const Eigen::VectorXcd nodal = B.cast<std::complex<double>>() * es.eigenvectors().col(k).head(nf);
    double along = 0, all = 0;  // axial and twist vs all nodal motion (rotations scaled by L = 1)
    for (int n = 0; n < nn; ++n) {
      for (int c = 0; c < 6; ++c) {
        const double a = std::norm(nodal[6 * n + c]);
        all += a;
        if (c == 0 || c == 3) along += a;
      }
    }
    if (along < 0.01 * all) out.push_back(lam.imag());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(SpinningShaft, RayleighShaftWhirlsForwardAndBackwardAsTheContinuum) {
  // A simply supported steel shaft (pinned-pinned frame: the chord frame spins with the
  // shaft at Omega about its axis), L = 1 m, d = 0.1 m (L/r = 40), 16 elements. In the
  // fixed frame the first mode of the spinning Rayleigh shaft (Euler-Bernoulli stiffness,
  // rotary inertia rho I, gyroscopic moment rho Ip Omega, Ip = 2 I) whirls at
  //   omega^2 (rho A + rho I k^2) -+ Omega rho Ip k^2 omega - EI k^4 = 0,  k = pi / L,
  // forward (+) and backward (-) (e.g. Genta, Dynamics of Rotating Systems, 2005, sec.
  // 4.9; Lalanne & Ferraris, Rotordynamics Prediction in Engineering, ch. 2). The body
  // frame turns with the shaft, so it sees omega_F - Omega and omega_B + Omega. The
  // Euler-Bernoulli element has no gyroscopic moment: no split.
  //  - kWhirl 1e-5: the 16-element Hermite model's own error in the first frequency
  //    (measured at rest against the closed form: printed, 8e-7); the same holds at speed.
  //  - kSplit 1e-3 of the split omega_F - omega_B (~0.4-0.7% of omega): the two
  //    frequencies' discretisation errors nearly cancel in it (measured 1e-5).
  //  - kNoSplit 1e-7: the Euler-Bernoulli pair's difference is the nonsymmetric
  //    eigensolver's round-off, eps ||A|| / omega^2 ~ 1e-16 * 1e11 / 1.6e6 ~ 1e-8.
  constexpr double kWhirl = 1e-5, kSplit = 1e-3, kNoSplit = 1e-7;
  const double d = 0.1, L = 1.0;
  const BeamSection3d s = circularSection3d(d, 2.1e11, 8.1e10, 7800.0);
  auto shaft = [&](BeamTheory theory) {
    FfrBeamOptions3d o;
    o.reference.type = ReferenceConditions3d::Type::PinnedPinned;
    o.theory = theory;
    return std::make_shared<const FfrBeamModel3d>(BeamMesh3d::straight(L, 16, s), o, "body 'shaft'");
  };
  const auto ray = shaft(BeamTheory::Rayleigh), eb = shaft(BeamTheory::EulerBernoulli);
  const FfrBody3d rayBody("rayleigh", ray, FrameState3d{}), ebBody("euler-bernoulli", eb, FrameState3d{});
  const double rhoA = s.density * s.area, rhoI = s.density * s.inertiaZ, rhoIp = s.density * s.polarMoment();
  const double k = M_PI / L, m = rhoA + rhoI * k * k, K = s.bendingStiffnessZ() * std::pow(k, 4);
  const double w0 = std::sqrt(K / m);
  const std::vector<double> rest = bendingFrequencies(rayBody, *ray, 0.0);
  ASSERT_GE(rest.size(), 2u);
  std::printf("[ figures ] Rayleigh shaft at rest: %.6f rad/s (continuum %.6f, error %.1e; Euler-Bernoulli "
              "continuum %.6f)\n",
              rest[0], w0, rest[0] / w0 - 1, std::sqrt(K / rhoA));
  EXPECT_NEAR(rest[0] / w0, 1.0, kWhirl);
  for (double ratio : {0.3, 0.6}) {
    const double Om = ratio * w0, a = Om * rhoIp * k * k;
    const double wF = (a + std::sqrt(a * a + 4 * m * K)) / (2 * m), wB = (-a + std::sqrt(a * a + 4 * m * K)) / (2 * m);
    const std::vector<double> r = bendingFrequencies(rayBody, *ray, Om), e = bendingFrequencies(ebBody, *eb, Om);
    ASSERT_GE(r.size(), 2u);
    ASSERT_GE(e.size(), 2u);
    const double mF = r[0] + Om, mB = r[1] - Om;  // back to the fixed frame
    std::printf("[ figures ] Rayleigh shaft at %.1f omega0: forward %.6f (continuum %.6f), backward %.6f (%.6f) "
                "rad/s; split %.6f (%.6f); Euler-Bernoulli split %.2e\n",
                ratio, mF, wF, mB, wB, mF - mB, wF - wB, (e[0] + Om) - (e[1] - Om));
    EXPECT_NEAR(mF / wF, 1.0, kWhirl);
    EXPECT_NEAR(mB / wB, 1.0, kWhirl);
    EXPECT_NEAR((mF - mB) / (wF - wB), 1.0, kSplit);
    EXPECT_NEAR((e[0] + Om) / (e[1] - Om), 1.0, kNoSplit);  // no gyroscopic split without rotary inertia
  }
}
