// Craig-Bampton reduction of the planar and spatial beam models (
// bodies/modal_reduction.hpp): the basis holds exactly the static response of the nodal
// model to loads at the interface nodes (so its section forces are the nodal model's),
// its fixed-interface frequencies are those of the nodal model with the interface held,
// its invariants are the projection of the nodal invariants, a spatial cantilever under
// tip loads is recovered exactly; input errors.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "core/errors.hpp"
#include "elements/beam_section.hpp"
#include "tests/test_support.hpp"

using namespace flexmbd;
using testsupport::expectInputError;

namespace {

// Static responses of the nodal and the reduced model to the same loads: two dense
// Cholesky solves of K_ff (cond(K_ff) ~ 1e8 for these steel beams: axial EA/l against
// rotational EI/l entries), so the round-off is ~eps cond ~ 1e-8 of the largest entry
// in the worst coordinate; measured <= 6e-12 (relative to the largest displacement).
constexpr double kStaticTol = 1e-8;
// Section forces from those displacements: the element stiffness times the nodal
// displacements. The displacement round-off (~1e-11 of the largest, a bending
// displacement) is relative to the bending field, while the axial displacements of
// these slender steel frames are ~1e-5 of it (ratio ~ EI / (EA L^2)); the axial force
// EA (u2 - u1) / l thus carries a relative round-off ~1e-6: measured <= 3.5e-7 (planar
// clamped L-frame), 1e-10 elsewhere.
constexpr double kSectionTol = 1e-5;
// Frequencies of the same generalized eigenproblem computed in two bases: round-off
// ~eps lambda_max / lambda_k, below 1e-9 for these meshes.
constexpr double kFrequencyTol = 1e-9;
// Invariants by two routes of the same products (B2 P with P least-squares recovered
// from the bases): round-off relative to each block's size.
constexpr double kProjectionTol = 1e-10;

using RC = ReferenceConditions::Type;
using RC3 = ReferenceConditions3d::Type;

// 8 mm x 8 mm steel: the connecting rod of examples/slider_crank_elastic.json
BeamSection steel8mm() { return rectangularSection(0.008, 0.008, 2e11, 7870.0); }

/// L-shaped frame (0,0)-(0.3,0)-(0.3,0.2), `perLeg` elements on each leg.
BeamMesh2d lFrame(int perLeg) {
  BeamMesh2d m;
  const Vec2 P0(0, 0), P1(0.3, 0), P2(0.3, 0.2);
  for (int i = 0; i <= perLeg; ++i) m.nodes.push_back(P0 + (P1 - P0) * double(i) / perLeg);
  for (int i = 1; i <= perLeg; ++i) m.nodes.push_back(P1 + (P2 - P1) * double(i) / perLeg);
  for (int i = 0; i < 2 * perLeg; ++i) m.elements.push_back({i, i + 1, steel8mm()});
  return m;
}

FfrBeamOptions planarOptions(RC type, ModalReduction reduction, int modes, std::vector<int> interfaceNodes = {}) {
  FfrBeamOptions o;
  o.reference.type = type;
  o.reduction = reduction;
  o.modes = modes;
  o.interfaceNodes = std::move(interfaceNodes);
  return o;
}

const char* name(RC t) {
  return t == RC::Clamped ? "clamped" : t == RC::PinnedPinned ? "pinned_pinned" : "free_free";
}
const char* name(RC3 t) {
  return t == RC3::Clamped ? "clamped" : t == RC3::PinnedPinned ? "pinned_pinned" : "free_free";
}

/// Elastic coordinates of the static response K_ff q = basis^T f to nodal loads f (the
/// generalized forces of nodal forces and moments, body frame).
template <class Model>
VecX staticResponse(const Model& m, const VecX& f) {
  const MatX B = MatX(m.basis());
  return MatX(m.invariants().kff).llt().solve(B.transpose() * f);
}

/// Random loads on every coordinate of the nodes (nodeDofs per node), zero elsewhere.
VecX interfaceLoads(int numNodeDofs, int nodeDofs, const std::vector<int>& nodes, unsigned seed, double scale) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX f = VecX::Zero(numNodeDofs);
  for (int n : nodes) {
    for (int k = 0; k < nodeDofs; ++k) f[nodeDofs * n + k] = scale * u(gen);
  }
  return f;
}

