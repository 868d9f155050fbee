// Interface frames of imported FE bodies (bodies/fe_body_model.hpp FeInterface,
// docs/fe-import.md "Interfaces"), on the rotor of ../shared/data/exudyn-rotor (the tests
// skip without it):
//  - both kinds move rigidly with a rigid motion of the nodes (translation and rotation
//    reproduced to round-off);
//  - an averaging (RBE3) interface adds no stiffness: the modes are those without it;
//  - a rigid (RBE2) interface stiffens: every frequency rises (Rayleigh's interlacing of a
//    constrained system), and a static load on it equals the solution of the unreduced
//    stiffness with the rigid-set conditions as Lagrange multipliers (a second,
//    independent way to impose them);
//  - a joint in a scene attaches at an interface's point;
//  - the errors name the interface and what was expected;
//  - inertia modes (FeBodyOptions::inertiaModes): the reduced body's static deformation by
//    its own spin equals the unreduced one, free-free (inertia relief) and Craig-Bampton.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bodies/fe_body_model.hpp"
#include "bodies/modal_reduction.hpp"
#include "core/errors.hpp"
#include "core/rotation_3d.hpp"
#include "simulation/simulation.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "scene/scene.hpp"
#include "fe_test_support.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using json = nlohmann::json;
namespace fs = std::filesystem;
using flexmbd::fetest::expectMentions;

namespace {

const std::string kRotorDir = std::string(FLEXMBD_SOURCE_DIR) + "/../shared/data/exudyn-rotor";

#define SKIP_WITHOUT_ROTOR_DATA() \
  if (!fs::exists(kRotorDir + "/rotorDiscTest.inp")) GTEST_SKIP() << "no rotor data at " << kRotorDir

const FeBodyData& rotor() {
  static const FeBodyData d = readAbaqusFe(kRotorDir + "/rotorDiscTest.inp", kRotorDir + "/rotorDiscTestMASS1.mtx",
                                           kRotorDir + "/rotorDiscTestSTIF1.mtx");
  return d;
}

/// The nodes with coordinate z = `z` (to 1e-6 m: the export's single precision), and with
/// distance from the axis at least `rMin`.
std::vector<int> nodesAt(const FeBodyData& d, double z, double rMin = 0.0) {
  std::vector<int> out;
  for (int a = 0; a < d.numNodes(); ++a) {
    const Vec3& x = d.coordinates[a];
    if (std::abs(x.z() - z) < 1e-6 && std::hypot(x.x(), x.y()) >= rMin) out.push_back(a);
  }
  return out;
}

FeBodyOptions options(std::vector<FeInterface> interfaces = {}) {
  FeBodyOptions o;
  o.modes = 8;
  o.stiffnessScale = 0.01;
  o.interfaces = std::move(interfaces);
  return o;
}

FeInterface averaging(const std::string& name, std::vector<int> nodes) {
  return {name, std::move(nodes), FeInterfaceKind::Averaging};
}
FeInterface rigid(const std::string& name, std::vector<int> nodes) {
  return {name, std::move(nodes), FeInterfaceKind::Rigid};
}

std::string errorOf(const FeBodyOptions& o) {
  return fetest::errorOf([&] { FeBodyModel(rotor(), o, "body 'rotor'"); });
}

}  // namespace

TEST(FeInterfaces, AveragingInterfaceMovesRigidlyWithTheNodes) {
  // Nodal rigid motions q = R c (FeBodyModel::rigidBodyModes): translation j gives the
  // frame u_I = e_j, theta_I = 0; rotation j gives u_I = e_j x X_I, theta_I = e_j. For
  // the rim of the disc (centroid on the axis) and the same set with its point moved off
  // the centroid. 1e-12: round-off of sums over 8 nodes of coordinates ~0.2 m.
  SKIP_WITHOUT_ROTOR_DATA();
  FeInterface offset = averaging("rim_offset", nodesAt(rotor(), 0.150000006, 0.19));
  offset.atCentroid = false;
  offset.point = Vec3(0.05, -0.02, 0.3);
  const FeBodyModel m(rotor(), options({averaging("rim", nodesAt(rotor(), 0.150000006, 0.19)), offset}), "rotor");
  const MatX R = FeBodyModel::rigidBodyModes(rotor());
  for (int k = 0; k < 2; ++k) {
    const FfrPoint3d& p = m.nodalInvariants().points[m.interfacePoint(k)];
    for (int j = 0; j < 3; ++j) {
      EXPECT_LT((p.shape * R.col(j) - Vec3::Unit(j)).norm(), 1e-12);
      EXPECT_LT((p.rotationShape * R.col(j)).norm(), 1e-12);
      EXPECT_LT((p.shape * R.col(3 + j) - Vec3::Unit(j).cross(p.position)).norm(), 1e-12);
      EXPECT_LT((p.rotationShape * R.col(3 + j) - Vec3::Unit(j)).norm(), 1e-12);
    }
  }
  // the rim's centroid is on the axis, at the rim's plane
  EXPECT_LT((m.nodalInvariants().points[m.interfacePoint(0)].position - Vec3(0, 0, 0.150000006)).norm(), 1e-9);
}

