// Bodies from FE meshes whose nodes have rotations (beams, shells: 6 DOF per node;
// docs/fe-import.md "Beams and shells"). flexmbd's own spatial beam is exported as an
// Abaqus deck (B31 elements) with its nodal mass and stiffness in Abaqus's MATRIX INPUT
// format, read back by readAbaqusFe and made a body by FeBodyModel, and the result is held
// against the beam's own invariants (bodies/ffr_beam_model.hpp), which integrate the
// element shape functions exactly:
//  - the matrices round-trip exactly, and the free-free frequencies are those of a dense
//    generalized eigensolver and, within the discretisation error, of the closed form;
//  - what the rigid motions give is exact for any mass matrix: mass, first and second
//    moment, S-bar, the rotational part of the position shape integrals;
//  - the rest is lumped at the nodes, and converges to the beam's at second order in the
//    element length;
//  - a free spinning, vibrating imported beam conserves energy and momentum (the lumped
//    invariants still form one kinetic energy);
//  - the reader's strictness on 6-DOF files; a rigid interface at one beam node.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "bodies/body_geometry.hpp"
#include "bodies/fe_body_model.hpp"
#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "fe_test_support.hpp"
#include "free_body_drift.hpp"
#include "simulation/simulation.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "scene/scene.hpp"

using namespace flexmbd;
namespace fs = std::filesystem;
using flexmbd::fetest::errorOf;
using flexmbd::fetest::expectMentions;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kE = 2.1e11, kG = 8.1e10, kRho = 7850.0;
constexpr double kLength = 1.2, kWidth = 0.03, kHeight = 0.02;

// Tolerances.
// The matrices are printed with 17 significant digits, which round-trip a double exactly;
// a file of one triangle is mirrored, so it differs from the beam's matrix by that matrix's
// own asymmetry (round-off of its sums, measured 7e-17 of entries of order 1 in M).
double asymmetry(const SpMat& A) { return (MatX(A) - MatX(A).transpose()).cwiseAbs().maxCoeff(); }
// Invariants exact for any mass matrix (sums of O(N) products of the matrices' entries,
// against the beam's own sums of the same integrals): round-off, 1e-12 of their scale.
constexpr double kExactTol = 1e-12;
// Spectra's shift-invert Lanczos (bodies/modal_reduction.hpp) against Eigen's dense
// generalized solver on the same matrices: both converge to 1e-13 of the eigenvalue; 1e-9
// of the frequency leaves a margin for the condition of the 96 x 96 problem.
constexpr double kEigenTol = 1e-9;

/// A straight beam of `elements` elements along x from the origin.
BeamMesh3d straightBeam(int elements) {
  return BeamMesh3d::straight(kLength, elements, rectangularSection3d(kWidth, kHeight, kE, kG, kRho));
}

/// A straight spatial beam of `elements` elements along a skew direction from an offset
/// origin (so every first and second moment and every rotation is off the axes).
BeamMesh3d skewBeam(int elements) {
  const Vec3 origin(0.1, 0.2, -0.1), dir = Vec3(1.0, 0.5, 0.3).normalized();
  const BeamSection3d s = rectangularSection3d(kWidth, kHeight, kE, kG, kRho);
  BeamMesh3d m;
  for (int i = 0; i <= elements; ++i) m.nodes.push_back(origin + (kLength * i / elements) * dir);
  for (int i = 0; i < elements; ++i) {
    BeamMesh3d::Element e;
    e.node1 = i;
    e.node2 = i + 1;
    e.section = s;
    e.yHint = Vec3(0.2, 1.0, -0.4);
    m.elements.push_back(e);
  }
  return m;
}

/// Euler-Bernoulli by default; Rayleigh adds the sections' rotary inertia to m_ff, which the
/// beam's second moment always has, so only then are M's rigid motions the beam's inertia.
FfrBeamModel3d beamModel(int elements, BeamTheory theory = BeamTheory::EulerBernoulli) {
  FfrBeamOptions3d o;
  o.theory = theory;
  return FfrBeamModel3d(skewBeam(elements), o, "beam");
}