/// P with basisReduced = basisNodal P (exact when the reduced basis lies in the nodal
/// one's range, as every reduction of the same reference conditions does).
template <class Model>
SpMat projection(const Model& nodal, const Model& reduced) {
  const MatX Bn = MatX(nodal.basis()), Br = MatX(reduced.basis());
  const MatX P = Bn.colPivHouseholderQr().solve(Br);
  EXPECT_LT((Bn * P - Br).norm(), 1e-12 * Br.norm()) << "reduced basis outside the nodal range";
  return P.sparseView();
}

/// Largest entry of a - b relative to the largest entry of a, b, or to `scale` if that
/// is larger (blocks that vanish, e.g. S-bar under mean-axis conditions, hold only
/// round-off: they are compared on the scale they would have).
double relDiff(const MatX& a, const MatX& b, double scale = 0.0) {
  const double s = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), scale});
  return s > 0 ? (a - b).cwiseAbs().maxCoeff() / s : 0.0;
}

/// The scale of int rho f N dV for a weight f with int rho f^2 dV = fSquared: by
/// Cauchy-Schwarz |int rho f N q dV| <= sqrt(fSquared q^T m_ff q).
double inertiaScale(double fSquared, const SpMat& mff) { return std::sqrt(fSquared * MatX(mff).diagonal().maxCoeff()); }

}  // namespace

// ----- planar -------------------------------------------------------------------------

TEST(CraigBampton, PlanarBasisHoldsTheStaticResponseToInterfaceLoads) {
  // L-frame, 4 elements per leg (9 nodes), interface: both ends and the corner; loads
  // (forces ~100 N, moments ~100 N m) at the interface nodes only. The Galerkin solution
  // in a basis that contains the exact solution is the exact solution.
  const std::vector<int> iface = {0, 4, 8};
  for (RC type : {RC::Clamped, RC::PinnedPinned, RC::FreeFree}) {
    const FfrBeamModel nodal(lFrame(4), planarOptions(type, ModalReduction::Normal, 0), "body 'frame'");
    const FfrBeamModel cb(lFrame(4), planarOptions(type, ModalReduction::CraigBampton, 3, iface), "body 'frame'");
    const FfrBeamModel normal(lFrame(4), planarOptions(type, ModalReduction::Normal, cb.numElastic()), "body 'frame'");
    // constraint modes: every interface coordinate not held by the reference conditions
    const int held = type == RC::Clamped ? 3 : type == RC::PinnedPinned ? 3 : 0;
    EXPECT_EQ(static_cast<int>(cb.constraintModeCoordinates().size()), 9 - held) << name(type);
    EXPECT_EQ(cb.numElastic(), 9 - held + 3) << name(type);
    const VecX f = interfaceLoads(27, 3, iface, 7, 100.0);
    const VecX un = MatX(nodal.basis()) * staticResponse(nodal, f);
    const VecX qc = staticResponse(cb, f);
    const VecX uc = MatX(cb.basis()) * qc;
    const VecX um = MatX(normal.basis()) * staticResponse(normal, f);
    const double errCb = (uc - un).cwiseAbs().maxCoeff() / un.cwiseAbs().maxCoeff();
    const double errNormal = (um - un).cwiseAbs().maxCoeff() / un.cwiseAbs().maxCoeff();
    EXPECT_LT(errCb, kStaticTol) << name(type);
    // the first elastic coordinates are the interface displacements themselves
    for (size_t k = 0; k < cb.constraintModeCoordinates().size(); ++k) {
      EXPECT_NEAR(qc[k], un[cb.constraintModeCoordinates()[k]], kStaticTol * un.cwiseAbs().maxCoeff()) << name(type);
    }
    // section forces at every element's midpoint and ends: the nodal model's
    double nMax = 0, errN = 0, errM = 0, errNormalN = 0;
    const VecX qn = staticResponse(nodal, f), qm = staticResponse(normal, f);
    std::vector<Vec2> sn, sc, sm;
    for (int e = 0; e < 8; ++e) {
      for (double xi : {0.0, 0.5, 1.0}) {
        sn.push_back(nodal.sectionForces(qn, e, xi));
        sc.push_back(cb.sectionForces(qc, e, xi));
        sm.push_back(normal.sectionForces(qm, e, xi));
      }
    }
    double mMax = 0;
    for (const Vec2& s : sn) nMax = std::max(nMax, std::abs(s[0])), mMax = std::max(mMax, std::abs(s[1]));
    for (size_t k = 0; k < sn.size(); ++k) {
      errN = std::max(errN, std::abs(sc[k][0] - sn[k][0]) / nMax);
      errM = std::max(errM, std::abs(sc[k][1] - sn[k][1]) / mMax);
      errNormalN = std::max(errNormalN, std::abs(sm[k][0] - sn[k][0]) / nMax);
    }
    EXPECT_LT(errN, kSectionTol) << name(type);
    EXPECT_LT(errM, kSectionTol) << name(type);
    std::printf("[ measured ] %s, %d coordinates: static response error CB %.1e, normal modes %.1e; axial force "
                "error CB %.1e, normal modes %.1e; moment error CB %.1e\n",
                name(type), cb.numElastic(), errCb, errNormal, errN, errNormalN, errM);
  }
}