TEST(FeInterfaces, AveragingInterfaceAddsNoStiffness) {
  // RBE3 is a measurement of the nodes, not a constraint: the same mass and modes as
  // without it (1e-12: two solves of the same pencil, the same start vector).
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyModel plain(rotor(), options(), "rotor");
  const FeBodyModel with(rotor(), options({averaging("end", nodesAt(rotor(), 0.5))}), "rotor");
  EXPECT_EQ(with.invariants().mass, plain.invariants().mass);
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(with.naturalFrequencies()[i], plain.naturalFrequencies()[i], 1e-12 * plain.naturalFrequencies()[i]);
  }
  EXPECT_EQ(with.invariants().points.size(), plain.invariants().points.size() + 1);
}

TEST(FeInterfaces, RigidInterfaceRaisesEveryFrequency) {
  // A rigid face is a constraint on the free-free body: by Rayleigh's interlacing each
  // frequency is at least the unconstrained one, and the rigid motions still are the six
  // zero eigenvalues (freeFreeModes refuses otherwise). The bound: 1e-9 relative below
  // (solver tolerance), and the face must stiffen something (a mode rises by > 1e-3).
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyModel plain(rotor(), options(), "rotor");
  // the disc's face (17 nodes): made rigid, the disc's own modes stiffen
  const FeBodyModel with(rotor(), options({rigid("disc", nodesAt(rotor(), 0.150000006))}), "rotor");
  double rise = 0.0;
  for (int i = 0; i < 8; ++i) {
    EXPECT_GE(with.naturalFrequencies()[i], plain.naturalFrequencies()[i] * (1.0 - 1e-9)) << "mode " << i;
    rise = std::max(rise, with.naturalFrequencies()[i] / plain.naturalFrequencies()[i] - 1.0);
  }
  EXPECT_GT(rise, 1e-3);
  EXPECT_NEAR(with.invariants().mass, plain.invariants().mass, 1e-13 * plain.invariants().mass);  // no mass added
  std::printf("[ figures ] rigid disc face: largest rise of the first 8 frequencies %.3e\n", rise);
}