/// The Abaqus export of a beam: a deck of B31 elements, node sets END0 and END1, and the
/// nodal mass and stiffness (node a's DOF k at row 6 a + k) as MATRIX INPUT lines "node,
/// DOF, node, DOF, value" (the lower triangle, or both with `both`).
struct AbaqusExport {
  std::string inp, mass, stiffness;
};

void writeMatrixInput(const SpMat& A, const std::string& path, bool both) {
  std::ofstream out(path);
  out << "** written by test_fe_beams_shells\n";
  char line[128];
  for (int j = 0; j < A.outerSize(); ++j) {
    for (SpMat::InnerIterator it(A, j); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (!both && r < j) continue;
      std::snprintf(line, sizeof line, "%d, %d, %d, %d, %.17g\n", r / 6 + 1, r % 6 + 1, j / 6 + 1, j % 6 + 1,
                    it.value());
      out << line;
    }
  }
}

AbaqusExport exportBeam(const FfrBeamModel3d& beam, const std::string& name, bool both = false) {
  // one folder per test: CTest runs the tests of this file in parallel
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_fe_beams_shells_" +
                                                    std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::create_directories(dir);
  AbaqusExport e{(dir / (name + ".inp")).string(), (dir / (name + "_MASS1.mtx")).string(),
                 (dir / (name + "_STIF1.mtx")).string()};
  std::ofstream inp(e.inp);
  inp << "*Heading\n** a flexmbd beam as Abaqus would export it\n*Node\n";
  char line[128];
  const auto& nodes = beam.mesh().nodes;
  for (std::size_t a = 0; a < nodes.size(); ++a) {
    std::snprintf(line, sizeof line, "%zu, %.17g, %.17g, %.17g\n", a + 1, nodes[a].x(), nodes[a].y(), nodes[a].z());
    inp << line;
  }
  inp << "*Element, type=B31, elset=BEAM\n";
  for (std::size_t e2 = 0; e2 < beam.mesh().elements.size(); ++e2) {
    inp << e2 + 1 << ", " << beam.mesh().elements[e2].node1 + 1 << ", " << beam.mesh().elements[e2].node2 + 1 << "\n";
  }
  inp << "*Nset, nset=END0\n1\n*Nset, nset=END1\n" << nodes.size() << "\n";
  const FfrInvariants3d nodal = beam.nodalInvariants();
  writeMatrixInput(nodal.mff, e.mass, both);
  writeMatrixInput(nodal.kff, e.stiffness, both);
  return e;
}

FeBodyData readExport(const AbaqusExport& e) { return readAbaqusFe(e.inp, e.mass, e.stiffness); }

double relDiff(const MatX& a, const MatX& b) { return (a - b).norm() / std::max(b.norm(), 1e-300); }

}  // namespace

TEST(FeBeamsShells, AbaqusMatrixInputRoundTripsTheBeamsMatrices) {
  const FfrBeamModel3d beam = beamModel(8);
  const FfrInvariants3d nodal = beam.nodalInvariants();
  for (bool both : {false, true}) {
    const FeBodyData d = readExport(exportBeam(beam, both ? "beam8_both" : "beam8", both));
    ASSERT_EQ(d.numNodes(), 9);
    ASSERT_EQ(d.numDofs(), 54);
    EXPECT_TRUE(d.hasRotations());
    for (int i = 0; i < d.numDofs(); ++i) {  // node by node, DOF 1..6: the beam's own order
      EXPECT_EQ(d.dofs[i].node, i / 6);
      EXPECT_EQ(d.dofs[i].direction, i % 6);
    }
    EXPECT_LE((MatX(d.mass) - MatX(nodal.mff)).cwiseAbs().maxCoeff(), both ? 0.0 : asymmetry(nodal.mff));
    EXPECT_LE((MatX(d.stiffness) - MatX(nodal.kff)).cwiseAbs().maxCoeff(), both ? 0.0 : asymmetry(nodal.kff));
    EXPECT_EQ(d.elements.size(), 8u);
    EXPECT_EQ(d.elements[0].type, "B31");
    EXPECT_EQ(d.nodeSets.at("END1"), std::vector<int>{8});
  }
}

