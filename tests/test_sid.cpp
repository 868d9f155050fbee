// The Standard Input Data (SID, Wallrapp 1994) of flexible bodies: bodies/sid_data.hpp and
// fe_import/sid_file.hpp (docs/fe-import.md, "SID").
//  - a beam model's SID, written and read back, gives its invariants to round-off (modal
//    with the section-rotation terms R_kl and H_i, and nodal);
//  - the blocks mean what the SID defines: J is the inertia tensor of a uniform beam about
//    its end (closed form), mdCM m times its centre of mass, and Oe(q) w-bar is minus the
//    body's own centrifugal force on the elastic coordinates (FfrBody3d, to round-off);
//  - the same free flight from the body and from its SID;
//  - the reader's strictness, each error naming the file, the line or block and what was
//    expected.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <memory>
#include <sstream>
#include <string>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/sid_data.hpp"
#include "core/system.hpp"
#include "fe_test_support.hpp"
#include "simulation/simulation.hpp"
#include "scene/scene.hpp"
#include "fe_import/sid_file.hpp"
#include <nlohmann/json.hpp>

using namespace flexmbd;
using flexmbd::fetest::errorOf;
using flexmbd::fetest::expectMentions;

namespace {

// Round trip: the file holds every number to 17 significant digits (exact), and the
// reader recombines the blocks (S_kl = -Gr1 / 2 + m_ff, P_j = (D_j - skew(x0_j)) / 2,
// J = tr(I) / 2 - I, ...) with a few roundings each: 1e-14 of each invariant's largest
// entry is some 50 units of round-off.
constexpr double kRoundTrip = 1e-14;
// Closed forms of sums over 8 elements: round-off of O(10) terms, 1e-12 relative.
constexpr double kClosedForm = 1e-12;

/// A uniform steel cantilever along x (L = 1 m, 8 elements), clamped to its frame at
/// x = 0; `modes` > 0: reduced to them (R_kl carried through), Timoshenko: H_i as well.
std::shared_ptr<const FfrBeamModel3d> beam(int modes, BeamTheory theory) {
  BeamSection3d s;
  s.area = 1e-3;
  s.inertiaY = 2e-8;
  s.inertiaZ = 8e-8;
  s.torsionConstant = 4e-8;
  s.youngsModulus = 2.1e11;
  s.shearModulus = 8.1e10;
  s.shearFactorY = s.shearFactorZ = 5.0 / 6.0;  // Timoshenko's, rectangle
  s.density = 7800.0;
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  o.modes = modes;
  o.theory = theory;
  return std::make_shared<const FfrBeamModel3d>(BeamMesh3d::straight(1.0, 8, s), o, "body 'beam'");
}

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "/" + name; }

FfrInvariants3d roundTrip(const FfrInvariants3d& inv, const std::string& file) {
  writeSidFile(sidFromInvariants(inv), tempPath(file));
  return invariantsFromSid(readSidFile(tempPath(file)), "body 'copy'");
}

double largest(const MatX& A) { return A.size() ? A.cwiseAbs().maxCoeff() : 0.0; }

/// |a - b| <= kRoundTrip max |a|; an absent matrix (0 x 0) equals one of zeros (the
/// invariants may hold an optional term as an n x n matrix without entries, the SID then
/// has nothing of it).
/// `scale`: the size of the family the matrix belongs to (an S_kl that is round-off of
/// zero for a straight beam is read back to the round-off of the larger S_kk, m_ff).
void expectSame(const MatX& a, const MatX& b, const std::string& what, double scale = 0.0) {
  const auto zero = [](const MatX& m) { return m.size() == 0 || m.cwiseAbs().maxCoeff() == 0.0; };
  if (zero(a) && zero(b)) return;
  ASSERT_EQ(a.rows(), b.rows()) << what;
  ASSERT_EQ(a.cols(), b.cols()) << what;
  EXPECT_LE(largest(a - b), kRoundTrip * std::max(largest(a), scale) + 1e-300) << what;
}

