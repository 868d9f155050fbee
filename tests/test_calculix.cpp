// CalculiX import (docs/fe-import.md, "CalculiX"): the readers of fe_import/fe_calculix.hpp and
// the clamped modes of bodies/modal_reduction.hpp against ccx itself. The test meshes a
// steel bar (1 x 0.1 x 0.1 m, 10 x 2 x 2 C3D20R bricks, 321 nodes) and runs `ccx` three
// times in a temporary folder (skipped without ccx on PATH):
//  - clamped (*BOUNDARY on the x = 0 face, *FREQUENCY): its frequencies and mode shapes
//    (.frd) against the clamped modes of the imported free matrices, the shapes as
//    eigenvectors of the imported K and M;
//  - free (*FREQUENCY, no boundary): its elastic frequencies against FeBodyModel's
//    free-free ones;
//  - the matrices (*FREQUENCY, SOLVER=MATRIXSTORAGE: .sti, .mas, .dof), read here; their
//    total mass against rho V.
// Then every strictness check of the readers on small broken files written here.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bodies/fe_body_model.hpp"
#include "bodies/fe_stress.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/modal_reduction.hpp"
#include "core/errors.hpp"
#include "simulation/simulation.hpp"
#include "fe_import/fe_abaqus.hpp"
#include "fe_import/fe_calculix.hpp"
#include "scene/scene.hpp"
#include "results/vtk_writer.hpp"
#include "fe_test_support.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;
namespace fs = std::filesystem;
using flexmbd::fetest::errorOf;
using flexmbd::fetest::expectMentions;
using json = nlohmann::json;