TEST(FeBeamsShells, FreeFreeFrequenciesOfTheImportedBeam) {
  // 16 Euler-Bernoulli elements: the free-free bending frequencies of a uniform beam are
  // (beta_n L)^2 sqrt(EI / (rho A L^4)), beta_1 L = 4.730040745 (Blevins, table 8-1); cubic
  // elements approximate the first with an error of order (h / L)^4 (about 1e-6 here)
  const FfrBeamModel3d beam = beamModel(16);
  const FeBodyData d = readExport(exportBeam(beam, "beam16"));
  FeBodyOptions o;
  o.modes = 6;
  const FeBodyModel fe(d, o, "imported beam");
  // the six rigid modes (with the rotation DOF turned by e_k) are K's null space
  EXPECT_LT(fe.rigidEigenvalues().cwiseAbs().maxCoeff(), 1e-6 * fe.naturalFrequencies()[0] * fe.naturalFrequencies()[0]);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatX> dense(MatX(d.stiffness), MatX(d.mass));
  for (int i = 0; i < 6; ++i) {
    const double ref = std::sqrt(dense.eigenvalues()[6 + i]);
    EXPECT_NEAR(fe.naturalFrequencies()[i], ref, kEigenTol * ref) << "mode " << i + 1;
  }
  // bending about the section's weak axis (height 0.02 m) comes first
  const double I = kWidth * kHeight * kHeight * kHeight / 12.0, A = kWidth * kHeight;
  const double closed = 4.730040745 * 4.730040745 * std::sqrt(kE * I / (kRho * A * std::pow(kLength, 4)));
  // discretisation error (h/L)^4 ~ 1.5e-5 relative at most, with margin
  EXPECT_NEAR(fe.naturalFrequencies()[0], closed, 1e-4 * closed);
  std::printf("[ figures ] imported 16-element beam: f1 = %.6f Hz (closed form %.6f Hz)\n",
              fe.naturalFrequencies()[0] / (2 * kPi), closed / (2 * kPi));
}

TEST(FeBeamsShells, RigidMotionInvariantsAreExact) {
  const FfrBeamModel3d beam = beamModel(8, BeamTheory::Rayleigh);
  const FfrInvariants3d ref = beam.nodalInvariants();
  FeBodyOptions o;
  o.modes = 4;
  const FeBodyModel fe(readExport(exportBeam(beam, "beam8")), o, "imported beam");
  const FfrInvariants3d& v = fe.nodalInvariants();
  EXPECT_NEAR(v.mass, ref.mass, kExactTol * ref.mass);
  EXPECT_LT((v.firstMoment - ref.firstMoment).norm(), kExactTol * ref.firstMoment.norm());
  EXPECT_LT((v.secondMoment - ref.secondMoment).norm(), kExactTol * ref.secondMoment.norm());
  EXPECT_LT(relDiff(v.sBar, ref.sBar), kExactTol);
  // the rotational part: int rho (u0_k N_l - u0_l N_k) dV, the rows of rho_m^T M
  for (int k = 0; k < 3; ++k) {
    for (int l = k + 1; l < 3; ++l) {
      const MatX a = v.positionShape[k].row(l) - v.positionShape[l].row(k);
      const MatX b = ref.positionShape[k].row(l) - ref.positionShape[l].row(k);
      EXPECT_LT(relDiff(a, b), kExactTol) << "k " << k << " l " << l;
    }
  }
  EXPECT_LE((MatX(v.mff) - MatX(ref.mff)).cwiseAbs().maxCoeff(), asymmetry(ref.mff));  // m_ff = M itself
  EXPECT_NO_THROW(fe.invariants().validate("imported beam"));
}