void expectSameInvariants(const FfrInvariants3d& a, const FfrInvariants3d& b) {
  EXPECT_NEAR(a.mass, b.mass, kRoundTrip * a.mass);
  expectSame(a.firstMoment, b.firstMoment, "first moment");
  expectSame(a.secondMoment, b.secondMoment, "second moment");
  expectSame(a.sBar, b.sBar, "S-bar");
  expectSame(MatX(a.mff), MatX(b.mff), "m_ff");
  expectSame(MatX(a.kff), MatX(b.kff), "K_ff");
  expectSame(MatX(a.dff), MatX(b.dff), "D_ff");
  const double sM = largest(MatX(a.mff));  // S_kl, R_kl, H_i: m_ff = S_xx + S_yy + S_zz bounds them
  double sP = 0.0;                         // the position shapes
  for (int k = 0; k < 3; ++k) sP = std::max(sP, largest(a.positionShape[k]));
  for (int k = 0; k < 3; ++k) {
    expectSame(a.positionShape[k], b.positionShape[k], "position shape " + std::to_string(k), sP);
    expectSame(MatX(a.hI[k]), MatX(b.hI[k]), "H_" + std::to_string(k), sM);
    for (int l = 0; l < 3; ++l) {
      expectSame(MatX(a.sKL[k][l]), MatX(b.sKL[k][l]), "S_" + std::to_string(k) + std::to_string(l), sM);
      expectSame(MatX(a.rKL[k][l]), MatX(b.rKL[k][l]), "R_" + std::to_string(k) + std::to_string(l), sM);
    }
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    expectSame(a.points[i].position, b.points[i].position, "node position");
    expectSame(a.points[i].shape, b.points[i].shape, "node shape");
    expectSame(a.points[i].rotationShape, b.points[i].rotationShape, "node rotation shape");
  }
}

bool hasEntries(const SpMat& A) { return A.nonZeros() > 0; }

}  // namespace

TEST(SidRoundTrip, ModalTimoshenkoBeamGivesItsInvariants) {
  const auto model = beam(6, BeamTheory::Timoshenko);
  const FfrInvariants3d& inv = model->invariants();
  ASSERT_TRUE(hasEntries(inv.rKL[1][1]) && hasEntries(inv.hI[0])) << "the test needs the section-rotation terms";
  const FfrInvariants3d back = roundTrip(inv, "modal.SID_FEM");
  expectSameInvariants(inv, back);
  EXPECT_TRUE(hasEntries(back.rKL[1][1]) && hasEntries(back.hI[0]));
}

TEST(SidRoundTrip, SpinStiffnessComesBack) {
  FfrInvariants3d inv = beam(4, BeamTheory::EulerBernoulli)->invariants();
  for (int k = 0; k < 3; ++k)
    for (int l = k; l < 3; ++l) inv.spinStiffness[k][l] = inv.spinStiffness[l][k] = (1.0 + k - l) * 1e-2 * inv.kff;
  const FfrInvariants3d back = roundTrip(inv, "spin.SID_FEM");
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      // through Oe's sum with the inertia terms: round-off of those (larger) entries
      const MatX a(inv.spinStiffness[k][l]), b(back.spinStiffness[k][l]);
      ASSERT_EQ(b.rows(), a.rows());
      EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-12 * MatX(inv.kff).cwiseAbs().maxCoeff());
    }
}

TEST(SidRoundTrip, NodalBeamGivesItsInvariantsAndKeepsTheirSparsity) {
  const auto model = beam(0, BeamTheory::EulerBernoulli);
  const FfrInvariants3d& inv = model->invariants();
  ASSERT_EQ(inv.numElastic(), 48);
  const FfrInvariants3d back = roundTrip(inv, "nodal.SID_FEM");
  expectSameInvariants(inv, back);
  // A nodal body's cost is linear in its size because m_ff and the S_kl are banded: the
  // read ones have no entry outside the stored pattern (explicit zeros there are dropped).
  const auto insidePattern = [](const SpMat& read, const SpMat& stored) {
    for (int j = 0; j < read.outerSize(); ++j)
      for (SpMat::InnerIterator it(read, j); it; ++it) {
        bool found = false;
        for (SpMat::InnerIterator jt(stored, j); jt; ++jt) found = found || jt.row() == it.row();
        if (!found) return false;
      }
    return true;
  };
  EXPECT_TRUE(insidePattern(back.mff, inv.mff));
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) EXPECT_TRUE(insidePattern(back.sKL[k][l], SpMat(inv.sKL[k][l] + inv.mff)));
}