TEST(FeInterfaces, StaticLoadOnARigidInterfaceEqualsTheLagrangeMultiplierSolution) {
  // The shaft clamped at z = 0 (its 9 nodes held), a force and moment on a rigid interface
  // over the 9 nodes at z = 0.5. Condensed: (T^T K T) x = f at the frame's DOF. Unreduced:
  // [K C^T; C 0] [u; u_I; theta_I; mu] = [0; F; M; 0] with C u = u_a - u_I - theta_I x r_a
  // for the set's nodes. The frame's displacement and rotation agree to 1e-9 relative
  // (dense LU of two systems of condition ~1e8 at 1e-16).
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyData& d = rotor();
  const std::vector<int> clamped = nodesAt(d, 0.0), face = nodesAt(d, 0.5);
  const FeBodyModel m(d, options({rigid("end", face)}), "rotor");
  const MatX K = MatX(m.nodalInvariants().kff);
  const int master = static_cast<int>(K.rows()) - 6;
  const Vec3 F(1e3, -2e3, 5e2), Mo(30.0, 10.0, -20.0);
  // which condensed DOF are clamped: the columns of T with a single 1 at a clamped node's row
  const SpMat& T = m.nodalMap();
  std::vector<int> keep;
  std::vector<char> isClamped(d.numNodes(), 0);
  for (int a : clamped) isClamped[a] = 1;
  for (int j = 0; j < T.cols(); ++j) {
    const SpMat::InnerIterator it(T, j);
    if (j >= master || !isClamped[d.dofs[it.row()].node]) keep.push_back(j);
  }
  const int nk = static_cast<int>(keep.size());
  MatX Kc(nk, nk);
  VecX fc = VecX::Zero(nk);
  for (int i = 0; i < nk; ++i) {
    for (int j = 0; j < nk; ++j) Kc(i, j) = K(keep[i], keep[j]);
    if (keep[i] >= master) fc[i] = keep[i] - master < 3 ? F[keep[i] - master] : Mo[keep[i] - master - 3];
  }
  const VecX xc = Kc.partialPivLu().solve(fc);
  const VecX frameCondensed = xc.tail(6);

  // unreduced: all 3 N DOF less the clamped ones, the frame's 6, the multipliers
  const SpMat Kfull = 0.01 * d.stiffness;
  const std::vector<int> dof = d.dofIndex();
  std::vector<int> freeDof;
  for (int i = 0; i < d.numDofs(); ++i) {
    if (!isClamped[d.dofs[i].node]) freeDof.push_back(i);
  }
  std::vector<int> col(d.numDofs(), -1);
  for (std::size_t i = 0; i < freeDof.size(); ++i) col[freeDof[i]] = static_cast<int>(i);
  const int nu = static_cast<int>(freeDof.size()), nc = 3 * static_cast<int>(face.size());
  const int n = nu + 6 + nc;
  MatX A = MatX::Zero(n, n);
  VecX b = VecX::Zero(n);
  const MatX Kd = MatX(Kfull);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nu; ++j) A(i, j) = Kd(freeDof[i], freeDof[j]);
  }
  b.segment<3>(nu) = F;
  b.segment<3>(nu + 3) = Mo;
  Vec3 XI = Vec3::Zero();
  for (int a : face) XI += d.coordinates[a] / static_cast<double>(face.size());
  int row = nu + 6;
  for (int a : face) {
    const Mat3 rt = skew(d.coordinates[a] - XI);  // theta x r = -r~ theta
    for (int c = 0; c < 3; ++c, ++row) {
      // u_a,c - u_I,c + (r~ theta)_c = 0
      A(row, col[dof[3 * a + c]]) = 1.0;
      A(row, nu + c) = -1.0;
      for (int j = 0; j < 3; ++j) A(row, nu + 3 + j) = rt(c, j);
    }
  }
  A.bottomLeftCorner(nc, nu + 6).eval();
  A.topRightCorner(nu + 6, nc) = A.bottomLeftCorner(nc, nu + 6).transpose();
  const VecX x = A.partialPivLu().solve(b);
  const VecX frameKkt = x.segment(nu, 6);
  EXPECT_LT((frameCondensed - frameKkt).norm(), 1e-9 * frameKkt.norm())
      << "condensed " << frameCondensed.transpose() << "\nmultipliers " << frameKkt.transpose();
  std::printf("[ figures ] rigid interface static load: |condensed - multipliers| / |x| = %.2e\n",
              (frameCondensed - frameKkt).norm() / frameKkt.norm());
}

namespace {

/// The shaft of the rotor on a rigid interface at z = 0 (the Craig-Bampton reference) and
/// one at z = 0.5: 6 constraint modes and 8 fixed-interface modes.
FeBodyOptions craigBamptonShaft(const FeBodyData& d) {
  FeBodyOptions o = options({rigid("bottom", nodesAt(d, 0.0)), rigid("top", nodesAt(d, 0.5))});
  o.reduction = FeReduction::CraigBampton;
  o.reference = "bottom";
  return o;
}

/// The unreduced static solution K x = f with the six DOF from `held` held (x = 0 there).
VecX heldStaticSolution(const MatX& K, const VecX& f, int held) {
  const int n = static_cast<int>(K.rows());
  std::vector<int> free;
  for (int i = 0; i < n; ++i) {
    if (i < held || i >= held + 6) free.push_back(i);
  }
  MatX Kf(free.size(), free.size());
  VecX ff(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) {
    ff[i] = f[free[i]];
    for (std::size_t j = 0; j < free.size(); ++j) Kf(i, j) = K(free[i], free[j]);
  }
  const VecX uf = Kf.ldlt().solve(ff);
  VecX x = VecX::Zero(n);
  for (std::size_t i = 0; i < free.size(); ++i) x[free[i]] = uf[i];
  return x;
}

}  // namespace