TEST(FeBeamsShells, LumpedInvariantsConvergeAtSecondOrder) {
  // The symmetric position shape integrals and the S_kl are lumped at the nodes; measured
  // on a mesh-independent basis (the first six free-free modes of each mesh, reduced on
  // both sides), their error against the beam's exact integrals falls by about 4 per
  // halving of the element (second order: the lumped node is a one-point quadrature of a
  // smooth integrand over its half elements). So does the error of what they feed: the
  // spin softening of the first mode, (omega^2 - omega0^2) / w^2 with the frame spinning
  // about its z axis (skew to the beam).
  std::vector<double> errors, softening;
  const double w = 2.0 * kPi * 20.0;
  for (int n : {4, 8, 16}) {
    const FfrBeamModel3d beam = beamModel(n);
    FeBodyOptions o;
    o.modes = 6;
    const FeBodyModel fe(readExport(exportBeam(beam, "conv" + std::to_string(n))), o, "imported beam");
    const SpMat P = fe.basis().sparseView();
    const FfrInvariants3d ref = beam.nodalInvariants().transformed(P);
    const FfrInvariants3d& v = fe.invariants();
    double num = 0.0, den = 0.0;
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) {
        num += (MatX(v.sKL[k][l]) - MatX(ref.sKL[k][l])).squaredNorm();
        den += MatX(ref.sKL[k][l]).squaredNorm();
        const MatX ps = v.positionShape[k].row(l) + v.positionShape[l].row(k);
        const MatX pr = ref.positionShape[k].row(l) + ref.positionShape[l].row(k);
        num += (ps - pr).squaredNorm();
        den += pr.squaredNorm();
      }
    }
    errors.push_back(std::sqrt(num / den));
    FfrInvariants3d exact = ref;  // the beam's, on the same modes, without its section-rotation terms
    exact.rKL = {};
    exact.hI = {};
    exact.points = v.points;
    const double f0 = fetest::spinningFrequencies(v, 0.0)[0];
    const double cFe = fetest::southwellCoefficient(fetest::spinningFrequencies(v, w)[0], f0, w);
    const double cBeam = fetest::southwellCoefficient(fetest::spinningFrequencies(exact, w)[0], f0, w);
    softening.push_back(std::abs(cFe - cBeam) / std::abs(cBeam));
  }
  std::printf("[ figures ] lumped invariants vs the beam's (6 modes): 4 el %.3e, 8 el %.3e, 16 el %.3e (ratios %.2f, "
              "%.2f); spin softening of mode 1: %.3e, %.3e, %.3e\n",
              errors[0], errors[1], errors[2], errors[0] / errors[1], errors[1] / errors[2], softening[0], softening[1],
              softening[2]);
  // second order gives 4 per halving; 3 admits the pre-asymptotic first step
  EXPECT_GT(errors[0] / errors[1], 3.0);
  EXPECT_GT(errors[1] / errors[2], 3.0);
  EXPECT_GT(softening[1] / softening[2], 3.0);
}

TEST(FeBeamsShells, FreeSpinningImportedBeamConservesEnergyAndMomentum) {
  // Energy, linear and angular momentum are constants of the free motion whatever the
  // lumping, if the invariants form one kinetic energy (m_ff exact, S_kl lumped).
  const FfrBeamModel3d beam = beamModel(8);
  FeBodyOptions o;
  o.modes = 4;
  const FeBodyModel fe(readExport(exportBeam(beam, "beam8")), o, "imported beam");
  VecX qf0dot(4);
  for (int k = 0; k < 4; ++k) qf0dot[k] = 0.05 * (k + 1);
  FrameState3d s;
  s.velocity = Vec3(0.3, -0.1, 0.2);
  s.angularVelocity = Vec3(1.0, 6.0, -2.0);  // a tumble, not about a principal axis
  SolverSettings st;
  st.rtol = 1e-9;
  st.atol = 1e-11;
  st.tEnd = 0.2;
  st.outputStep = 0.002;
  const testsupport::FreeBodyDrift d = testsupport::freeBodyDrift(
      std::make_unique<FfrBody3d>("beam", fe.invariants(), s, VecX::Zero(4), qf0dot), st);
  ASSERT_TRUE(d.summary.ok) << d.summary.message;
  // BDF at rtol 1e-9: drift well below 1e-6 (as the rotor's and the beam body's tests)
  EXPECT_LT(d.energy, 1e-6);
  EXPECT_LT(d.momentum, 1e-6);
  EXPECT_LT(d.angularMomentum, 1e-6);
  std::printf("[ figures ] free tumbling imported beam, 0.2 s: energy drift %.2e, |dL| %.2e, |dH| %.2e\n", d.energy,
              d.momentum, d.angularMomentum);
}