TEST(CraigBampton, PlanarFixedInterfaceFrequenciesAreThoseOfTheHeldInterface) {
  // The slider-crank rod (8 elements, pinned-pinned), interface its two end nodes: the
  // fixed-interface structure is the clamped-clamped rod. The nodal model with the
  // interface held: its K_ff, m_ff without the coordinates of the end nodes (unit
  // columns of the pinned B2).
  const BeamMesh2d rod = BeamMesh2d::straight(0.3, 8, steel8mm());
  const FfrBeamModel nodal(rod, planarOptions(RC::PinnedPinned, ModalReduction::Normal, 0), "body 'rod'");
  const FfrBeamModel cb(rod, planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 5, {0, 8}), "body 'rod'");
  const MatX B = MatX(nodal.basis());
  std::vector<int> inner;
  for (int c = 0; c < B.cols(); ++c) {
    const bool atInterface = B.col(c).head(3).cwiseAbs().maxCoeff() > 0 || B.col(c).tail(3).cwiseAbs().maxCoeff() > 0;
    if (!atInterface) inner.push_back(c);
  }
  ASSERT_EQ(inner.size(), 21u);  // 7 inner nodes x 3
  const MatX K = MatX(nodal.invariants().kff)(inner, inner), M = MatX(nodal.invariants().mff)(inner, inner);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> eig(K, M, Eigen::EigenvaluesOnly);
  const VecX& w = cb.fixedInterfaceFrequencies();
  ASSERT_EQ(w.size(), 5);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(w[k], std::sqrt(eig.eigenvalues()[k]), kFrequencyTol * w[k]) << k;
  // the modal block of the CB invariants: m = I, K = diag(omega^2), uncoupled from the
  // constraint modes in K (K Psi loads only the interface, which the modes do not move)
  const int nc = static_cast<int>(cb.constraintModeCoordinates().size());
  EXPECT_EQ(nc, 3);  // psi_0, ux_8, psi_8 (u_0 and uy_8 held by the reference conditions)
  const MatX Kc = MatX(cb.invariants().kff), Mc = MatX(cb.invariants().mff);
  EXPECT_LT((Mc.bottomRightCorner(5, 5) - MatX::Identity(5, 5)).norm(), kFrequencyTol);
  EXPECT_LT(relDiff(Kc.bottomRightCorner(5, 5), MatX(w.cwiseAbs2().asDiagonal())), kFrequencyTol);
  EXPECT_LT(Kc.topRightCorner(nc, 5).norm(), kFrequencyTol * Kc.norm());
  // and the continuum: clamped-clamped bending 4.7300^2 sqrt(EI / rho A) / L^2; 8 Hermite
  // elements converge as h^4 (measured 7e-5)
  const BeamSection s = steel8mm();
  const double w1 = 22.3733 * std::sqrt(s.youngsModulus * s.inertia / s.massPerLength()) / (0.3 * 0.3);
  EXPECT_NEAR(w[0], w1, 1e-4 * w1);
  std::printf("[ measured ] clamped-clamped rod: fixed-interface frequencies %.1f %.1f %.1f %.1f %.1f rad/s "
              "(continuum first %.1f)\n", w[0], w[1], w[2], w[3], w[4], w1);
}