TEST(FeInterfaces, CraigBamptonIsExactForStaticLoadsAtItsInterfaces) {
  // The shaft on a rigid interface at z = 0 (the reference, held) with a rigid one at
  // z = 0.5 (6 constraint modes) and 8 fixed-interface modes: a static force and moment at
  // the free interface give, in the reduced coordinates, the unreduced solution with the
  // z = 0 interface held (constraint modes are the static responses: exact to the
  // solver's round-off, 1e-9). Its lowest frequencies bound the unreduced ones from above
  // (Rayleigh-Ritz) and approach them (the first: 1.4e-3 above with 8 fixed-interface modes,
  // held to 2e-3 so that a worse basis fails).
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyData& d = rotor();
  const FeBodyModel cb(d, craigBamptonShaft(d), "rotor");
  ASSERT_EQ(cb.invariants().numElastic(), 6 + 8);
  const MatX K = MatX(cb.nodalInvariants().kff), M = MatX(cb.nodalInvariants().mff);
  const int n = static_cast<int>(K.rows());
  // columns: ..., bottom's 6, top's 6 (the order of the interfaces)
  const int bottom = n - 12, top = n - 6;
  VecX f = VecX::Zero(n);
  f.segment<6>(top) << 1e3, -2e3, 5e2, 30.0, 10.0, -20.0;
  const VecX full = heldStaticSolution(K, f, bottom);
  const MatX& B = cb.basis();
  const MatX Kr = B.transpose() * K * B;
  const VecX x = Kr.ldlt().solve(B.transpose() * f);
  const VecX reduced = B * x;
  EXPECT_LT((reduced.segment<6>(top) - full.segment<6>(top)).norm(), 1e-9 * full.segment<6>(top).norm());
  EXPECT_LT((reduced - full).norm(), 1e-9 * full.norm());
  // frequencies: reduced pencil against the unreduced clamped-free ones
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> red(Kr, MatX(B.transpose() * M * B));
  VecX exact;
  std::vector<int> held;
  for (int c = 0; c < 6; ++c) held.push_back(bottom + c);
  clampedModes(cb.nodalInvariants().kff, cb.nodalInvariants().mff, held, 4, "rotor", &exact);
  for (int i = 0; i < 4; ++i) {
    const double w = std::sqrt(red.eigenvalues()[i]);
    EXPECT_GE(w, exact[i] * (1.0 - 1e-9)) << "mode " << i;
  }
  EXPECT_NEAR(std::sqrt(red.eigenvalues()[0]) / exact[0], 1.0, 2e-3);
  std::printf("[ figures ] Craig-Bampton shaft (6 + 8): static error %.1e, first frequency %.3f Hz vs %.3f Hz "
              "(rel. %.1e)\n",
              (reduced - full).norm() / full.norm(), std::sqrt(red.eigenvalues()[0]) / (2 * M_PI), exact[0] / (2 * M_PI),
              std::sqrt(red.eigenvalues()[0]) / exact[0] - 1.0);
}