namespace {

constexpr double kE = 2.1e11, kNu = 0.3, kRho = 7850.0;
constexpr double kLength = 1.0, kWidth = 0.1, kHeight = 0.1;
constexpr int kNx = 10, kNy = 2, kNz = 2;
constexpr int kClampedModes = 8;  // compared; ccx is asked for 10
constexpr int kFreeModes = 8;     // elastic ones compared; ccx is asked for 6 + 8

/// A bar meshed by the test: length along x, its cross-section from (y0, z0), elements.
struct BarSpec {
  double length = kLength, width = kWidth, height = kHeight;
  int nx = kNx, ny = kNy, nz = kNz;
  double y0 = 0.0, z0 = 0.0;
  double E = kE, nu = kNu, rho = kRho;
  std::string type = "C3D20R";
};

/// The mesh part of the deck: 20-node bricks on a (2 nx + 1) (2 ny + 1) (2 nz + 1)
/// grid of points, a point a node if at most one of its indices is odd (corners and edge
/// midpoints), numbered 1 + its grid index (so with gaps). Keywords in mixed case, as ccx
/// accepts them. Node sets FIX: the x = 0 face; TIP: the x = length face.
std::string barMesh(const BarSpec& b = BarSpec{}) {
  const int kNx = b.nx, kNy = b.ny, kNz = b.nz;
  const double kLength = b.length, kWidth = b.width, kHeight = b.height, kE = b.E, kNu = b.nu, kRho = b.rho;
  const int gx = 2 * kNx + 1, gy = 2 * kNy + 1, gz = 2 * kNz + 1;
  const auto id = [&](int i, int j, int k) { return 1 + i + gx * (j + gy * k); };
  std::ostringstream s;
  s.precision(17);
  s << "*Heading\nbar, " << b.type << "\n*NODE, nset=Nall\n";
  std::vector<int> fixed, tip;
  for (int k = 0; k < gz; ++k) {
    for (int j = 0; j < gy; ++j) {
      for (int i = 0; i < gx; ++i) {
        if (i % 2 + j % 2 + k % 2 > 1) continue;
        s << id(i, j, k) << ", " << kLength * i / (gx - 1) << ", " << b.y0 + kWidth * j / (gy - 1) << ", "
          << b.z0 + kHeight * k / (gz - 1) << "\n";
        if (i == 0) fixed.push_back(id(i, j, k));
        if (i == gx - 1) tip.push_back(id(i, j, k));
      }
    }
  }
  // C3D20 node order: corners (bottom face counter-clockwise, then top), midpoints of the
  // bottom edges, of the top edges, of the vertical edges
  static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  static const int edge[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                  {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  s << "*Element, TYPE=" << b.type << ", ELSET=Eall\n";
  int label = 0;
  for (int ez = 0; ez < kNz; ++ez) {
    for (int ey = 0; ey < kNy; ++ey) {
      for (int ex = 0; ex < kNx; ++ex) {
        std::array<std::array<int, 3>, 8> c;
        for (int a = 0; a < 8; ++a) c[a] = {2 * (ex + corner[a][0]), 2 * (ey + corner[a][1]), 2 * (ez + corner[a][2])};
        std::vector<int> n;
        for (int a = 0; a < 8; ++a) n.push_back(id(c[a][0], c[a][1], c[a][2]));
        for (const auto& e : edge) {
          n.push_back(id((c[e[0]][0] + c[e[1]][0]) / 2, (c[e[0]][1] + c[e[1]][1]) / 2, (c[e[0]][2] + c[e[1]][2]) / 2));
        }
        s << ++label;
        for (int a = 0; a < 20; ++a) s << (a == 15 ? ",\n" : ", ") << n[a];  // 16 entries on the first line
        s << "\n";
      }
    }
  }
  s << "*nset, NSET=FIX\n";
  for (size_t a = 0; a < fixed.size(); ++a) s << fixed[a] << (a % 8 == 7 || a + 1 == fixed.size() ? "\n" : ", ");
  s << "*nset, NSET=TIP\n";
  for (size_t a = 0; a < tip.size(); ++a) s << tip[a] << (a % 8 == 7 || a + 1 == tip.size() ? "\n" : ", ");
  s << "*MATERIAL, NAME=STEEL\n*ELASTIC\n"
    << kE << ", " << kNu << "\n*DENSITY\n"
    << kRho << "\n*SOLID SECTION, ELSET=Eall, MATERIAL=STEEL\n";
  return s.str();
}

// The static tip load of the RBE2 test: ccx's *RIGID BODY over the TIP face with its
// reference node at the face's centre, the bar clamped at FIX; a force and a moment there.
const Vec3 kTipForce(0.0, -1000.0, 500.0), kTipMoment(50.0, 0.0, 0.0);
const Vec3 kTipPoint(kLength, kWidth / 2, kHeight / 2);

/// The model data of the tip's rigid body: its reference and rotation nodes at
/// kTipPoint, the clamped face held.
std::string clampedWithRigidTip() {
  std::ostringstream s;
  s.precision(17);
  s << "*NODE\n9001, " << kTipPoint.x() << ", " << kTipPoint.y() << ", " << kTipPoint.z() << "\n9002, "
    << kTipPoint.x() << ", " << kTipPoint.y() << ", " << kTipPoint.z() << "\n"
    << "*BOUNDARY\nFIX, 1, 3\n*RIGID BODY, NSET=TIP, REF NODE=9001, ROT NODE=9002\n";
  return s.str();
}

std::string staticTipLoadStep() {
  std::ostringstream s;
  s.precision(17);
  s << clampedWithRigidTip() << "*STEP\n*STATIC\n*CLOAD\n";
  for (int k = 0; k < 3; ++k) {
    if (kTipForce[k] != 0.0) s << "9001, " << k + 1 << ", " << kTipForce[k] << "\n";
    if (kTipMoment[k] != 0.0) s << "9002, " << k + 1 << ", " << kTipMoment[k] << "\n";
  }
  s << "*NODE PRINT, NSET=Nall\nU\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n";
  return s.str();
}

/// Six static load cases: a unit force along x, y, z at the tip's reference node, then a
/// unit moment about x, y, z at its rotation node (the static responses whose span is
/// the Craig-Bampton constraint modes of the tip), with displacements and stresses.
std::string unitTipLoadCases() {
  std::ostringstream s;
  s << clampedWithRigidTip();
  for (int c = 0; c < 6; ++c) {
    s << "*STEP\n*STATIC\n*CLOAD, OP=NEW\n" << (c < 3 ? 9001 : 9002) << ", " << c % 3 + 1
      << ", 1.\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n";
  }
  return s.str();
}

/// The displacements ccx printed to `path` (.dat, *NODE PRINT: "node ux uy uz", 7 digits).
std::map<int, Vec3> datDisplacements(const std::string& path) {
  std::ifstream in(path);
  std::map<int, Vec3> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    int node = 0;
    Vec3 u;
    if (ls >> node >> u.x() >> u.y() >> u.z()) out[node] = u;
  }
  return out;
}

/// The connecting rod of examples/spatial_slider_crank_elastic.json as a solid: aluminium,
/// 0.45 m x 8 mm x 8 mm centred on the x axis, 20 x 1 x 1 C3D20 bricks (full
/// integration: one reduced-integration C3D20R through the section has zero-energy
/// modes, and the rod's clamped stiffness is then singular).
BarSpec rodSpec() {
  BarSpec b;
  b.length = 0.45;
  b.width = b.height = 0.008;
  b.nx = 20;
  b.ny = b.nz = 1;
  b.y0 = b.z0 = -0.004;
  b.E = 7e10;
  b.nu = 0.33;
  b.rho = 2700.0;
  b.type = "C3D20";
  return b;
}

/// The bar centred on the x axis: a spin about z through the origin turns it about its
/// root face's centre (the spin-stiffening test).
BarSpec spinSpec() {
  BarSpec b;
  b.y0 = -kWidth / 2;
  b.z0 = -kHeight / 2;
  return b;
}

/// The spinning bar's preload run: clamped at FIX, a steady spin of w rad/s about z through
/// the origin (*DLOAD CENTRIF, w^2), then `perturbation` (a *FREQUENCY step) about it.
std::string spinPreload(double w, const std::string& perturbation) {
  std::ostringstream s;
  s.precision(17);
  s << barMesh(spinSpec()) << "*BOUNDARY\nFIX, 1, 3\n*STEP, NLGEOM\n*STATIC\n*DLOAD\nEall, CENTRIF, " << w * w
    << ", 0., 0., 0., 0., 0., 1.\n*END STEP\n*STEP, PERTURBATION\n" << perturbation << "*END STEP\n";
  return s.str();
}

/// The folder of the ccx runs, made once for all tests of the suite.
class CalculixBar : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (std::system("command -v ccx > /dev/null 2>&1") != 0) {
      skip_ = "ccx (CalculiX, Debian package calculix-ccx: scripts/setup.sh) is not on PATH";
      return;
    }
    dir_ = fs::temp_directory_path() /
           ("flexmbd_ccx_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(dir_);
    const std::string mesh = barMesh(), matrixStep = "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n";
    std::ofstream((dir_ / "rod.inp").string()) << barMesh(rodSpec()) << matrixStep;
    std::map<std::string, std::string> steps = {
        {"clamped", "*BOUNDARY\nFIX, 1, 3\n*STEP\n*FREQUENCY\n10\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n"},
        {"free", "*STEP\n*FREQUENCY\n14\n*NODE FILE\nU\n*END STEP\n"},
        {"matrices", "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n"},
        {"static", staticTipLoadStep()},
        {"unit_cases", unitTipLoadCases()},
        {"fixed_fixed", "*BOUNDARY\nFIX, 1, 3\nTIP, 1, 3\n*STEP\n*FREQUENCY\n10\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n"}};
    steps["rod"] = "";  // written above
    std::ofstream((dir_ / "spin_matrices.inp").string()) << barMesh(spinSpec()) << matrixStep;
    std::ofstream((dir_ / "spin_pre.inp").string()) << spinPreload(100.0, "*FREQUENCY, SOLVER=MATRIXSTORAGE\n");
    std::ofstream((dir_ / "spin_50.inp").string()) << spinPreload(50.0, "*FREQUENCY\n6\n*NODE FILE\nU\n");
    for (const char* written : {"spin_matrices", "spin_pre", "spin_50"}) steps[written] = "";
    for (const auto& [job, step] : steps) {
      if (!step.empty()) std::ofstream((dir_ / (job + ".inp")).string()) << mesh << step;
      const std::string cmd =
          "cd '" + dir_.string() + "' && OMP_NUM_THREADS=1 ccx -i " + job + " > " + job + ".log 2>&1";
      if (std::system(cmd.c_str()) != 0) {
        error_ = "ccx failed on " + job + ".inp: see " + (dir_ / (job + ".log")).string();
        return;
      }
    }
  }
  static void TearDownTestSuite() {
    if (!dir_.empty() && error_.empty()) fs::remove_all(dir_);
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_TRUE(error_.empty()) << error_;
  }
  static std::string job(const std::string& name) { return (dir_ / name).string(); }
  static FeBodyData bar() { return readCalculixFe(CalculixFeFiles::ofJob(job("matrices"))); }

  static fs::path dir_;
  static std::string skip_, error_;
};

fs::path CalculixBar::dir_;
std::string CalculixBar::skip_, CalculixBar::error_;

/// The frequencies (Hz) of a frequency analysis' steps, in order.
std::vector<double> frequencies(const FrdResults& r) {
  std::vector<double> f;
  for (const FrdStep& s : r.steps) f.push_back(s.value);
  return f;
}

/// The sum of |A_ij| over the x-direction rows and columns of a body's matrix.
double absSumX(const FeBodyData& d, const SpMat& A) {
  double s = 0.0;
  for (int j = 0; j < A.outerSize(); ++j) {
    for (SpMat::InnerIterator it(A, j); it; ++it) {
      if (d.dofs[it.row()].direction == 0 && d.dofs[j].direction == 0) s += std::abs(it.value());
    }
  }
  return s;
}

/// The free DOF (not of `held`), ascending.
std::vector<int> freeDofs(int n, const std::vector<int>& held) {
  std::vector<char> h(n, 0);
  for (int i : held) h[i] = 1;
  std::vector<int> out;
  for (int i = 0; i < n; ++i) {
    if (!h[i]) out.push_back(i);
  }
  return out;
}

}  // namespace

TEST_F(CalculixBar, MatricesAreReadAndHoldTheBarsMass) {
  const FeBodyData d = bar();
  EXPECT_EQ(d.numNodes(), 321);  // (21 x 5 x 5) grid points less those with two or three odd indices
  EXPECT_EQ(d.numDofs(), 963);
  ASSERT_EQ(d.elements.size(), 40u);
  EXPECT_EQ(d.elements[0].type, "C3D20R");
  EXPECT_EQ(d.nodeSets.at("FIX").size(), 21u);  // the 5 x 5 face less its 4 face-centre points
  // total mass r_x^T M r_x = int rho (sum_a n_a)^2 dV = rho V for any quadrature exact
  // for constants (C3D20R's reduced 2 x 2 x 2 rule is). The .mas prints 14 significant
  // digits (relative 5e-14 per entry): the sum errs by at most 5e-14 sum |M_ij| (x block).
  const double m = VecX::Ones(d.numDofs()).dot(d.mass * VecX::Ones(d.numDofs())) / 3.0;
  const double rhoV = kRho * kLength * kWidth * kHeight;
  const double printed = 5e-14 * absSumX(d, d.mass);
  EXPECT_NEAR(m, rhoV, printed + 1e-15 * rhoV);
  const FeBodyModel model(d, FeBodyOptions{}, "bar");
  EXPECT_NEAR(model.invariants().mass, rhoV, printed + 1e-15 * rhoV);
  // a finding: the stored C3D20R mass is indefinite. Its LDL^T (a congruence,
  // Sylvester's law of inertia) counts the negative eigenvalues; a Cholesky factor fails.
  const Eigen::SimplicialLDLT<SpMat> ldlt(d.mass);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const int negative = static_cast<int>((ldlt.vectorD().array() < 0.0).count());
  EXPECT_GT(negative, 0);
  EXPECT_NE(Eigen::SimplicialLLT<SpMat>(d.mass).info(), Eigen::Success);
  std::printf(
      "[ figures ] C3D20R bar: mass %.14g kg (rho V %.14g, rel. %.1e, print bound %.1e); M has %d negative of %d "
      "eigenvalues\n",
      m, rhoV, m / rhoV - 1.0, printed / rhoV, negative, d.numDofs());
}