TEST(SidConventions, InertiaAndCentreOfMassOfAUniformBeamAboutItsEnd) {
  const auto model = beam(4, BeamTheory::EulerBernoulli);
  const SidData sid = sidFromInvariants(model->invariants());
  const double rhoA = 7800.0 * 1e-3, m = rhoA * 1.0;
  EXPECT_NEAR(sid.mass, m, kClosedForm * m);
  EXPECT_NEAR(sid.mdCM.m0(0, 0), m * 0.5, kClosedForm * m);  // m times the centre of mass
  EXPECT_NEAR(sid.mdCM.m0(1, 0), 0.0, kClosedForm * m);
  // int rho u~^T u~ dV about x = 0: I_xx = rho (I_y + I_z) L, I_yy = m L^2 / 3 + rho I_y L
  const double rho = 7800.0;
  EXPECT_NEAR(sid.J.m0(0, 0), rho * (2e-8 + 8e-8), kClosedForm * m);
  EXPECT_NEAR(sid.J.m0(1, 1), m / 3.0 + rho * 2e-8, kClosedForm * m);
  EXPECT_NEAR(sid.J.m0(2, 2), m / 3.0 + rho * 8e-8, kClosedForm * m);
  EXPECT_NEAR(sid.J.m0(0, 1), 0.0, kClosedForm * m);
}

TEST(SidConventions, OeIsMinusTheBodysCentrifugalForce) {
  // With R' = 0 and q_f' = 0 the velocity-dependent forces on q_f are the centrifugal
  // forces 1/2 w^T dI/dq_f w (Lagrange) and the spin stiffening -sum w_k w_l G_kl q_f;
  // the SID puts them on the left: Oe(q) w-bar.
  // With a spin stiffness G_kl (here made up, symmetric) Oe's first-order term holds it too.
  const auto model = beam(6, BeamTheory::Timoshenko);
  FfrInvariants3d inv = model->invariants();
  for (int k = 0; k < 3; ++k)
    for (int l = k; l < 3; ++l) inv.spinStiffness[k][l] = inv.spinStiffness[l][k] = (1.0 + k + 3 * l) * 1e-2 * inv.kff;
  const FfrBody3d body("beam", inv, FrameState3d{});
  const SidData sid = sidFromInvariants(inv);
  const int nf = body.numElastic();
  VecX q = body.initialCoordinates(), v = VecX::Zero(6 + nf);
  for (int k = 0; k < nf; ++k) q[7 + k] = 0.01 * std::sin(1.0 + k);  // deformed: Oe's first order
  const Vec3 w(1.3, -0.7, 2.1);
  v.segment<3>(3) = w;
  VecX Qw = VecX::Zero(6 + nf), Q0 = VecX::Zero(6 + nf);
  body.addInternalForces(q, v, Qw);
  body.addInternalForces(q, VecX::Zero(6 + nf), Q0);
  Eigen::Matrix<double, 6, 1> wbar;
  wbar << w.x() * w.x(), w.y() * w.y(), w.z() * w.z(), w.x() * w.y(), w.y() * w.z(), w.x() * w.z();
  MatX Oe = sid.Oe.m0;
  for (int k = 0; k < nf; ++k) Oe += sid.Oe.m1[k] * q[7 + k];
  const VecX centrifugal = (Qw - Q0).tail(nf);
  EXPECT_LE((Oe * wbar + centrifugal).cwiseAbs().maxCoeff(), 1e-10 * centrifugal.cwiseAbs().maxCoeff());
}

TEST(SidRoundTrip, FreeFlightFromTheSidEqualsTheBodys) {
  // The same motion from the beam model and from its SID: a spinning, vibrating free body.
  const auto model = beam(6, BeamTheory::Timoshenko);
  const FfrInvariants3d back = roundTrip(model->invariants(), "flight.SID_FEM");
  FrameState3d s;
  s.velocity = Vec3(0.3, -0.1, 0.2);
  s.angularVelocity = Vec3(0.5, 2.0, -1.0);
  VecX qf0dot = VecX::Zero(6);
  for (int k = 0; k < 6; ++k) qf0dot[k] = 0.05 * std::cos(2.0 + k);
  const auto run = [&](std::unique_ptr<FfrBody3d> b) {
    System sys;
    sys.addBody(std::move(b));
    sys.finalize();
    SolverSettings st;
    st.rtol = 1e-8;
    st.atol = 1e-10;
    st.tEnd = 0.2;
    st.outputStep = 0.01;
    st.progress = false;
    std::vector<VecX> qs;
    const SimulationSummary sum = simulate(sys, st, [&](const OutputSample& o) { qs.push_back(o.q); });
    EXPECT_TRUE(sum.ok) << sum.message;
    return qs;
  };
  // Both bodies from invariants (the original's and the SID's), so the two systems differ
  // only by the invariants' round-off (1e-16). Not bit for bit: the error control's step
  // decisions flip on round-off, so the two runs are two solutions within the tolerance:
  // each carries a global error of a few rtol |q| (rtol 1e-8 of coordinates of ~0.1, over
  // 20 outputs), so they may differ by twice that: bound 5e-8 (measured 2e-9, and 1.4e-8
  // once the modes' sign convention changed the run's round-off).
  const auto a = run(std::make_unique<FfrBody3d>("beam", model->invariants(), s, VecX(), qf0dot));
  const auto b = run(std::make_unique<FfrBody3d>("copy", back, s, VecX(), qf0dot));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 10u);
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 5e-8);
  std::printf("[ figures ] free flight, invariants vs their SID: largest coordinate difference %.1e\n", worst);
}