TEST(FeBeamsShells, RigidInterfaceAtOneBeamNodeIsTheNode) {
  // A rigid interface over one node with rotations is that node: clamped there
  // (Craig-Bampton reference), the fixed-interface frequencies are the beam's clamped-free
  // ones (the same matrices with the node's six DOF removed, dense).
  const FfrBeamModel3d beam = beamModel(8);
  const FeBodyData d = readExport(exportBeam(beam, "beam8"));
  FeBodyOptions o;
  o.modes = 4;
  o.reduction = FeReduction::CraigBampton;
  o.reference = "root";
  FeInterface root;
  root.name = "root";
  root.kind = FeInterfaceKind::Rigid;
  root.nodes = d.nodeSets.at("END0");
  o.interfaces.push_back(root);
  const FeBodyModel fe(d, o, "imported beam");
  const int n = d.numDofs() - 6;
  const MatX K = MatX(d.stiffness).bottomRightCorner(n, n), M = MatX(d.mass).bottomRightCorner(n, n);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatX> dense(K, M);
  for (int i = 0; i < 4; ++i) {
    const double ref = std::sqrt(dense.eigenvalues()[i]);
    EXPECT_NEAR(fe.naturalFrequencies()[i], ref, kEigenTol * ref) << "mode " << i + 1;
  }
  // an averaging interface still needs three nodes off a line
  o.reduction = FeReduction::FreeFree;
  o.interfaces[0].kind = FeInterfaceKind::Averaging;
  expectMentions(errorOf([&] { FeBodyModel(d, o, "imported beam"); }),
                 {"imported beam", "interface 'root'", "1 nodes", "expected at least 3"});
}

TEST(FeBeamsShells, StrictnessOfSixDofFiles) {
  const FfrBeamModel3d beam = beamModel(2);
  const AbaqusExport e = exportBeam(beam, "strict");
  const fs::path dir = fs::path(e.inp).parent_path();
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string p = (dir / name).string();
    std::ofstream(p) << text;
    return p;
  };
  // a DOF outside 1..6
  const std::string bad = write("bad_dof.mtx", "1, 7, 1, 7, 1.0\n");
  expectMentions(errorOf([&] { readAbaqusFe(e.inp, bad, e.stiffness); }),
                 {bad, "line 1", "the row DOF is 7", "expected 1, 2, 3 (translations) or 4, 5, 6 (rotations)"});
  // a node the deck does not have
  const std::string node = write("bad_node.mtx", "1, 1, 1, 1, 1.0\n9, 1, 9, 1, 1.0\n");
  expectMentions(errorOf([&] { readAbaqusFe(e.inp, node, e.stiffness); }), {node, "line 2", "the row node 9"});
  // the two files in different formats
  const std::string coord = write("coord.mtx", "1 1 1.0\n");
  expectMentions(errorOf([&] { readAbaqusFe(e.inp, coord, e.stiffness); }),
                 {coord, "not in the format of the other matrix file", "expected both matrices in one format"});
  // a node with two rotations only
  const std::string partial = write("partial.mtx", "1, 1, 1, 1, 1.0\n1, 2, 1, 2, 1.0\n1, 3, 1, 3, 1.0\n"
                                                   "1, 4, 1, 4, 1.0\n1, 5, 1, 5, 1.0\n");
  expectMentions(errorOf([&] { readAbaqusFe(e.inp, partial, partial); }),
                 {"node 1 has 3 translations and 2 rotations", "expected x, y, z"});
  // a 5-DOF shell
  const std::string s4r5 = write("s4r5.inp", "*Node\n1, 0., 0., 0.\n*Element, type=S4R5\n1, 1, 1, 1, 1\n");
  expectMentions(errorOf([&] { readAbaqusFe(s4r5, e.mass, e.stiffness); }),
                 {s4r5, "line 3", "'S4R5'", "a shell S3, S3R, S4, S4R, S8R"});
  // a rotation without stiffness: named with its direction
  SpMat K = beam.nodalInvariants().kff;
  for (int j = 0; j < K.outerSize(); ++j)
    for (SpMat::InnerIterator it(K, j); it; ++it)
      if (it.row() == 3 || j == 3) it.valueRef() = 0.0;
  const std::string k0 = (dir / "k0.mtx").string();
  writeMatrixInput(K, k0, false);
  expectMentions(errorOf([&] { readAbaqusFe(e.inp, e.mass, k0); }), {k0, "node 1, direction rotation x"});
}