TEST_F(CalculixBar, ClampedFrequenciesEqualCcxs) {
  const FeBodyData d = bar();
  VecX omega;
  const std::vector<int> held = d.dofsOfNodes(d.nodeSets.at("FIX"));
  const MatX phi = clampedModes(d.stiffness, d.mass, held, kClampedModes, "bar", &omega);
  const std::vector<double> ccx = frequencies(readCalculixFrd(job("clamped.frd")));
  ASSERT_GE(ccx.size(), static_cast<size_t>(kClampedModes));
  // ccx prints each frequency to 10 significant digits (5e-10 relative) and its Lanczos
  // (ARPACK) agrees with itself to ~2e-9 on the degenerate pairs of the square section;
  // ours converges to 1e-13: 1e-6 relative (the brief's bound) holds with a margin of 1e2.
  constexpr double kSameFrequency = 1e-6;
  double worst = 0.0;
  std::printf("[ figures ] clamped bar, Hz (ccx | imported | rel. error):");
  for (int i = 0; i < kClampedModes; ++i) {
    ASSERT_GT(ccx[i], 0.0) << "ccx mode " << i + 1 << " of negative eigenvalue";
    const double f = omega[i] / (2.0 * kPi), e = f / ccx[i] - 1.0;
    EXPECT_NEAR(f / ccx[i], 1.0, kSameFrequency) << "mode " << i + 1;
    worst = std::max(worst, std::abs(e));
    std::printf(" %.10g | %.10g | %.1e;", ccx[i], f, e);
  }
  std::printf(" worst %.1e\n", worst);
  // mass-normalised and zero at the clamped DOF
  EXPECT_LT((phi.transpose() * (d.mass * phi) - MatX::Identity(kClampedModes, kClampedModes)).cwiseAbs().maxCoeff(),
            1e-10);
  for (int i : held) EXPECT_EQ(phi.row(i).cwiseAbs().maxCoeff(), 0.0);
}

TEST_F(CalculixBar, CraigBamptonFixedInterfaceFrequenciesEqualCcxsClamped) {
  // A rigid interface over the clamped face as the Craig-Bampton reference: holding its 6
  // DOF holds every node of the face, ccx's *BOUNDARY FIX, 1, 3; the body's fixed-interface
  // frequencies are then ccx's clamped ones, to 1e-6 as the clamped modes above.
  const FeBodyData d = bar();
  FeBodyOptions o;
  o.modes = kClampedModes;
  o.interfaces.push_back({"root", d.nodeSets.at("FIX"), FeInterfaceKind::Rigid});
  o.reduction = FeReduction::CraigBampton;
  o.reference = "root";
  const FeBodyModel model(d, o, "bar");
  const std::vector<double> ccx = frequencies(readCalculixFrd(job("clamped.frd")));
  ASSERT_EQ(model.naturalFrequencies().size(), kClampedModes);
  ASSERT_EQ(model.invariants().numElastic(), kClampedModes);  // one interface: no constraint modes
  double worst = 0.0;
  for (int i = 0; i < kClampedModes; ++i) {
    const double f = model.naturalFrequencies()[i] / (2.0 * kPi);
    EXPECT_NEAR(f / ccx[i], 1.0, 1e-6) << "mode " << i + 1;
    worst = std::max(worst, std::abs(f / ccx[i] - 1.0));
  }
  std::printf("[ figures ] Craig-Bampton bar on a rigid root: fixed-interface vs ccx clamped, worst %.1e\n", worst);
}

TEST_F(CalculixBar, StaticTipLoadThroughARigidInterfaceEqualsCcxs) {
  // The imported bar with a rigid interface over its TIP face (point: the face's centre,
  // ccx's REF NODE), clamped at FIX: (T^T K T) x = f at the interface, the nodes' u = T x,
  // against ccx's *RIGID BODY solution at every node. ccx prints 7 digits (5e-7 of each
  // value) and its rigid-body MPC is exact to the square of the tip rotation (~1e-4 rad):
  // 1e-6 of the largest displacement.
  const FeBodyData d = bar();
  FeBodyOptions o;
  FeInterface tip{"tip", d.nodeSets.at("TIP"), FeInterfaceKind::Rigid};
  tip.atCentroid = false;
  tip.point = kTipPoint;
  o.interfaces.push_back(tip);
  o.modes = 2;
  const FeBodyModel m(d, o, "bar");
  const SpMat& T = m.nodalMap();
  const MatX K = MatX(m.nodalInvariants().kff);
  const int n = static_cast<int>(K.rows()), master = n - 6;
  std::vector<char> clamped(d.numNodes(), 0);
  for (int a : d.nodeSets.at("FIX")) clamped[a] = 1;
  std::vector<int> keep;  // the condensed DOF not clamped
  for (int j = 0; j < n; ++j) {
    if (j >= master || !clamped[d.dofs[SpMat::InnerIterator(T, j).row()].node]) keep.push_back(j);
  }
  const int nk = static_cast<int>(keep.size());
  MatX Kk(nk, nk);
  VecX f = VecX::Zero(nk);
  for (int i = 0; i < nk; ++i) {
    for (int j = 0; j < nk; ++j) Kk(i, j) = K(keep[i], keep[j]);
    if (keep[i] >= master) f[i] = keep[i] - master < 3 ? kTipForce[keep[i] - master] : kTipMoment[keep[i] - master - 3];
  }
  const VecX xk = Kk.ldlt().solve(f);
  VecX x = VecX::Zero(n);
  for (int i = 0; i < nk; ++i) x[keep[i]] = xk[i];
  const VecX u = T * x;
  const std::map<int, Vec3> ccx = datDisplacements(job("static.dat"));
  ASSERT_EQ(ccx.size(), static_cast<size_t>(d.numNodes()));
  const std::vector<int> dof = d.dofIndex();
  double largest = 0.0, worst = 0.0;
  for (const auto& [id, v] : ccx) largest = std::max(largest, v.norm());
  for (int a = 0; a < d.numNodes(); ++a) {
    const Vec3 ours(u[dof[3 * a]], u[dof[3 * a + 1]], u[dof[3 * a + 2]]);
    worst = std::max(worst, (ours - ccx.at(d.nodeIds[a])).norm());
  }
  EXPECT_LT(worst, 1e-6 * largest);
  std::printf("[ figures ] RBE2 tip load: largest displacement %.6e m, worst difference to ccx %.1e of it\n", largest,
              worst / largest);
}