TEST(CraigBampton, PlanarInvariantsAreTheProjectionOfTheNodalInvariants) {
  for (RC type : {RC::Clamped, RC::PinnedPinned, RC::FreeFree}) {
    const FfrBeamModel nodal(lFrame(3), planarOptions(type, ModalReduction::Normal, 0), "body 'frame'");
    const FfrBeamModel cb(lFrame(3), planarOptions(type, ModalReduction::CraigBampton, 2, {0, 6}), "body 'frame'");
    const FfrInvariants p = nodal.invariants().transformed(projection(nodal, cb));
    const FfrInvariants& c = cb.invariants();
    const std::string what = name(type);
    EXPECT_EQ(c.mass, p.mass) << what;
    const double sBarScale = inertiaScale(c.mass, c.mff), momentScale = inertiaScale(c.polarMoment, c.mff);
    EXPECT_LT(relDiff(c.sBar, p.sBar, sBarScale), kProjectionTol) << what;
    EXPECT_LT(relDiff(c.i1, p.i1, momentScale), kProjectionTol) << what;
    EXPECT_LT(relDiff(c.j0, p.j0, momentScale), kProjectionTol) << what;
    EXPECT_LT(relDiff(MatX(c.mff), MatX(p.mff)), kProjectionTol) << what;
    EXPECT_LT(relDiff(MatX(c.sTilde), MatX(p.sTilde)), kProjectionTol) << what;
    EXPECT_LT(relDiff(MatX(c.kff), MatX(p.kff)), kProjectionTol) << what;
    ASSERT_EQ(c.points.size(), p.points.size());
    for (size_t k = 0; k < c.points.size(); ++k) {
      EXPECT_LT(relDiff(c.points[k].shape, p.points[k].shape), kProjectionTol) << what << " point " << k;
      EXPECT_LT(relDiff(c.points[k].rotationShape, p.points[k].rotationShape), kProjectionTol) << what;
    }
    // and the frame-level invariants do not depend on the reduction
    EXPECT_EQ(c.firstMoment, nodal.invariants().firstMoment);
    EXPECT_EQ(c.polarMoment, nodal.invariants().polarMoment);
  }
}

TEST(CraigBampton, GuyanWithoutFixedInterfaceModesAndModeSets) {
  // modes = 0: static condensation only (Guyan), one coordinate per interface coordinate
  const BeamMesh2d rod = BeamMesh2d::straight(0.3, 8, steel8mm());
  const FfrBeamModel guyan(rod, planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 0, {0, 4, 8}),
                           "body 'rod'");
  EXPECT_EQ(guyan.numElastic(), 6);  // psi_0, ux_4, uy_4, psi_4, ux_8, psi_8
  EXPECT_EQ(guyan.fixedInterfaceFrequencies().size(), 0);
  // a chosen set of fixed-interface modes
  FfrBeamOptions o = planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 0, {0, 8});
  o.modeSet = {1, 3};
  const FfrBeamModel chosen(rod, o, "body 'rod'");
  const FfrBeamModel first3(rod, planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 3, {0, 8}), "body 'rod'");
  ASSERT_EQ(chosen.fixedInterfaceFrequencies().size(), 2);
  EXPECT_NEAR(chosen.fixedInterfaceFrequencies()[1], first3.fixedInterfaceFrequencies()[2],
              kFrequencyTol * first3.fixedInterfaceFrequencies()[2]);
}