namespace {

using json = nlohmann::json;

/// examples/spatial_slider_crank_elastic.json over 0.05 s, the rod without geometric
/// stiffening (a SID holds the linear stiffness) and without outputs (its "deflection"
/// needs a beam mesh).
json linearSliderCrank() {
  std::ifstream in(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json");
  json j = json::parse(in);
  j.erase("outputs");
  j["solver"]["t_end"] = 0.05;
  for (json& b : j["bodies"]) {
    if (b["name"] == "rod") b["geometric_stiffening"] = false;
  }
  return j;
}

std::vector<VecX> positions(Scene& scene) {
  std::vector<VecX> qs;
  scene.solver.progress = false;
  const SimulationSummary sum = simulate(scene.system, scene.solver, [&](const OutputSample& o) { qs.push_back(o.q); });
  EXPECT_TRUE(sum.ok) << sum.message;
  return qs;
}

std::string shellQuote(const std::string& s) { return "'" + s + "'"; }

}  // namespace

TEST(SidScene, TheSliderCranksRodFromItsSidRunsTheSame) {
  // flexmbd sid writes the rod's SID; a scene whose rod is that "sid_body" (the file
  // relative to the scene's folder) runs as the beam-mesh scene: same joints at the
  // same nodes, invariants equal to round-off (SidRoundTrip), so the same steps and
  // states to round-off amplified over the run.
  const std::string dir = tempPath("sid_scene");
  std::filesystem::create_directories(dir);
  json j = linearSliderCrank();
  std::ofstream(dir + "/beam.json") << j.dump(1);
  const std::string cmd = std::string(FLEXMBD_CLI) + " sid " + shellQuote(dir + "/beam.json") +
                          " --body rod --out " + shellQuote(dir + "/rod.SID_FEM") + " > " + shellQuote(dir + "/out.txt");
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  for (json& b : j["bodies"]) {
    if (b["name"] != "rod") continue;
    b = {{"name", "rod"}, {"type", "sid_body"}, {"file", "rod.SID_FEM"}, {"position", b["position"]},
         {"orientation", b["orientation"]}};
  }
  Scene beamScene = loadScene(dir + "/beam.json");
  Scene sidScene = parseSceneText(j.dump(), dir + "/sid.json");
  const auto a = positions(beamScene), b = positions(sidScene);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 20u);
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - b[i]).cwiseAbs().maxCoeff());
  // The beam scene's rod computes its elastic force and Jacobian through the beam model
  // (its strain energy's Hessian, another sparsity pattern), the SID's from K_ff: equal to
  // round-off, but the Newton iterates then differ within IDA's nonlinear tolerance (a
  // fraction of rtol |y| = 1e-6 x 0.1 m per step). Bound: 1e-7 m; measured 6e-9.
  EXPECT_LT(worst, 1e-7);
  std::printf("[ figures ] slider crank, beam rod vs its SID: largest coordinate difference %.1e over %zu outputs\n",
              worst, a.size());
}

TEST(SidScene, CommandErrorsNameTheBody) {
  const std::string dir = tempPath("sid_cli");
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/beam.json") << linearSliderCrank().dump(1);
  const auto run = [&](const std::string& args) {
    const std::string cmd = std::string(FLEXMBD_CLI) + " sid " + shellQuote(dir + "/beam.json") + " " + args + " 2> " +
                            shellQuote(dir + "/err.txt");
    const int rc = std::system(cmd.c_str());
    std::ifstream in(dir + "/err.txt");
    const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return std::make_pair(WEXITSTATUS(rc), err);
  };
  auto [rc1, e1] = run("--body crank --out " + shellQuote(dir + "/x.SID_FEM"));
  EXPECT_EQ(rc1, 2);
  expectMentions(e1, {"body 'crank' is not a spatial flexible body"});
  auto [rc2, e2] = run("--body wheel --out " + shellQuote(dir + "/x.SID_FEM"));
  EXPECT_EQ(rc2, 2);
  expectMentions(e2, {"unknown body 'wheel'", "crank, rod, slider"});
  auto [rc3, e3] = run("--out " + shellQuote(dir + "/x.SID_FEM"));
  EXPECT_EQ(rc3, 2);
  expectMentions(e3, {"sid needs the option --body"});
}