namespace {

/// The bar reduced by Craig-Bampton: a rigid root (FIX) as the reference, a rigid tip
/// interface (TIP, its point kTipPoint: 6 constraint modes), 4 fixed-interface modes.
FeBodyOptions craigBamptonBar(const FeBodyData& d) {
  FeBodyOptions o;
  o.modes = 4;
  o.interfaces.push_back({"root", d.nodeSets.at("FIX"), FeInterfaceKind::Rigid});
  FeInterface tip{"tip", d.nodeSets.at("TIP"), FeInterfaceKind::Rigid};
  tip.atCentroid = false;
  tip.point = kTipPoint;
  o.interfaces.push_back(tip);
  o.reduction = FeReduction::CraigBampton;
  o.reference = "root";
  return o;
}

/// The static tip load in the reduced coordinates: (B^T K B) q = B^T f, f at the tip
/// frame's DOF (the last 6 of the nodal DOF).
VecX staticTipSolution(const FeBodyModel& m) {
  const MatX K = MatX(m.nodalInvariants().kff);
  const int n = static_cast<int>(K.rows());
  VecX f = VecX::Zero(n);
  f.segment<3>(n - 6) = kTipForce;
  f.segment<3>(n - 3) = kTipMoment;
  const MatX& B = m.basis();
  return (B.transpose() * K * B).ldlt().solve(B.transpose() * f);
}

}  // namespace

TEST_F(CalculixBar, StressOfAStaticTipLoadRecoveredFromStressShapesEqualsCcxs) {
  // The bar reduced by Craig-Bampton on a rigid root (FIX) with a rigid tip interface (6
  // constraint modes) and 4 fixed-interface modes. Stress samples from ccx: the six unit
  // tip load cases and the fixed-fixed modes (DISP and STRESS of each); every coordinate's
  // stress shape is the samples' combination that gives its displacement (stressShapes).
  // The static tip load of the RBE2 test, solved in the reduced coordinates, then
  // sigma = S q_f at every node, against ccx's own stress of that load. Both sides print 6
  // digits (E12.5, 5e-6 of each value) and the unit cases combine with weights up to 1e3:
  // 1e-4 of the largest von Mises stress.
  const FeBodyData d = bar();
  const FeBodyModel m(d, craigBamptonBar(d), "bar");
  const FeStressSamples samples =
      joinedSamples(stressSamplesFromFrd(readCalculixFrd(job("unit_cases.frd")), d, "unit_cases.frd", "bar"),
                    stressSamplesFromFrd(readCalculixFrd(job("fixed_fixed.frd")), d, "fixed_fixed.frd", "bar"));
  ASSERT_EQ(samples.displacement.cols(), 6 + 10);
  const MatX S = stressShapes(m, samples, "bar");
  ASSERT_EQ(S.cols(), 6 + 4);
  const VecX q = staticTipSolution(m);
  const VecX sigma = S * q;
  const FrdResults ccx = readCalculixFrd(job("static.frd"));
  ASSERT_EQ(ccx.steps.size(), 1u);
  const FrdBlock& st = ccx.steps[0].blocks.at("STRESS");
  double largest = 0.0, worst = 0.0, rootBending = 0.0, rootWorst = 0.0;
  std::vector<char> isRoot(d.numNodes(), 0);
  for (int a : d.nodeSets.at("FIX")) isRoot[a] = 1;
  for (int a = 0; a < d.numNodes(); ++a) {
    const std::vector<double>& c = st.values.at(d.nodeIds[a]);
    const Eigen::Matrix<double, 6, 1> theirs = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(c.data());
    largest = std::max(largest, vonMises(theirs));
    worst = std::max(worst, (sigma.segment<6>(6 * a) - theirs).cwiseAbs().maxCoeff());
    if (isRoot[a]) {
      rootBending = std::max(rootBending, std::abs(theirs[0]));
      rootWorst = std::max(rootWorst, std::abs(sigma[6 * a] - theirs[0]));
    }
  }
  EXPECT_LT(worst, 1e-4 * largest);
  EXPECT_LT(rootWorst, 1e-4 * rootBending);
  std::printf(
      "[ figures ] stress recovery, static tip load: largest von Mises %.6e Pa, worst component difference to ccx "
      "%.1e of it; root bending stress sxx up to %.6e Pa, recovered to %.1e of it\n",
      largest, worst / largest, rootBending, rootWorst / rootBending);
  // a basis the samples do not span is refused naming the coordinate: free-free modes
  FeBodyOptions ff;
  ff.modes = 2;
  try {
    stressShapes(FeBodyModel(d, ff, "bar"), samples, "body 'bar'");
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("do not span elastic coordinate 1"), std::string::npos) << e.what();
  }
}

TEST_F(CalculixBar, SceneStressOutputAndVtkSurfaceOfTheStaticTipLoad) {
  // The same reduction as a scene's fe_body with "stresses", its elastic coordinates the
  // static solution of the test above: a "stress" output at every root node gives ccx's
  // static stress (1e-4 of the largest von Mises, as above), and the VTK frame draws the
  // bar's outer surface (2 (10 x 2 + 10 x 2 + 2 x 2) = 88 quadrilaterals) with von Mises.
  const FeBodyData d = bar();
  json body = {{"type", "fe_body"},
               {"name", "bar"},
               {"calculix", {{"job", "matrices"}}},
               {"modes", 4},
               {"reduction", "craig_bampton"},
               {"reference", "root"},
               {"stresses", {{"calculix_frd", {"unit_cases.frd", "fixed_fixed.frd"}}}}};
  body["interfaces"] = json::array(
      {json{{"name", "root"}, {"kind", "rigid"}, {"node_set", "FIX"}},
       json{{"name", "tip"}, {"kind", "rigid"}, {"node_set", "TIP"}, {"point", {kTipPoint.x(), kTipPoint.y(), kTipPoint.z()}}}});
  // the static solution in the body's coordinates, from the model of the same options
  const FeBodyModel m(d, craigBamptonBar(d), "bar");
  const VecX qf = staticTipSolution(m);
  body["elastic_coordinates"] = std::vector<double>(qf.data(), qf.data() + qf.size());
  json outputs = json::array();
  for (int a : d.nodeSets.at("FIX")) {
    outputs.push_back({{"type", "stress"}, {"name", "s" + std::to_string(d.nodeIds[a])}, {"body", "bar"},
                       {"node", d.nodeIds[a]}});
  }
  const json scene = {{"dimension", 3}, {"bodies", {body}}, {"outputs", outputs}};
  const Scene sc = parseSceneText(scene.dump(), job("scene.json"));
  const VecX q0 = sc.system.initialCoordinates(), v0 = VecX::Zero(sc.system.numVelocities());
  const FrdResults ccx = readCalculixFrd(job("static.frd"));
  const FrdBlock& st = ccx.steps.at(0).blocks.at("STRESS");
  double largest = 0.0, worst = 0.0;
  for (const auto& [id, c] : st.values) {
    largest = std::max(largest, vonMises(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(c.data())));
  }
  for (const OutputRequest& out : sc.outputs) {
    const std::vector<double> v = out.evaluate(sc.system, q0, v0);
    const std::vector<double>& c = st.values.at(out.node);
    ASSERT_EQ(v.size(), 7u);
    for (int k = 0; k < 6; ++k) worst = std::max(worst, std::abs(v[k] - c[k]));
    EXPECT_NEAR(v[6], vonMises(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(c.data())), 1e-4 * largest);
  }
  EXPECT_LT(worst, 1e-4 * largest);
  EXPECT_EQ(sc.outputs[0].columnNames().back(), sc.outputs[0].name + ".von_mises");
  // the VTK frame
  {
    VtkWriter vtk(dir_ / "vtk", sc.system, "bodies", 4, sc.geometry, sc.feBodies);
    OutputSample sample;
    sample.q = q0;
    sample.v = v0;
    vtk.write(sample);
  }
  std::ifstream in((dir_ / "vtk" / "bodies_000000.vtu").string());
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("NumberOfCells=\"88\""), std::string::npos) << text.str().substr(0, 400);
  EXPECT_NE(text.str().find("Name=\"von_mises\""), std::string::npos);
  // a stress output on a body without stresses names the key
  json plain = scene;
  plain["bodies"][0].erase("stresses");
  try {
    parseSceneText(plain.dump(), job("scene.json"));
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no \"stresses\""), std::string::npos) << e.what();
  }
}