TEST(CraigBampton, RejectsBadInterfacesNamingTheBody) {
  const BeamMesh2d rod = BeamMesh2d::straight(0.3, 4, steel8mm());
  const std::string owner = "body 'rod'";
  auto build = [&](const FfrBeamOptions& o) { return [=] { FfrBeamModel m(rod, o, owner); }; };
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 2, {})),
                   {owner, "at least one interface node"});
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 2, {0, 5})),
                   {owner, "interface node 5 does not exist", "nodes 0..4"});
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 2, {4, 0, 4})),
                   {owner, "interface node 4 is listed twice"});
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::Normal, 2, {0, 4})),
                   {owner, "craig_bampton reduction only"});
  // 4 elements, both ends held: 3 inner nodes x 3 = 9 fixed-interface modes
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 10, {0, 4})),
                   {owner, "fixed-interface mode 10 does not exist", "1..9"});
  FfrBeamOptions o = planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 0, {0, 4});
  o.modeSet = {2, 2};
  expectInputError(build(o), {owner, "mode 2 is chosen twice"});
  expectInputError(build(planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, -1, {0, 4})),
                   {owner, "modes must be >= 0"});
  // the spatial model checks the same (shared helper)
  FfrBeamOptions3d o3;
  o3.reduction = ModalReduction::CraigBampton;
  o3.interfaceNodes = {9};
  const BeamMesh3d beam = BeamMesh3d::straight(1.0, 3, rectangularSection3d(0.03, 0.018, 2.1e11, 8.1e10, 7850.0));
  expectInputError([&] { FfrBeamModel3d m(beam, o3, owner); }, {owner, "interface node 9 does not exist", "nodes 0..3"});
}

// ----- spatial ------------------------------------------------------------------------

namespace {

const BeamSection3d kBar = rectangularSection3d(0.03, 0.018, 2.1e11, 8.1e10, 7850.0);

FfrBeamOptions3d spatialOptions(RC3 type, ModalReduction reduction, int modes, std::vector<int> interfaceNodes = {}) {
  FfrBeamOptions3d o;
  o.reference.type = type;
  o.reduction = reduction;
  o.modes = modes;
  o.interfaceNodes = std::move(interfaceNodes);
  return o;
}

/// A bent spatial frame: 3 elements along x, 3 along y, 2 along z (9 nodes).
BeamMesh3d bentFrame3d() {
  BeamMesh3d m;
  m.nodes.push_back(Vec3::Zero());
  const Vec3 legs[3] = {Vec3(0.6, 0, 0), Vec3(0, 0.4, 0), Vec3(0, 0, 0.3)};
  const int per[3] = {3, 3, 2};
  for (int leg = 0; leg < 3; ++leg) {
    for (int i = 1; i <= per[leg]; ++i) {
      m.nodes.push_back(m.nodes.back() + legs[leg] / per[leg]);
      const int n = static_cast<int>(m.nodes.size());
      m.elements.push_back({n - 2, n - 1, kBar, leg == 1 ? Vec3::UnitZ() : Vec3::UnitY()});
    }
  }
  return m;
}

}  // namespace