TEST(SidRoundTrip, BeamStiffeningIsWrittenAsItsLinearSpinStiffness) {
  // A nodal cantilever with geometric stiffening (8 elements, root on the spin axis z):
  // its SID holds the spin stiffness linearised about the undeformed beam
  // (linearSpinStiffness), and the body read back stiffens as the uniform cantilever does,
  // Southwell coefficients 1.1933 out of the plane of rotation and 0.1933 in it (the
  // softening from the S_kl), to 5e-3 (8 Euler-Bernoulli elements: the first mode's
  // discretisation error is ~1e-4 of omega^2, the geometric stiffness's a little more).
  BeamSection3d s;
  s.area = 1e-3;
  s.inertiaY = s.inertiaZ = 2e-8;  // equal: the pair splits only by the spin
  s.torsionConstant = 4e-8;
  s.youngsModulus = 2.1e11;
  s.shearModulus = 8.1e10;
  s.density = 7800.0;
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  o.geometricStiffening = true;
  const FfrBeamModel3d model(BeamMesh3d::straight(1.0, 8, s), o, "body 'blade'");
  FfrInvariants3d inv = model.invariants();
  inv.spinStiffness = linearSpinStiffness(model);
  const FfrInvariants3d back = roundTrip(inv, "blade.SID_FEM");
  const double w = 20.0;
  const VecX f = fetest::spinningFrequencies(back, w), f0 = fetest::spinningFrequencies(back, 0.0);
  const double in = fetest::southwellCoefficient(f[0], f0[0], w), out = fetest::southwellCoefficient(f[1], f0[1], w);
  EXPECT_NEAR(in, fetest::kSouthwellCantilever - 1.0, 5e-3);
  EXPECT_NEAR(out, fetest::kSouthwellCantilever, 5e-3);
  std::printf("[ figures ] beam stiffening through its SID: Southwell %.4f in plane, %.4f out of plane (beam theory "
              "0.1933, 1.1933)\n", in, out);
}

// ----- strictness ------------------------------------------------------------------

namespace {

/// A well-formed SID of a 2-mode beam, as text.
std::string goodText() {
  std::ostringstream os;
  writeSid(sidFromInvariants(beam(2, BeamTheory::EulerBernoulli)->invariants()), os);
  return os.str();
}

/// The text with the first occurrence of `from` replaced by `to`.
std::string edited(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string errorOfText(const std::string& text, const std::string& name) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return errorOf([&] { invariantsFromSid(readSidFile(path), "body 'b'"); });
}

}  // namespace

TEST(SidReader, TheWellFormedFileReads) {
  const std::string path = tempPath("good.SID_FEM");
  std::ofstream(path) << goodText();
  EXPECT_NO_THROW(invariantsFromSid(readSidFile(path), "body 'b'"));
}

TEST(SidReader, MalformedFilesNameTheLineAndWhatWasExpected) {
  const std::string good = goodText();
  expectMentions(errorOfText(edited(good, "new modal", "new model"), "a.SID_FEM"),
                 {"a.SID_FEM, line 2", "\"new modal\""});
  expectMentions(errorOfText(edited(good, "    nelastq = 2", "    nelastq = two"), "b.SID_FEM"),
                 {"b.SID_FEM, line", "nelastq", "expected an integer"});
  expectMentions(errorOfText(edited(good, "    nelastq = 2", "    nelastq = 2\n    damping = 1"), "c.SID_FEM"),
                 {"unknown key 'damping' in refmod"});
  expectMentions(errorOfText(edited(good, "m0(1, 1) =", "m0(4, 1) ="), "d.SID_FEM"),
                 {"index 1 of m0(4, 1)", "expected 1 to 3"});
  expectMentions(errorOfText(edited(good, "Me\n    order = 0", "Me\n    order = 3"), "e.SID_FEM"),
                 {"Me has order 3", "expected 0, 1 or 2"});
  expectMentions(errorOfText(edited(good, "end Ke", "end Kx"), "f.SID_FEM"), {"expected 'key = value'"});
  expectMentions(errorOfText(edited(good, "end part\n", ""), "g.SID_FEM"), {"g.SID_FEM: the file ends", "\"end part\""});
  expectMentions(errorOfText(edited(good, "Gr\n", "Gx\n"), "h.SID_FEM"), {"found 'Gx'", "expected one of mdCM"});
}