namespace {

/// The largest distance of the rod's midpoint from the midpoint of its ends over a run of
/// `scene` (outputs "a", "m", "b": points at the two ends and the middle), after t0.
double largestMidspanDeflection(const Scene& sc, double t0, int* steps) {
  SolverSettings st = sc.solver;
  st.progress = false;
  double largest = 0.0;
  const SimulationSummary r = simulate(sc.system, st, [&](const OutputSample& o) {
    if (o.t < t0) return;
    const std::vector<double> a = sc.outputs[0].evaluate(sc.system, o.q, o.v);
    const std::vector<double> m = sc.outputs[1].evaluate(sc.system, o.q, o.v);
    const std::vector<double> b = sc.outputs[2].evaluate(sc.system, o.q, o.v);
    const Vec3 chord = 0.5 * (Vec3(a[0], a[1], a[2]) + Vec3(b[0], b[1], b[2]));
    largest = std::max(largest, (Vec3(m[0], m[1], m[2]) - chord).norm());
  });
  EXPECT_TRUE(r.ok) << r.message;
  *steps = static_cast<int>(r.stats.steps);
  return largest;
}

}  // namespace

TEST_F(CalculixBar, ImportedRodInTheSpatialSliderCrankAgreesWithTheBeamModel) {
  // examples/spatial_slider_crank_elastic.json with its rod (Timoshenko beam, 8 elements,
  // pinned-pinned frame; no damping or geometric stiffening, which the FE body has not;
  // the crank spun up over 0.1 s, so no start transient rings undamped) and the same rod
  // meshed as a solid by this test, exported by ccx and imported as an fe_body: rigid
  // interfaces over its end faces (their points the joints' points on the axis), 12
  // free-free modes on mean axes. The largest midspan deflection from the chord over the
  // second half of the run agrees to the difference between the solid with rigid end faces
  // and the Timoshenko beam, with the modal truncation: measured 1.3e-3, held to 1e-2.
  const std::string example = std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json";
  std::ifstream in(example);
  json beamScene = json::parse(in);
  json& rod = beamScene["bodies"][1];
  ASSERT_EQ(rod["name"], "rod");
  rod["section"].erase("damping");
  rod["geometric_stiffening"] = false;
  rod["beam_theory"] = "timoshenko";
  const json points = {json{{"type", "point"}, {"name", "a"}, {"body", "rod"}, {"point", {0.0, 0.0, 0.0}}},
                       json{{"type", "point"}, {"name", "m"}, {"body", "rod"}, {"point", {0.225, 0.0, 0.0}}},
                       json{{"type", "point"}, {"name", "b"}, {"body", "rod"}, {"point", {0.45, 0.0, 0.0}}}};
  beamScene["outputs"] = points;
  beamScene["drivers"][0]["law"] = {{"type", "spin_up"}, {"speed", 10.0 * kPi}, {"ramp_time", 0.1}, {"initial", 0.3}};
  beamScene["solver"]["t_end"] = 0.3;
  json feScene = beamScene;
  json fe = {{"type", "fe_body"}, {"name", "rod"}, {"calculix", {{"job", "rod"}}}, {"modes", 12},
             {"position", rod["position"]}, {"orientation", rod["orientation"]}};
  fe["interfaces"] = json::array({json{{"name", "a"}, {"kind", "rigid"}, {"node_set", "FIX"}},
                                  json{{"name", "b"}, {"kind", "rigid"}, {"node_set", "TIP"}},
                                  json{{"name", "m"}, {"kind", "averaging"}, {"nodes", json::array()}}});
  // the middle cross-section's nodes (x = 0.225: grid plane 20 of 40)
  const FeBodyData rodData = readCalculixFe(CalculixFeFiles::ofJob(job("rod")));
  for (int a = 0; a < rodData.numNodes(); ++a) {
    if (std::abs(rodData.coordinates[a].x() - 0.225) < 1e-9) fe["interfaces"][2]["nodes"].push_back(rodData.nodeIds[a]);
  }
  feScene["bodies"][1] = fe;
  const Scene beam = parseSceneText(beamScene.dump(), example);
  const Scene solid = parseSceneText(feScene.dump(), job("scene.json"));
  const double t0 = 0.2;  // after the spin-up, the second revolution
  int beamSteps = 0, solidSteps = 0;
  const double db = largestMidspanDeflection(beam, t0, &beamSteps);
  const double ds = largestMidspanDeflection(solid, t0, &solidSteps);
  ASSERT_GT(db, 1e-6);  // the rod bends: tens of micrometres
  EXPECT_NEAR(ds / db, 1.0, 1e-2);
  std::printf("[ figures ] spatial slider crank, largest midspan deflection after the spin-up: Timoshenko "
              "beam %.4e m (%d steps), imported solid %.4e m (%d steps), ratio %.4f\n",
              db, beamSteps, ds, solidSteps, ds / db);
}

TEST_F(CalculixBar, FreeFreeFrequenciesEqualCcxs) {
  FeBodyOptions o;
  o.modes = kFreeModes;
  const FeBodyModel model(bar(), o, "bar");
  const std::vector<double> ccx = frequencies(readCalculixFrd(job("free.frd")));
  ASSERT_EQ(ccx.size(), 6u + kFreeModes);
  // ccx's six rigid modes: its round-off, below 1e-5 of the first elastic frequency
  for (int i = 0; i < 6; ++i) EXPECT_LT(ccx[i], 1e-5 * ccx[6]) << "ccx rigid mode " << i + 1;
  constexpr double kSameFrequency = 1e-6;  // as the clamped frequencies
  double worst = 0.0;
  std::printf("[ figures ] free-free bar, Hz (ccx | imported | rel. error):");
  for (int i = 0; i < kFreeModes; ++i) {
    const double f = model.naturalFrequencies()[i] / (2.0 * kPi), e = f / ccx[6 + i] - 1.0;
    EXPECT_NEAR(f / ccx[6 + i], 1.0, kSameFrequency) << "elastic mode " << i + 1;
    worst = std::max(worst, std::abs(e));
    std::printf(" %.10g | %.10g | %.1e;", ccx[6 + i], f, e);
  }
  std::printf(" worst %.1e\n", worst);
}

TEST_F(CalculixBar, SceneBodyOfTheJobIsTheModelsBody) {
  // "type": "fe_body" with "calculix": {"job"} relative to the scene's folder: the same
  // first frequency as the model built from the files (one code path: equal to the bit),
  // and so ccx's free-free frequency to the tolerance of the test above.
  const json scene = {{"dimension", 3},
                      {"bodies",
                       {{{"type", "fe_body"}, {"name", "bar"}, {"calculix", {{"job", "matrices"}}}, {"modes", 2}}}}};
  const Scene s = parseSceneText(scene.dump(), job("scene.json"));
  const auto& body = dynamic_cast<const FfrBody3d&>(s.system.body(BodyIndex(1)));
  FeBodyOptions o;
  o.modes = 2;
  const FeBodyModel model(bar(), o, "bar");
  EXPECT_EQ(body.invariants().kff.coeff(0, 0), model.invariants().kff.coeff(0, 0));
  EXPECT_EQ(body.invariants().mass, model.invariants().mass);
}