TEST(CraigBampton, SpatialCantileverUnderTipLoadsIsRecoveredExactly) {
  // Cantilever L = 1.2 m, 6 elements, clamped at node 0, interface the tip node 6: six
  // constraint modes (ux..thz of the tip) and 2 fixed-interface modes. Under an axial
  // tip force F every section carries N = F and the tip moves F L / (EA); under a
  // transverse tip force Qy = F and Mz(x) = F (L - x); under a tip torque Mx = T.
  const double L = 1.2, F = 5e3, T = 40.0;
  const BeamMesh3d beam = BeamMesh3d::straight(L, 6, kBar);
  const FfrBeamModel3d cb(beam, spatialOptions(RC3::Clamped, ModalReduction::CraigBampton, 2, {6}), "body 'beam'");
  const FfrBeamModel3d normal(beam, spatialOptions(RC3::Clamped, ModalReduction::Normal, 8), "body 'beam'");
  ASSERT_EQ(cb.numElastic(), 8);
  const int tip = 6 * 6;
  VecX fAxial = VecX::Zero(42), fY = VecX::Zero(42), fT = VecX::Zero(42);
  fAxial[tip + 0] = F;
  fY[tip + 1] = F;
  fT[tip + 3] = T;
  const VecX qa = staticResponse(cb, fAxial), qy = staticResponse(cb, fY), qt = staticResponse(cb, fT);
  const VecX qaNormal = staticResponse(normal, fAxial);
  EXPECT_NEAR(qa[0], F * L / (kBar.youngsModulus * kBar.area), kStaticTol * F * L / (kBar.youngsModulus * kBar.area));
  double errNormal = 0;
  for (int e = 0; e < 6; ++e) {
    for (double xi : {0.0, 0.5, 1.0}) {
      const double x = L * (e + xi) / 6;
      const BeamSectionForces3d a = cb.sectionForces(qa, e, xi), y = cb.sectionForces(qy, e, xi),
                                t = cb.sectionForces(qt, e, xi);
      EXPECT_NEAR(a.N, F, kSectionTol * F) << e << " " << xi;
      EXPECT_NEAR(y.Qy, F, kSectionTol * F) << e << " " << xi;
      EXPECT_NEAR(y.Mz, F * (L - x), kSectionTol * F * L) << e << " " << xi;
      EXPECT_NEAR(t.Mx, T, kSectionTol * T) << e << " " << xi;
      errNormal = std::max(errNormal, std::abs(normal.sectionForces(qaNormal, e, xi).N - F) / F);
    }
  }
  std::printf("[ measured ] spatial cantilever, axial tip load: N error CB (6 constraint + 2 modes) %.1e, first 8 "
              "normal modes %.3f\n", std::abs(cb.sectionForces(qa, 3, 0.5).N - F) / F, errNormal);
  EXPECT_GT(errNormal, 0.01);  // the normal modes miss it (measured above)
}

TEST(CraigBampton, SpatialBasisHoldsTheStaticResponseAndIsTheProjection) {
  // The bent frame for the three reference conditions (pinned-pinned needs node B on the
  // body x axis: node 3, the end of the x leg), interface nodes 0, 3 and the last.
  const std::vector<int> iface = {0, 3, 8};
  for (RC3 type : {RC3::Clamped, RC3::PinnedPinned, RC3::FreeFree}) {
    FfrBeamOptions3d on = spatialOptions(type, ModalReduction::Normal, 0);
    FfrBeamOptions3d oc = spatialOptions(type, ModalReduction::CraigBampton, 4, iface);
    on.reference.nodeB = oc.reference.nodeB = 3;
    const FfrBeamModel3d nodal(bentFrame3d(), on, "body 'frame'");
    const FfrBeamModel3d cb(bentFrame3d(), oc, "body 'frame'");
    EXPECT_EQ(static_cast<int>(cb.constraintModeCoordinates().size()), 18 - (type == RC3::FreeFree ? 0 : 6))
        << name(type);
    const VecX f = interfaceLoads(54, 6, iface, 11, 1e3);
    const VecX un = MatX(nodal.basis()) * staticResponse(nodal, f);
    const VecX qc = staticResponse(cb, f);
    const VecX uc = MatX(cb.basis()) * qc;
    const double err = (uc - un).cwiseAbs().maxCoeff() / un.cwiseAbs().maxCoeff();
    EXPECT_LT(err, kStaticTol) << name(type);
    const VecX qn = staticResponse(nodal, f);
    double errN = 0, nMax = 0;
    for (int e = 0; e < 8; ++e) nMax = std::max(nMax, std::abs(nodal.sectionForces(qn, e, 0.5).N));
    for (int e = 0; e < 8; ++e) {
      errN = std::max(errN, std::abs(cb.sectionForces(qc, e, 0.5).N - nodal.sectionForces(qn, e, 0.5).N) / nMax);
    }
    EXPECT_LT(errN, kSectionTol) << name(type);
    // invariants: the projection of the nodal ones
    const FfrInvariants3d p = nodal.invariants().transformed(projection(nodal, cb));
    const FfrInvariants3d& c = cb.invariants();
    EXPECT_LT(relDiff(c.sBar, p.sBar, inertiaScale(c.mass, c.mff)), kProjectionTol) << name(type);
    for (int k = 0; k < 3; ++k) {
      const double scale = inertiaScale(c.secondMoment(k, k), c.mff);
      EXPECT_LT(relDiff(c.positionShape[k], p.positionShape[k], scale), kProjectionTol) << name(type);
      for (int l = 0; l < 3; ++l) EXPECT_LT(relDiff(MatX(c.sKL[k][l]), MatX(p.sKL[k][l])), kProjectionTol) << name(type);
    }
    EXPECT_LT(relDiff(MatX(c.mff), MatX(p.mff)), kProjectionTol) << name(type);
    EXPECT_LT(relDiff(MatX(c.kff), MatX(p.kff)), kProjectionTol) << name(type);
    for (size_t k = 0; k < c.points.size(); ++k) {
      EXPECT_LT(relDiff(c.points[k].shape, p.points[k].shape), kProjectionTol) << name(type);
      EXPECT_LT(relDiff(c.points[k].rotationShape, p.points[k].rotationShape), kProjectionTol) << name(type);
    }
    std::printf("[ measured ] spatial bent frame, %s: static response error %.1e, axial force error %.1e\n",
                name(type), err, errN);
  }
}