TEST(SidReader, StructureAndDuplicatesAreChecked) {
  const std::string good = goodText();
  // Me is symmetric (structure 2): the lower triangle only
  const std::size_t me = good.find("Me\n");
  std::string upper = good;
  upper.insert(good.find("end Me"), "    m0(1, 2) = 0.5\n");
  ASSERT_NE(me, std::string::npos);
  expectMentions(errorOfText(upper, "i.SID_FEM"), {"Me is symmetric (structure 2)", "m0(1, 2)", "expected i >= j"});
  std::string twice = good;
  twice.insert(good.find("end Me"), "    m0(1, 1) = 1\n");
  expectMentions(errorOfText(twice, "j.SID_FEM"), {"entry m0(1, 1) of Me is given twice"});
  std::string block = good;
  const std::size_t ke = good.find("Ke\n"), keEnd = good.find("end Ke\n") + 7;
  block.insert(keEnd, good.substr(ke, keEnd - ke));
  expectMentions(errorOfText(block, "k.SID_FEM"), {"block Ke is given twice"});
  std::string noGr = good;
  noGr.erase(good.find("Gr\n"), good.find("end Gr\n") + 7 - good.find("Gr\n"));
  expectMentions(errorOfText(noGr, "l.SID_FEM"), {"without block Gr"});
}

TEST(SidReader, BlocksThatDisagreeOrCarryStiffeningAreRefused) {
  const SidData sid = sidFromInvariants(beam(2, BeamTheory::EulerBernoulli)->invariants());
  // Oe's first-order term beyond the inertia is the spin stiffness: read when symmetric
  // in the elastic coordinates, refused when not
  SidData stiff = sid;
  const double g = 1e-2 * stiff.Oe.m1[0].cwiseAbs().maxCoeff();
  stiff.Oe.m1[1](0, 2) += g;  // G_zz(0, 1)
  SidData asym = stiff;
  stiff.Oe.m1[0](1, 2) += g;  // G_zz(1, 0)
  const FfrInvariants3d read = invariantsFromSid(stiff, "body 'b'");
  ASSERT_EQ(read.spinStiffness[2][2].rows(), 2);
  EXPECT_NEAR(read.spinStiffness[2][2].coeff(0, 1), g, 1e-12 * g);
  EXPECT_NEAR(read.spinStiffness[0][1].coeff(0, 1), 0.0, 1e-12 * g);
  expectMentions(errorOf([&] { invariantsFromSid(asym, "body 'b'"); }),
                 {"body 'b': SID block Oe", "not symmetric", "expected a stiffness matrix"});
  // Ct in another convention (not S-bar^T)
  SidData ct = sid;
  ct.Ct.m0(1, 0) += 0.1;
  expectMentions(errorOf([&] { invariantsFromSid(ct, "body 'b'"); }), {"block Ct, m0(2, 1)", "differs from"});
  // reference stresses
  SidData ks = sid;
  ks.ksigma.structure = SidTaylor::Full;
  ks.ksigma.m0(0, 0) = 5.0;
  expectMentions(errorOf([&] { invariantsFromSid(ks, "body 'b'"); }), {"ksigma", "reference stresses"});
  // Gr to order 0: the S_kl are missing
  SidData gr = sid;
  gr.Gr.order = 0;
  gr.Gr.m1.clear();
  expectMentions(errorOf([&] { invariantsFromSid(gr, "body 'b'"); }), {"block Gr has order 0", "S_kl"});
  // nelastq that does not match a block
  SidData nq = sid;
  nq.modeNames.push_back("q3");
  expectMentions(errorOf([&] { invariantsFromSid(nq, "body 'b'"); }), {"block mdCM", "nq = 2", "nelastq = 3"});
  // a required block missing from data built in code (the file reader refuses it earlier)
  SidData noKe = sid;
  noKe.Ke = SidTaylor{};
  expectMentions(errorOf([&] { invariantsFromSid(noKe, "body 'b'"); }), {"body 'b': SID has no block Ke"});
  // a node's psi (the joints' rotation) that disagrees with its AP
  SidData ap = sid;
  ap.nodes[3].psi.m0(2, 1) += 0.5;
  expectMentions(errorOf([&] { invariantsFromSid(ap, "body 'b'"); }), {"node 4 AP", "m1("});
}