TEST_F(CalculixBar, FrdModeShapesAreEigenvectorsOfTheImportedMatrices) {
  const FeBodyData d = bar();
  const FrdResults r = readCalculixFrd(job("clamped.frd"));
  EXPECT_EQ(r.nodes.size(), 321u);
  ASSERT_GE(r.steps.size(), static_cast<size_t>(kClampedModes));
  const std::vector<int> held = d.dofsOfNodes(d.nodeSets.at("FIX"));
  const std::vector<int> fr = freeDofs(d.numDofs(), held);
  const int nf = static_cast<int>(fr.size());
  std::vector<Eigen::Triplet<double>> tp;
  for (int i = 0; i < nf; ++i) tp.emplace_back(fr[i], i, 1.0);
  SpMat P(d.numDofs(), nf);
  P.setFromTriplets(tp.begin(), tp.end());
  const SpMat K = P.transpose() * d.stiffness * P, M = P.transpose() * d.mass * P;
  const SpMat Ka = K.cwiseAbs(), Ma = M.cwiseAbs();
  // The .frd prints E12.5, 6 significant digits: each printed u_i = u*_i (1 + e_i), |e_i|
  // <= 5e-6. With (K - lambda M) u* = 0, the residual of the printed shape is (K - lambda
  // M) (u - u*), componentwise at most kRound (|K| + lambda |M|) |u|; lambda, from the
  // 10-digit frequency (1e-9) of ccx's Lanczos (its degenerate pairs differ by 4e-9 in
  // lambda), adds at most 1e-8 lambda |M| |u|. The generalized mass
  // u^T M u = 1 (ccx mass-normalises) to 2 kRound |u|^T |M| |u|.
  constexpr double kRound = 5e-6;
  double worstRatio = 0.0;
  for (int m = 0; m < kClampedModes; ++m) {
    const FrdStep& s = r.steps[m];
    EXPECT_EQ(s.mode, m + 1);
    EXPECT_EQ(s.number, m + 1);
    EXPECT_EQ(s.type, 2);  // frequency
    EXPECT_EQ(s.analysis, "MODAL");
    ASSERT_EQ(s.blocks.count("DISP"), 1u);
    const FrdBlock& disp = s.blocks.at("DISP");
    EXPECT_EQ(disp.components, (std::vector<std::string>{"D1", "D2", "D3"}));  // ALL: computed by the viewer
    ASSERT_EQ(s.blocks.count("STRESS"), 1u);
    EXPECT_EQ(s.blocks.at("STRESS").components, (std::vector<std::string>{"SXX", "SYY", "SZZ", "SXY", "SYZ", "SZX"}));
    EXPECT_EQ(s.blocks.at("STRESS").values.size(), 321u);
    VecX u(d.numDofs());
    for (int i = 0; i < d.numDofs(); ++i) u[i] = disp.values.at(d.nodeIds[d.dofs[i].node]).at(d.dofs[i].direction);
    for (int i : held) EXPECT_EQ(u[i], 0.0);
    const VecX uf = P.transpose() * u, ua = uf.cwiseAbs();
    const double lambda = std::pow(2.0 * kPi * s.value, 2);
    const VecX residual = K * uf - lambda * (M * uf);
    const VecX bound = kRound * (Ka * ua + lambda * (Ma * ua)) + 1e-8 * lambda * (Ma * ua);
    const double ratio = residual.norm() / bound.norm();
    EXPECT_LE(ratio, 1.0) << "mode " << m + 1;
    worstRatio = std::max(worstRatio, ratio);
    EXPECT_NEAR(uf.dot(M * uf), 1.0, 2.0 * kRound * ua.dot(Ma * ua)) << "mode " << m + 1;
  }
  std::printf("[ figures ] .frd mode shapes: |K u - lambda M u| <= %.2f of the printing bound (worst of %d)\n",
              worstRatio, kClampedModes);
}

// ----- strictness of the readers, on small files written here -----------------------------

namespace {

class CalculixFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("flexmbd_ccxfiles_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string p = (dir_ / name).string();
    std::ofstream(p) << text;
    return p;
  }
  /// One C3D8 brick, nodes 11..18 (lower case keywords), its node set by GENERATE.
  static std::string deck() {
    return "*node, NSET=all\n11, 0., 0., 0.\n12, 1., 0., 0.\n13, 1., 1., 0.\n14, 0., 1., 0.\n"
           "15, 0., 0., 1.\n16, 1., 0., 1.\n17, 1., 1., 1.\n18, 0., 1., 1.\n"
           "*element, type=C3D8R, elset=E\n1, 11, 12, 13, 14, 15, 16, 17, 18\n"
           "*Nset, nset=top, generate\n15, 18\n*boundary\ntop, 1, 3\n";
  }
  /// The .dof of the brick's 24 equations, in node order, `extra` lines appended.
  static std::string dofText(const std::string& extra = "") {
    std::string s;
    for (int n = 11; n <= 18; ++n) {
      for (int k = 1; k <= 3; ++k) s += std::to_string(n) + "." + std::to_string(k) + "\n";
    }
    return s + extra;
  }
  /// A diagonal 24 x 24 matrix, upper triangle, `extra` lines appended.
  static std::string matrixText(double diag, const std::string& extra = "") {
    std::string s;
    for (int i = 1; i <= 24; ++i) s += std::to_string(i) + " " + std::to_string(i) + "  " + std::to_string(diag) + "\n";
    return s + extra;
  }
  CalculixFeFiles files(const std::string& dof = dofText(), const std::string& sti = matrixText(5.0, "1 2 0.5\n"),
                        const std::string& mas = matrixText(2.0)) {
    return {write("job.inp", deck()), write("job.sti", sti), write("job.mas", mas), write("job.dof", dof)};
  }
  fs::path dir_;
};


}  // namespace

TEST_F(CalculixFiles, SmallBodyIsRead) {
  const FeBodyData d = readCalculixFe(files(dofText()));
  EXPECT_EQ(d.numNodes(), 8);
  EXPECT_EQ(d.nodeIds[d.dofs[3].node], 12);
  EXPECT_EQ(d.dofs[5].direction, 2);
  EXPECT_EQ(d.stiffness.coeff(0, 1), 0.5);  // the upper triangle mirrored
  EXPECT_EQ(d.stiffness.coeff(1, 0), 0.5);
  EXPECT_EQ(d.nodeSets.at("top"), (std::vector<int>{4, 5, 6, 7}));  // generate 15..18
  EXPECT_EQ(d.elements.at(0).type, "C3D8R");
  // the .dof's order rules: equations of node 18 first
  std::string reversed;
  for (int n = 18; n >= 11; --n) {
    for (int k = 1; k <= 3; ++k) reversed += std::to_string(n) + "." + std::to_string(k) + "\n";
  }
  const FeBodyData r = readCalculixFe(files(reversed));
  EXPECT_EQ(r.nodeIds[r.dofs[0].node], 18);
  EXPECT_EQ(r.dofsOfNodes({7}), (std::vector<int>{0, 1, 2}));
}