TEST(FeInterfaces, JointAttachesAtAnInterfacePointInAScene) {
  // The rotor hung from the ground by a spherical joint at a rigid interface over its end
  // face (point given: the face's centre on the axis) and by an averaging one over the
  // other end: the scene builds, and a short swing under gravity keeps the joint's point
  // on the ground point (the constraint, to the solver's tolerance 1e-6 of 0.5 m).
  SKIP_WITHOUT_ROTOR_DATA();
  const json files = {
      {"input", "rotorDiscTest.inp"}, {"mass", "rotorDiscTestMASS1.mtx"}, {"stiffness", "rotorDiscTestSTIF1.mtx"}};
  const json top = {{"name", "top"},
                    {"kind", "rigid"},
                    {"nodes", {33, 34, 35, 36, 41, 42, 43, 44, 77}},
                    {"point", {0.0, 0.0, 0.5}}};
  const json bottom = {{"name", "bottom"}, {"kind", "averaging"}, {"node_set", "BCleft"}};
  json body = {{"type", "fe_body"}, {"name", "rotor"}, {"abaqus", files}, {"modes", 4}, {"stiffness_scale", 0.01}};
  body["interfaces"] = json::array({top, bottom});
  const json hinge = {{"type", "spherical"},
                      {"name", "hinge"},
                      {"bodies", {"ground", "rotor"}},
                      {"world", {{"point", {0.0, 0.0, 0.5}}}}};
  json scene = {{"dimension", 3}, {"gravity", {0.0, -9.81, 0.0}}};
  scene["bodies"] = json::array({body});
  scene["joints"] = json::array({hinge});
  scene["solver"] = {{"t_end", 0.05}, {"output_step", 0.01}};
  const auto sceneError = [&] { return fetest::errorOf([&] { parseSceneText(scene.dump(), kRotorDir + "/scene.json"); }); };
  std::string msg = sceneError();
  // "BCleft" is one node: an averaging interface needs three
  expectMentions(msg, {"interface 'bottom'", "at least 3"});
  scene["bodies"][0]["interfaces"][1]["node_set"] = "Set-1";  // every node: the body's mean motion
  const Scene s = parseSceneText(scene.dump(), kRotorDir + "/scene.json");
  SolverSettings st = s.solver;
  st.progress = false;
  const SimulationSummary r = simulate(s.system, st, [](const OutputSample&) {});
  ASSERT_TRUE(r.ok) << r.message;
  // the same hung from its Craig-Bampton reference: the frame follows "top", 4 fixed-interface modes
  scene["bodies"][0]["reduction"] = "craig_bampton";
  scene["bodies"][0]["reference"] = "top";
  const Scene cb = parseSceneText(scene.dump(), kRotorDir + "/scene.json");
  EXPECT_EQ(cb.system.body(BodyIndex(1)).numVelocities(), 6 + 4);
  const SimulationSummary rc = simulate(cb.system, st, [](const OutputSample&) {});
  ASSERT_TRUE(rc.ok) << rc.message;
  scene["bodies"][0]["reference"] = "bottom";
  expectMentions(sceneError(), {"'bottom' is an averaging interface", "rigid interfaces: 'top'"});
  scene["bodies"][0].erase("reference");
  expectMentions(sceneError(), {"\"reference\"", "craig_bampton"});
}

TEST(FeInterfaces, ErrorsNameTheInterface) {
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyData& d = rotor();
  // the axis nodes 78, 111, 77 lie on one line
  expectMentions(errorOf(options({averaging("axis", {d.nodeIndex(78), d.nodeIndex(111), d.nodeIndex(77)})})),
                 {"body 'rotor'", "interface 'axis'", "one line"});
  expectMentions(errorOf(options({rigid("two", {0, 1})})), {"interface 'two'", "at least 3"});
  const std::vector<int> face = nodesAt(d, 0.5);
  expectMentions(errorOf(options({rigid("a", face), rigid("b", face)})), {"rigid interfaces 'a' and 'b'"});
  expectMentions(errorOf(options({averaging("dup", {face[0], face[1], face[0]})})), {"interface 'dup'", "twice"});
}

// ----- inertia modes ----------------------------------------------------------------

namespace {

/// The inertia load of a steady spin w about the body's z axis: -int rho N^T (w x (w x u0))
/// dV = -sum_kl W_lk int rho N_l^T u0_k dV with W = w~ w~ (FfrInvariants3d::inertiaLoads).
VecX spinLoad(const FfrInvariants3d& inv, double w) {
  const Mat3 W = skew(Vec3(0.0, 0.0, w)) * skew(Vec3(0.0, 0.0, w));
  const MatX F = inv.inertiaLoads();
  VecX f = VecX::Zero(F.rows());
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) f -= W(l, k) * F.col(3 + 3 * k + l);
  return f;
}

/// The Galerkin static solution B (B^T K B)^-1 B^T f in the nodal DOF.
VecX reducedStatic(const MatX& B, const SpMat& K, const VecX& f) {
  const MatX Kr = B.transpose() * K * B;
  return B * Kr.ldlt().solve(B.transpose() * f);
}

}  // namespace