// ----- inertia modes ------------------------------------------------------------------

namespace {

/// The inertia loads of the frame's rigid motion on the elastic coordinates (columns),
/// as the models build them: planar [S-bar^T, I1, J0]; spatial [S-bar^T, rows of
/// positionShape[k]].
MatX inertiaLoads(const FfrInvariants& inv) {
  MatX F(inv.numElastic(), 4);
  F << inv.sBar.transpose(), inv.i1, inv.j0;
  return F;
}
MatX inertiaLoads(const FfrInvariants3d& inv) {
  MatX F(inv.mff.rows(), 12);
  F.leftCols(3) = inv.sBar.transpose();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) F.col(3 + 3 * k + l) = inv.positionShape[k].row(l).transpose();
  }
  return F;
}

/// Largest difference (relative to the largest displacement) between the nodal and the
/// reduced model's static responses to loads at the interface nodes plus the inertia
/// loads of a rigid motion of the frame (random combination).
template <class Model>
double quasiStaticError(const Model& nodal, const Model& reduced, const VecX& interfaceLoad, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const MatX Fn = inertiaLoads(nodal.invariants()), Fr = inertiaLoads(reduced.invariants());
  VecX c(Fn.cols());
  for (int k = 0; k < c.size(); ++k) c[k] = 1e3 * u(gen);  // accelerations ~1000 m/s^2, rad/s^2
  const MatX Bn = MatX(nodal.basis()), Br = MatX(reduced.basis());
  const VecX un = Bn * MatX(nodal.invariants().kff).llt().solve(Bn.transpose() * interfaceLoad + Fn * c);
  const VecX ur = Br * MatX(reduced.invariants().kff).llt().solve(Br.transpose() * interfaceLoad + Fr * c);
  return (ur - un).cwiseAbs().maxCoeff() / un.cwiseAbs().maxCoeff();
}

}  // namespace