TEST_F(CalculixFiles, MalformedOrUnknownDofEntries) {
  CalculixFeFiles f = files(dofText("12x3\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.dofs, "line 25", "'12x3'", "expected 'node.direction'"});
  f = files(dofText("12.3.1\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {"line 25", "expected 'node.direction'"});
  f = files(dofText("19.1\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.dofs, "line 25", "node 19 is not defined in", f.inp});
  f = files(dofText("12.4\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {"line 25", "direction 4", "expected 1, 2 or 3"});
  f = files(dofText("12.2\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {"line 25", "given twice (first on line 5)"});
  // a node's direction missing: matrices of a deck with *BOUNDARY
  std::string held = dofText();
  held.erase(0, held.find("12.1"));
  f = files(held);
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.dofs, "node 11 direction 1 has no equation", "*BOUNDARY"});
}

TEST_F(CalculixFiles, MatrixEntriesOutsideTheTriangleOrTheDofs) {
  CalculixFeFiles f = files(dofText(), matrixText(5.0, "2 1 0.5\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }),
                 {f.stiffness, "line 25", "entry (2, 1) is below the diagonal", "row <= column"});
  f = files(dofText(), matrixText(5.0), matrixText(2.0, "25 25 1.0\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }),
                 {f.mass, "line 25", "outside the 24 DOF of " + f.dofs, "expected row and column from 1 to 24"});
  f = files(dofText(), matrixText(5.0, "3 3 1.0\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.stiffness, "line 25", "given twice (first on line 3)"});
  f = files(dofText(), matrixText(5.0, "1 2\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {"line 25", "2 fields", "expected 'row column value'"});
  f = files(dofText(), matrixText(5.0, "1 2 0.5q\n"));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {"line 25", "'0.5q'", "expected a finite real number"});
  // a DOF without stiffness, a non-positive mass (feread::checkBodyData)
  f = files(dofText(), matrixText(5.0, "").substr(0, matrixText(5.0).find("24 24")));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.stiffness, "row 24 (node 18, direction z)"});
  f = files(dofText(), matrixText(5.0), matrixText(-1.0));
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.mass, "expected a positive mass"});
}

TEST_F(CalculixFiles, DeckStrictness) {
  CalculixFeFiles f = files();
  write("job.inp", "*NODE\n1, 0., 0., 0.\n*INCLUDE, INPUT=mesh.inp\n");
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.inp, "line 3", "*INCLUDE is not followed"});
  write("job.inp", "*NODE\n1, 0., 0.\n");
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.inp, "line 2", "expected 'label, x, y, z'"});
  write("job.inp", deck() +
                       "*ELEMENT, TYPE=C3D20R\n2, 11, 12, 13, 14, 15, 16, 17, 18, 11, 12, 13, 14, 15, 16, 17,\n"
                       "18, 11, 12, 19, 20\n");
  expectMentions(errorOf([&] { readCalculixFe(f); }), {f.inp, "line 17", "element 2 names node 19"});
  write("job.inp", "*NODE\n1, 0., 0., 0.\n*ELEMENT, TYPE=S8R\n1, 1, 1, 1, 1, 1, 1, 1, 1\n");
  expectMentions(errorOf([&] { readCalculixFe(f); }),
                 {f.inp, "line 3", "'S8R'", "is not read in a CalculiX deck", "expands beams and shells"});
}

namespace {

/// A .frd of two nodes and one DISP block (as ccx writes them, long format); the pieces
/// can be replaced to break it.
std::string frdText(const std::string& dataLine2 = " -1         7 4.00000E-01-5.00000E-01 6.00000E+00",
                    const std::string& end = " 9999\n", const std::string& count = "2") {
  return "    1C\n    1UUSER\n    2C                             2                                     1\n"
         " -1         5 0.00000E+00 0.00000E+00 0.00000E+00\n"
         " -1         7 1.00000E+00 0.00000E+00 0.00000E+00\n -3\n"
         "    1PMODE                         1\n"
         "  100CL  101 12.34567890" +
         std::string(12 - count.size(), ' ') + count +
         "                     2    1MODAL      1\n"
         " -4  DISP        4    1\n -5  D1          1    2    1    0\n -5  D2          1    2    2    0\n"
         " -5  D3          1    2    3    0\n -5  ALL         1    2    0    0    1ALL\n"
         " -1         5 1.00000E-01 2.00000E-01-3.00000E-01\n" +
         dataLine2 + "\n -3\n" + end;
}

}  // namespace

TEST_F(CalculixFiles, FrdIsReadStrictly) {
  const FrdResults r = readCalculixFrd(write("a.frd", frdText()));
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_EQ(r.steps[0].value, 12.3456789);
  EXPECT_EQ(r.steps[0].mode, 1);
  EXPECT_EQ(r.steps[0].analysis, "MODAL");
  EXPECT_EQ(r.nodes.at(7).x(), 1.0);
  EXPECT_EQ(r.steps[0].blocks.at("DISP").values.at(5), (std::vector<double>{0.1, 0.2, -0.3}));
  EXPECT_EQ(r.steps[0].blocks.at("DISP").values.at(7)[1], -0.5);  // fields without a blank between

  std::string p = write("b.frd", frdText(" -1         7 4.00000E-01-5.0000XE-01 6.00000E+00"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 15", "D2 of node 7", "'-5.0000XE-01'"});
  p = write("c.frd", frdText(" -1         9 4.00000E-01-5.00000E-01 6.00000E+00"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 15", "node 9", "node block (2C) lacks"});
  p = write("d.frd", frdText(" -1         7 4.00000E-01-5.00000E-01"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 15", "2 values; expected 3"});
  p = write("e.frd", frdText(" -1         5 4.00000E-01-5.00000E-01 6.00000E+00"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 15", "node 5 is given twice"});
  p = write("f.frd", frdText(" -1         7 4.00000E-01-5.00000E-01 6.00000E+00", ""));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "without '9999'"});
  p = write("g.frd", frdText(" -1         7 4.00000E-01-5.00000E-01 6.00000E+00", " 9999\n", "3"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 8", "announces 3 nodes, the block has 2"});
  p = write("h.frd", frdText(" -1         7 4.00000E-01-5.00000E-01 6.00000E+00 1.00000E+00"));
  expectMentions(errorOf([&] { readCalculixFrd(p); }), {p, "line 15", "more than the 3 values"});
}

TEST(CalculixModes, ClampedModesRefuseAFreeBodyAndBadArguments) {
  // a chain of three unit masses and two unit springs, not held: K singular
  SpMat K(3, 3), M(3, 3);
  K.insert(0, 0) = 1.0;
  K.insert(0, 1) = -1.0;
  K.insert(1, 0) = -1.0;
  K.insert(1, 1) = 2.0;
  K.insert(1, 2) = -1.0;
  K.insert(2, 1) = -1.0;
  K.insert(2, 2) = 1.0;
  for (int i = 0; i < 3; ++i) M.insert(i, i) = 1.0;
  try {
    clampedModes(K, M, {}, 1, "chain");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(clampedModes(K, M, {3}, 1, "chain"), InputError);
  EXPECT_THROW(clampedModes(K, M, {0, 0}, 1, "chain"), InputError);
  EXPECT_THROW(clampedModes(K, M, {0}, 2, "chain"), InputError);
}

// ----- spin stiffening from a prestressed export -----------------------------------


namespace {

/// The bar clamped at its root interface, 10 Craig-Bampton modes, spin-stiffened by ccx's
/// export of the 100 rad/s preload (jobs spin_matrices and spin_pre), as a scene.
nlohmann::json spinningBarScene() {
  return {{"dimension", 3},
          {"bodies",
           {{{"name", "bar"},
             {"type", "fe_body"},
             {"calculix", {{"job", "spin_matrices"}}},
             {"modes", 10},
             {"reduction", "craig_bampton"},
             {"reference", "root"},
             {"interfaces", {{{"name", "root"}, {"kind", "rigid"}, {"node_set", "FIX"}}}},
             {"spin_stiffening", {{"calculix", {{"job", "spin_pre"}}}, {"spin", {0, 0, 100}}}}}}}};
}

}  // namespace

TEST_F(CalculixBar, SpinStiffeningFromAPrestressedExportFollowsCcxAndSouthwell) {
  // The bar clamped at its root (a rigid interface, the Craig-Bampton reference), spinning
  // about z through the root's centre. Its stress stiffness comes from ccx's export of the
  // stiffness prestressed by a 100 rad/s spin (FeSpinStiffening), scaled by w^2:
  //  - at 50 rad/s the body's frequencies equal ccx's prestressed frequency analysis at
  //    50 rad/s to 1e-4 (ccx runs with NLGEOM: its stress stiffness is not exactly linear
  //    in w^2, by the strain of the preload, ~1e-4, times the stiffening's share of
  //    omega^2, a few %; the 10 fixed-interface modes' truncation is below that);
  //  - the Southwell coefficients (omega^2 - omega0^2) / w^2 of the first bending pair
  //    equal the uniform cantilever's, 1.193 out of the plane of rotation and 1.193 - 1 in
  //    it (the spin softening, from the S_kl) to 0.02 (solid against Euler-Bernoulli beam
  //    at L / h = 10; without the stiffening the first would be ~0 and the test fails).
  const FeBodyData d = readCalculixFe(CalculixFeFiles::ofJob(job("spin_matrices")));
  FeBodyOptions o;
  o.modes = 10;
  o.interfaces.push_back({"root", d.nodeSets.at("FIX"), FeInterfaceKind::Rigid});
  o.reduction = FeReduction::CraigBampton;
  o.reference = "root";
  o.spinStiffening.preloadedStiffness =
      readCalculixPreloadedStiffness(CalculixFeFiles::ofJob(job("spin_pre")), d, o.spinStiffening.heldDofs);
  o.spinStiffening.spin = Vec3(0.0, 0.0, 100.0);
  EXPECT_EQ(o.spinStiffening.heldDofs.size(), 3 * d.nodeSets.at("FIX").size());
  const FeBodyModel model(d, o, "bar");
  const VecX f50 = fetest::spinningFrequencies(model.invariants(), 50.0);
  std::vector<double> ccx;
  for (const FrdStep& st : readCalculixFrd(job("spin_50.frd")).steps) {
    if (st.type == 2) ccx.push_back(st.value);
  }
  ASSERT_GE(ccx.size(), 4u);
  double worst = 0.0;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(f50[i] / ccx[i], 1.0, 1e-4) << "mode " << i + 1;
    worst = std::max(worst, std::abs(f50[i] / ccx[i] - 1.0));
  }
  const VecX f0 = fetest::spinningFrequencies(model.invariants(), 0.0);
  const double southwell = fetest::kSouthwellCantilever;
  const auto coefficient = [&](int i) { return fetest::southwellCoefficient(f50[i], f0[i], 50.0); };
  EXPECT_NEAR(coefficient(0), southwell - 1.0, 0.02);  // in the plane of rotation: softened by w^2
  EXPECT_NEAR(coefficient(1), southwell, 0.02);        // out of it
  std::printf("[ figures ] spin stiffening (ccx prestressed export at 100 rad/s, scaled to 50): frequencies vs ccx "
              "worst %.1e; Southwell coefficients %.4f (in plane, beam %.4f), %.4f (out of plane, beam %.4f)\n",
              worst, coefficient(0), southwell - 1.0, coefficient(1), southwell);
  // the scene key gives the same body
  const nlohmann::json scene = spinningBarScene();
  const Scene sc = parseSceneText(scene.dump(), job("scene.json"));
  const auto& body = dynamic_cast<const FfrBody3d&>(sc.system.body(BodyIndex(1)));
  EXPECT_EQ(MatX(body.invariants().spinStiffness[2][2] - model.invariants().spinStiffness[2][2]).norm(), 0.0);
  // without Craig-Bampton (no held hub): refused, naming the key
  nlohmann::json free = scene;
  free["bodies"][0].erase("reduction");
  free["bodies"][0].erase("reference");
  fetest::expectMentions(fetest::errorOf([&] { parseSceneText(free.dump(), job("scene.json")); }),
                         {"spin stiffening needs \"reduction\": \"craig_bampton\""});
}

TEST_F(CalculixBar, SpinStiffeningFromAnAbaqusMatrixInputExportIsTheSame) {
  // Abaqus writes the prestressed stiffness of a perturbation step (after the preload step)
  // in FORMAT=MATRIX INPUT: "node, DOF, node, DOF, value", the held DOF absent. Abaqus is
  // not on this machine, so ccx's prestressed export is written in that format here (the
  // upper triangle, 17 digits, node labels) and read back: the same held DOF, the same
  // matrix exactly, the same spin stiffness through the scene key "abaqus". This checks the
  // Abaqus path's reading and mapping; the physics is the test above.
  const FeBodyData d = readCalculixFe(CalculixFeFiles::ofJob(job("spin_matrices")));
  std::vector<int> heldCcx, heldAbaqus;
  const SpMat K = readCalculixPreloadedStiffness(CalculixFeFiles::ofJob(job("spin_pre")), d, heldCcx);
  const std::string path = job("spin_pre_abaqus.mtx");
  {
    std::ofstream out(path);
    out << "** the prestressed stiffness, Abaqus MATRIX INPUT format\n";
    char line[160];
    for (int j = 0; j < K.outerSize(); ++j) {
      for (SpMat::InnerIterator it(K, j); it; ++it) {
        if (it.row() > j) continue;
        const FeDof &a = d.dofs[it.row()], &b = d.dofs[j];
        std::snprintf(line, sizeof line, "%d, %d, %d, %d, %.17g\n", d.nodeIds[a.node], a.direction + 1,
                      d.nodeIds[b.node], b.direction + 1, it.value());
        out << line;
      }
    }
  }
  const SpMat Ka = readAbaqusPreloadedStiffness(path, d, heldAbaqus);
  EXPECT_EQ(heldAbaqus, heldCcx);
  EXPECT_EQ(MatX(Ka - K).cwiseAbs().maxCoeff(), 0.0);
  const nlohmann::json scene = spinningBarScene();
  nlohmann::json abaqus = scene;
  abaqus["bodies"][0]["spin_stiffening"] = {{"abaqus", {{"stiffness", "spin_pre_abaqus.mtx"}}}, {"spin", {0, 0, 100}}};
  const Scene a = parseSceneText(scene.dump(), job("scene.json")), b = parseSceneText(abaqus.dump(), job("scene.json"));
  const auto& ba = dynamic_cast<const FfrBody3d&>(a.system.body(BodyIndex(1)));
  const auto& bb = dynamic_cast<const FfrBody3d&>(b.system.body(BodyIndex(1)));
  EXPECT_EQ(MatX(ba.invariants().spinStiffness[2][2] - bb.invariants().spinStiffness[2][2]).cwiseAbs().maxCoeff(), 0.0);
  // both files, or a DOF the body does not have: refused, named
  nlohmann::json both = abaqus;
  both["bodies"][0]["spin_stiffening"]["calculix"] = {{"job", "spin_pre"}};
  fetest::expectMentions(fetest::errorOf([&] { parseSceneText(both.dump(), job("scene.json")); }),
                         {"spin_stiffening", "give exactly one of \"calculix\"", "or \"abaqus\""});
  const std::string bad = job("spin_pre_bad.mtx");
  std::ofstream(bad) << "1, 1, 1, 1, 1.0\n1, 4, 1, 4, 1.0\n";
  fetest::expectMentions(fetest::errorOf([&] { readAbaqusPreloadedStiffness(bad, d, heldAbaqus); }),
                         {bad, "line 2", "node 1, DOF 4 is not a DOF of"});
}