TEST(FeBeamsShells, ImportedBeamPendulumOnARevoluteJointAtANode) {
  // The imported beam in a scene, hung from the ground by a revolute joint (axis z) at its
  // end node, released 2 degrees from the vertical under gravity: a physical pendulum of a
  // uniform rod, T = 2 pi sqrt(2 L / (3 g)) (1 + theta0^2 / 16) (small-amplitude series),
  // with the steel beam's elastic stretch and sag (g / omega1^2 ~ 1e-5 of L) far below the
  // 1e-4 asserted. The period is read from the frame angle's zero crossings.
  FfrBeamOptions3d bo;
  const FfrBeamModel3d beam(straightBeam(8), bo, "beam");
  const AbaqusExport e = exportBeam(beam, "pendulum");
  const double theta0 = 2.0 * kPi / 180.0, g = 9.81;
  // the beam hangs along -y: its x axis turned by -90 + 2 degrees about z
  const double angle = -0.5 * kPi + theta0;
  const nlohmann::json scene = {
      {"dimension", 3},
      {"gravity", {0, -g, 0}},
      {"solver", {{"t_end", 2.4}, {"rtol", 1e-8}, {"output_step", 1e-3}}},
      {"bodies",
       {{{"name", "beam"},
         {"type", "fe_body"},
         {"abaqus", {{"input", e.inp}, {"mass", e.mass}, {"stiffness", e.stiffness}}},
         {"modes", 4},
         {"orientation", {{"axis", {0, 0, 1}}, {"angle", angle}}}}}},
      {"joints",
       {{{"name", "pivot"},
         {"type", "revolute"},
         {"bodies", {"ground", "beam"}},
         {"world", {{"point", {0, 0, 0}}, {"axis", {0, 0, 1}}}}}}}};
  Scene sc = parseSceneText(scene.dump(), "pendulum.json");
  const int oq = sc.system.coordinateOffset(BodyIndex(1));
  std::vector<double> t, phi;
  const SimulationSummary sum = simulate(sc.system, sc.solver, [&](const OutputSample& o) {
    const Mat3 A = FfrBody3d::rotationOf(o.q.segment(oq, 7));
    t.push_back(o.t);
    phi.push_back(std::atan2(A(1, 0), A(0, 0)) + 0.5 * kPi);  // the beam axis's angle from -y
  });
  ASSERT_TRUE(sum.ok) << sum.message;
  std::vector<double> crossings;  // downward zero crossings, linearly interpolated
  for (std::size_t k = 1; k < phi.size(); ++k) {
    if (phi[k - 1] > 0.0 && phi[k] <= 0.0) crossings.push_back(t[k - 1] + (t[k] - t[k - 1]) * phi[k - 1] / (phi[k - 1] - phi[k]));
  }
  ASSERT_GE(crossings.size(), 2u);
  const double T = crossings[1] - crossings[0];
  const double closed = 2.0 * kPi * std::sqrt(2.0 * kLength / (3.0 * g)) * (1.0 + theta0 * theta0 / 16.0);
  EXPECT_NEAR(T, closed, 1e-4 * closed);
  std::printf("[ figures ] imported beam pendulum: period %.6f s, closed form %.6f s (%.1e)\n", T, closed,
              std::abs(T / closed - 1.0));
}

TEST(FeBeamsShells, ShellsAreDrawnAsTheirFacesAndBeamsAreSkipped) {
  FeBodyData d;
  d.coordinates = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(2, 0, 0), Vec3(2, 1, 0)};
  d.nodeIds = {1, 2, 3, 4, 5, 6};
  d.elements = {{1, "S4R", {0, 1, 2, 3}}, {2, "S3", {1, 4, 5}}, {3, "B31", {0, 1}}};
  const SurfaceMesh m = outerSurface(d);
  ASSERT_EQ(m.faces.size(), 2u);
  EXPECT_EQ(m.faces[0].size() + m.faces[1].size(), 7u);  // a quadrilateral and a triangle
}