TEST(CraigBampton, InertiaModesHoldTheQuasiStaticResponseToTheFramesMotion) {
  // The slider-crank rod (pinned-pinned, 8 elements), interface its end nodes, 2
  // fixed-interface modes, with and without inertia modes; and 2 normal modes with them.
  // Loads: forces and moments at the end nodes plus the inertia loads of a random rigid
  // acceleration of the frame. Only Craig-Bampton with inertia modes holds the sum.
  const BeamMesh2d rod = BeamMesh2d::straight(0.3, 8, steel8mm());
  const FfrBeamModel nodal(rod, planarOptions(RC::PinnedPinned, ModalReduction::Normal, 0), "body 'rod'");
  FfrBeamOptions o = planarOptions(RC::PinnedPinned, ModalReduction::CraigBampton, 2, {0, 8});
  const FfrBeamModel cb(rod, o, "body 'rod'");
  o.inertiaModes = true;
  const FfrBeamModel cbi(rod, o, "body 'rod'");
  FfrBeamOptions on = planarOptions(RC::PinnedPinned, ModalReduction::Normal, 2);
  on.inertiaModes = true;
  const FfrBeamModel ni(rod, on, "body 'rod'");
  // S-bar_x, S-bar_y, I1, J0 of the pinned rod: axial uniform and linear, transverse
  // uniform and linear loads; none is in the span of 3 constraint + 2 bending modes
  EXPECT_EQ(cbi.numInertiaModes(), 4);
  EXPECT_EQ(cbi.numElastic(), 3 + 2 + 4);
  EXPECT_EQ(cb.numInertiaModes(), 0);
  const VecX f = interfaceLoads(27, 3, {0, 8}, 5, 100.0);
  const double eCbi = quasiStaticError(nodal, cbi, f, 3), eCb = quasiStaticError(nodal, cb, f, 3),
               eNi = quasiStaticError(nodal, ni, f, 3);
  EXPECT_LT(eCbi, kStaticTol);
  EXPECT_GT(eCb, 1e-3);
  std::printf("[ measured ] rod, joint loads + rigid-motion inertia loads: static response error CB 3 + 2 + 4 "
              "inertia modes %.1e, CB 3 + 2 %.1e, normal 2 + 4 inertia modes %.1e\n", eCbi, eCb, eNi);
  // the constraint-mode coordinates are still the interface displacements (the inertia
  // modes are K-orthogonal to the constraint modes, Psi^T K y = Lambda^T G y = 0, so
  // they leave the interface at rest): to the round-off of that projection, ~eps
  // cond(K_ff) ~ 1e-8 of the column (measured <= 1e-10)
  constexpr double kInterfaceRestTol = 1e-8;
  const MatX B = MatX(cbi.basis());
  for (size_t k = 0; k < cbi.constraintModeCoordinates().size(); ++k) {
    const int row = cbi.constraintModeCoordinates()[k];
    for (int c = 0; c < B.cols(); ++c) {
      EXPECT_NEAR(B(row, c), c == static_cast<int>(k) ? 1.0 : 0.0, kInterfaceRestTol * B.col(c).cwiseAbs().maxCoeff());
    }
  }
  // spatial: the bent frame, clamped, interface both ends and the corner
  const std::vector<int> iface = {0, 3, 8};
  FfrBeamOptions3d o3 = spatialOptions(RC3::Clamped, ModalReduction::CraigBampton, 3, iface);
  o3.inertiaModes = true;
  const FfrBeamModel3d nodal3(bentFrame3d(), spatialOptions(RC3::Clamped, ModalReduction::Normal, 0), "body 'frame'");
  const FfrBeamModel3d cbi3(bentFrame3d(), o3, "body 'frame'");
  EXPECT_GT(cbi3.numInertiaModes(), 0);
  EXPECT_LE(cbi3.numInertiaModes(), 12);
  const double e3 = quasiStaticError(nodal3, cbi3, interfaceLoads(54, 6, iface, 9, 1e3), 4);
  EXPECT_LT(e3, kStaticTol);
  std::printf("[ measured ] spatial bent frame, CB 12 + 3 + %d inertia modes: static response error %.1e\n",
              cbi3.numInertiaModes(), e3);
  // an option that needs a reduction
  FfrBeamOptions bad = planarOptions(RC::PinnedPinned, ModalReduction::Normal, 0);
  bad.inertiaModes = true;
  expectInputError([&] { FfrBeamModel m(rod, bad, "body 'rod'"); }, {"body 'rod'", "inertia modes need a modal reduction"});
}