TEST(FeInertiaModes, FreeFreeRotorHoldsItsSpinStretchExactly) {
  // Free-free (mean axes): the unreduced static response to the spin load with inertia
  // relief (freeStaticResponses) against the reduced body's. With the inertia modes the
  // response lies in the basis, so the Galerkin solution is it, to the solvers' round-off
  // (K's condition ~1e8 times 1e-16: 1e-8 relative); with the 8 free-free modes alone the
  // truncation leaves a larger error (measured and printed; asserted above 1e-4 so the
  // test tells the two bases apart).
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyData& d = rotor();
  FeBodyOptions o = options();
  const FeBodyModel plain(d, o, "rotor");
  o.inertiaModes = true;
  const FeBodyModel with(d, o, "rotor");
  const FfrInvariants3d& nodal = with.nodalInvariants();
  const VecX f = spinLoad(nodal, 2.0 * M_PI * 50.0);
  const MatX R = FeBodyModel::rigidBodyModes(d);
  const VecX exact = freeStaticResponses(nodal.kff, nodal.mff, R, f, "rotor");
  // the unreduced response itself: K y = f - M R a with R^T M R a = R^T f (the load less
  // what accelerates the body rigidly, Newton-Euler), and R^T M y = 0 (mean axes)
  const MatX MR = nodal.mff * R;
  const VecX relieved = f - MR * (R.transpose() * MR).ldlt().solve(R.transpose() * f);
  EXPECT_LT((nodal.kff * exact - relieved).norm(), 1e-9 * relieved.norm());
  EXPECT_LT((MR.transpose() * exact).norm(), 1e-9 * MR.norm() * exact.norm());
  const double errWith = (reducedStatic(with.basis(), nodal.kff, f) - exact).norm() / exact.norm();
  const double errPlain = (reducedStatic(plain.basis(), nodal.kff, f) - exact).norm() / exact.norm();
  EXPECT_GT(with.basis().cols(), plain.basis().cols());
  EXPECT_LT(errWith, 1e-8);
  EXPECT_GT(errPlain, 1e-4);
  // still mean axes: S-bar = 0 (the basis M-orthogonal to the rigid translations), and the
  // first 8 coordinates are the free-free modes (frequencies unchanged)
  EXPECT_LT(with.invariants().sBar.cwiseAbs().maxCoeff(), 1e-10 * std::sqrt(nodal.mass));
  EXPECT_EQ(with.naturalFrequencies(), plain.naturalFrequencies());
  std::printf("[ figures ] free-free rotor spin stretch: 8 modes error %.2e, + %d inertia modes %.2e\n", errPlain,
              static_cast<int>(with.basis().cols() - plain.basis().cols()), errWith);
}

TEST(FeInertiaModes, CraigBamptonShaftHoldsItsSpinStretchExactly) {
  // The shaft held at its z = 0 interface (the reference), a rigid interface at z = 0.5:
  // the unreduced static response with the reference held against the reduced body's,
  // as above.
  SKIP_WITHOUT_ROTOR_DATA();
  const FeBodyData& d = rotor();
  FeBodyOptions o = craigBamptonShaft(d);
  const FeBodyModel plain(d, o, "rotor");
  o.inertiaModes = true;
  o.dampingRatio = 0.01;
  const FeBodyModel with(d, o, "rotor");
  const FfrInvariants3d& nodal = with.nodalInvariants();
  const int n = static_cast<int>(nodal.kff.rows()), bottom = n - 12;
  const VecX f = spinLoad(nodal, 2.0 * M_PI * 50.0);
  const VecX exact = heldStaticSolution(MatX(nodal.kff), f, bottom);
  const double errWith = (reducedStatic(with.basis(), nodal.kff, f) - exact).norm() / exact.norm();
  const double errPlain = (reducedStatic(plain.basis(), nodal.kff, f) - exact).norm() / exact.norm();
  EXPECT_LT(errWith, 1e-8);
  EXPECT_GT(errPlain, 1e-4);
  // modal damping on the fixed-interface modes only: none on the 6 constraint modes or
  // on the inertia modes after them
  const MatX D(with.invariants().dff);
  const int nm = static_cast<int>(with.naturalFrequencies().size());
  EXPECT_EQ(D.topLeftCorner(6, 6).norm(), 0.0);
  EXPECT_NEAR(D(6, 6), 2.0 * 0.01 * with.naturalFrequencies()[0], 1e-12 * D(6, 6));
  EXPECT_EQ(D.bottomRightCorner(D.rows() - 6 - nm, D.cols() - 6 - nm).norm(), 0.0);
  std::printf("[ figures ] Craig-Bampton shaft spin stretch: 6 + 8 modes error %.2e, + %d inertia modes %.2e\n",
              errPlain, static_cast<int>(with.basis().cols() - plain.basis().cols()), errWith);
}
