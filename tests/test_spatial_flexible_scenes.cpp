// Spatial flexible bodies in scene files ("dimension": 3, "type": "flexible" and
// "flexible_invariants"): the reader builds the body the C++ API builds, given invariants
// written from a beam model reproduce the beam-mesh body's run, the deflection output's
// section forces satisfy the cantilever's equilibrium, and bad input names the key.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "analysis/linearization.hpp"
#include "scene/scene.hpp"
#include "test_support.hpp"

using namespace flexmbd;
using namespace flexmbd::testsupport;
using nlohmann::json;

namespace {

constexpr double kLength = 0.8, kWidth = 0.03, kHeight = 0.02, kE = 2e9, kNu = 0.3, kRho = 2700.0;

/// A flexible beam (4 elements, clamped at node 0) hanging from a spherical joint at
/// node 0, tilted and spinning, under gravity: every inertia invariant takes part.
json pendulumScene() {
  return json::parse(R"({
    "name": "spatial flexible pendulum", "dimension": 3, "gravity": [0, 0, -9.81],
    "bodies": [{"name": "beam", "type": "flexible",
                "section": {"width": 0.03, "height": 0.02, "youngs_modulus": 2e9, "poisson_ratio": 0.3,
                            "density": 2700, "damping": 1e-4},
                "beam": {"length": 0.8, "elements": 4}, "y_axis": [0, 1, 0.2], "reference": {"type": "clamped"},
                "orientation": {"axis": [0, 1, 0], "angle": 0.4}, "angular_velocity": [0.5, 1.0, 2.0]}],
    "joints": [{"name": "ball", "type": "spherical", "bodies": ["ground", "beam"],
                "frames": [{"point": [0, 0, 0]}, {"point": [0, 0, 0]}]}],
    "outputs": [{"type": "deflection", "name": "mid", "body": "beam", "point": [0.4, 0, 0]}, {"type": "energy"}],
    "solver": {"t_end": 0.05, "output_step": 0.005, "rtol": 1e-8, "atol": 1e-10}
  })");
}

json matrixJson(const MatX& m) {
  json rows = json::array();
  for (int i = 0; i < m.rows(); ++i) {
    json row = json::array();
    for (int j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

json vectorJson(const VecX& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

/// The "invariants" object of a body's invariants (all points included).
json invariantsJson(const FfrInvariants3d& inv) {
  json j;
  j["mass"] = inv.mass;
  j["first_moment"] = vectorJson(inv.firstMoment);
  j["second_moment"] = matrixJson(inv.secondMoment);
  j["m_ff"] = matrixJson(MatX(inv.mff));
  j["s_bar"] = matrixJson(inv.sBar);
  const char* axis = "xyz";
  for (int k = 0; k < 3; ++k) {
    j[std::string("position_shape_") + axis[k]] = matrixJson(inv.positionShape[k]);
    for (int l = k; l < 3; ++l) j[std::string("s_") + axis[k] + axis[l]] = matrixJson(MatX(inv.sKL[k][l]));
  }
  for (int k = 0; k < 3; ++k) {  // optional: the sections' second-order rotation
    for (int l = k; l < 3; ++l) {
      if (inv.rKL[k][l].size() != 0) j[std::string("r_") + axis[k] + axis[l]] = matrixJson(MatX(inv.rKL[k][l]));
    }
    if (inv.hI[k].size() != 0) j[std::string("h_") + axis[k]] = matrixJson(MatX(inv.hI[k]));
  }
  j["k_ff"] = matrixJson(MatX(inv.kff));
  j["d_ff"] = matrixJson(MatX(inv.dff));
  json pts = json::array();
  for (const FfrPoint3d& p : inv.points) {
    pts.push_back({{"position", vectorJson(p.position)},
                   {"shape", matrixJson(p.shape)},
                   {"rotation_shape", matrixJson(p.rotationShape)}});
  }
  j["points"] = pts;
  return j;
}

/// Every output row (t, q) of a scene's run.
std::vector<VecX> runStates(Scene& scene) {
  std::vector<VecX> rows;
  scene.solver.progress = false;
  const SimulationSummary s = simulate(scene.system, scene.solver, [&](const OutputSample& o) {
    VecX row(1 + o.q.size());
    row << o.t, o.q;
    rows.push_back(row);
  });
  EXPECT_TRUE(s.ok) << s.message;
  return rows;
}

const FfrBody3d& flexBody(const Scene& scene) {
  return dynamic_cast<const FfrBody3d&>(scene.system.body(scene.system.findBody("beam")));
}

}  // namespace

TEST(SpatialFlexibleScene, TheReaderBuildsTheBodyOfTheApi) {
  // The scene's section keys (width, height, poisson_ratio) and mesh keys give the model
  // the C++ API builds from rectangularSection3d and BeamMesh3d::straight: equal invariants
  // (the same arithmetic: exactly equal but for G = E / (2 (1 + nu)) evaluated once; 1e-14).
  const Scene scene = parseScene(pendulumScene());
  const FfrBody3d& body = flexBody(scene);
  ASSERT_NE(body.model(), nullptr);
  const BeamSection3d s = rectangularSection3d(kWidth, kHeight, kE, kE / (2.0 * (1.0 + kNu)), kRho, 1e-4);
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::Clamped;
  const FfrBeamModel3d api(BeamMesh3d::straight(kLength, 4, s, Vec3::Zero(), Vec3(0, 1, 0.2)), o, "api");
  const FfrInvariants3d &a = body.invariants(), &b = api.invariants();
  ASSERT_EQ(a.numElastic(), 24);
  EXPECT_NEAR(a.mass, kRho * kWidth * kHeight * kLength, 1e-14);
  expectMatrixNear(MatX(a.kff), MatX(b.kff), 1e-14, "K_ff", MatX(b.kff).cwiseAbs().maxCoeff());
  expectMatrixNear(MatX(a.mff), MatX(b.mff), 1e-14, "m_ff", MatX(b.mff).cwiseAbs().maxCoeff());
  expectMatrixNear(MatX(a.dff), MatX(b.dff), 1e-14, "D_ff", MatX(b.dff).cwiseAbs().maxCoeff());
  // frame state: origin at the joint, orientation 0.4 rad about y, body-axes spin
  const VecX q0 = body.initialCoordinates(), v0 = body.initialVelocities();
  EXPECT_NEAR(q0[3], std::cos(0.2), 1e-15);
  EXPECT_NEAR(q0[5], std::sin(0.2), 1e-15);
  EXPECT_EQ(v0.segment<3>(3), Vec3(0.5, 1.0, 2.0));
  // columns: 9 deflection columns, 3 energy columns
  ASSERT_EQ(scene.outputs.size(), 2u);
  EXPECT_EQ(scene.outputs[0].columnNames(),
            (std::vector<std::string>{"mid.ux", "mid.uy", "mid.uz", "mid.N", "mid.Qy", "mid.Qz", "mid.Mx", "mid.My",
                                      "mid.Mz"}));
}

TEST(SpatialFlexibleScene, GivenInvariantsReproduceTheBeamMeshBody) {
  // The invariants of the scene's beam model written as a "flexible_invariants" body
  // (17 significant digits) run the same motion: the bodies differ only in the order of
  // summation of K_ff q_f, so the two runs agree to the integrator's round-off
  // amplification; bound 1e-9 of the coordinates' scale (the runs take the same steps).
  // Euler-Bernoulli, Rayleigh and Timoshenko: the optional r_kl and h_i keys carry the
  // sections' second-order rotation.
  for (const char* theory : {"euler_bernoulli", "rayleigh", "timoshenko"}) {
  SCOPED_TRACE(theory);
  json meshScene = pendulumScene();
  meshScene["bodies"][0]["beam_theory"] = theory;
  Scene mesh = parseScene(meshScene);
  json j = pendulumScene();
  json& b = j["bodies"][0];
  const FfrInvariants3d& inv = flexBody(mesh).invariants();
  json given = {{"name", "beam"},
                {"type", "flexible_invariants"},
                {"orientation", b["orientation"]},
                {"angular_velocity", b["angular_velocity"]},
                {"invariants", invariantsJson(inv)}};
  b = given;
  j["outputs"] = json::array({json{{"type", "energy"}}});
  Scene invariants = parseScene(j);
  const std::vector<VecX> a = runStates(mesh), c = runStates(invariants);
  ASSERT_EQ(a.size(), c.size());
  ASSERT_GT(a.size(), 5u);
  double worst = 0.0;
  for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, (a[k] - c[k]).cwiseAbs().maxCoeff());
  EXPECT_LE(worst, 1e-9);
  // the motion is not trivial: the frame turned and the beam bent
  EXPECT_GT((a.back() - a.front()).segment(4, 4).norm(), 1e-2);
  EXPECT_GT(a.back().tail(24).cwiseAbs().maxCoeff(), 1e-7);
  std::printf("[ figures ] given invariants vs beam mesh (%s), %zu rows: largest difference %.2e\n", theory,
              a.size(), worst);
  }
}

TEST(SpatialFlexibleScene, DeflectionOutputMatchesTheCantileverStatics) {
  // A cantilever (clamped at node 0, body frame = world frame) deformed by the static
  // response to a tip force F (elastic_coordinates = K_ff^-1 f): the deflection output at
  // x has the section forces of a tip-loaded cantilever in BeamSectionForces3d's
  // convention (element axes = body axes here): N = Fx, Qy = Fy, Qz = Fz,
  // Mz = EIz v'' = Fy (L - x), My = -EIy w'' = -Fz (L - x), Mx = 0; the
  // Euler-Bernoulli element is exact for this load, so the shear forces and end
  // moments agree to the round-off of the solve (1e-9 relative to F L).
  const Vec3 F(300.0, -2.0, 1.5);
  const double x = 0.3;  // between nodes: xi inside element 1
  json j = pendulumScene();
  j["bodies"][0].erase("orientation");
  j["bodies"][0].erase("angular_velocity");
  j["bodies"][0]["y_axis"] = {0, 1, 0};
  j["outputs"] = json::array({json{{"type", "deflection"}, {"name", "p"}, {"body", "beam"}, {"point", {x, 0, 0}}}});
  const Scene s0 = parseScene(j);
  const FfrBody3d& b0 = flexBody(s0);
  const FfrInvariants3d& inv = b0.invariants();
  const int nf = inv.numElastic();
  VecX f = VecX::Zero(nf);
  f.segment<3>(nf - 6) = F;  // tip node translations: the last node's first three coordinates
  const VecX qf = MatX(inv.kff).ldlt().solve(f);
  j["bodies"][0]["elastic_coordinates"] = vectorJson(qf);
  const Scene s = parseScene(j);
  const VecX q = s.system.initialCoordinates(), v = s.system.initialVelocities();
  const std::vector<double> out = s.outputs[0].evaluate(s.system, q, v);
  ASSERT_EQ(out.size(), 9u);
  const double arm = kLength - x, scale = F.norm() * kLength;
  EXPECT_NEAR(out[3], F.x(), 1e-9 * scale) << "N";
  EXPECT_NEAR(out[4], F.y(), 1e-9 * scale) << "Qy";
  EXPECT_NEAR(out[5], F.z(), 1e-9 * scale) << "Qz";
  EXPECT_NEAR(out[6], 0.0, 1e-9 * scale) << "Mx";
  EXPECT_NEAR(out[7], -F.z() * arm, 1e-9 * scale) << "My";
  EXPECT_NEAR(out[8], F.y() * arm, 1e-9 * scale) << "Mz";
  // the displacement at x: the cantilever's closed form w(x) = F x^2 (3 L - x) / (6 E I)
  const BeamSection3d sec = rectangularSection3d(kWidth, kHeight, kE, kE / (2.0 * (1.0 + kNu)), kRho, 0.0);
  const double wy = F.y() * x * x * (3 * kLength - x) / (6 * kE * sec.inertiaZ);
  const double wz = F.z() * x * x * (3 * kLength - x) / (6 * kE * sec.inertiaY);
  EXPECT_NEAR(out[1], wy, 1e-9 * std::abs(wy)) << "uy";
  EXPECT_NEAR(out[2], wz, 1e-9 * std::abs(wz)) << "uz";
  EXPECT_NEAR(out[0], F.x() * x / (kE * sec.area), 1e-9 * F.x() * x / (kE * sec.area)) << "ux";
}

TEST(SpatialFlexibleScene, BadInputNamesTheBodyAndTheKey) {
  auto expectError = [](const std::function<void(json&)>& change, const std::vector<std::string>& fragments) {
    json j = pendulumScene();
    change(j);
    expectInputError([&] { parseScene(j); }, fragments);
  };
  expectError([](json& j) { j["bodies"][0]["section"]["shear_modulus"] = 8e8; },
              {"bodies[0] (\"beam\")", "section", "exactly one of \"shear_modulus\" or \"poisson_ratio\""});
  expectError([](json& j) { j["bodies"][0]["section"]["poisson_ratio"] = 0.7; }, {"poisson_ratio", "(-1, 0.5)"});
  expectError([](json& j) { j["bodies"][0]["section"]["inertia"] = 1.0; }, {"section", "inertia"});
  expectError([](json& j) { j["bodies"][0]["y_axis"] = {1, 0, 0}; }, {"beam"});
  expectError([](json& j) { j["bodies"][0]["elastic_coordinates"] = {0.0, 1.0}; },
              {"bodies[0] (\"beam\")", "elastic_coordinates", "24 numbers", "got 2"});
  expectError([](json& j) { j["bodies"][0]["reference"] = {{"type", "hinged"}}; }, {"reference", "hinged"});
  expectError([](json& j) { j["bodies"][0]["nodes"] = {{0, 0, 0}, {1, 0, 0}}; }, {"either \"beam\" or \"nodes\""});
  expectError([](json& j) { j["outputs"][0]["point"] = {0.4, 0.1, 0}; }, {"outputs[0]", "not on the axis"});
  expectError([](json& j) { j["joints"][0]["frames"][1]["point"] = {0.3, 0, 0}; }, {"ball", "no node at"});
  // given invariants: sizes and symmetry named
  Scene mesh = parseScene(pendulumScene());
  const json inv = invariantsJson(flexBody(mesh).invariants());
  auto given = [&](const std::function<void(json&)>& change) {
    json j = pendulumScene();
    j["bodies"][0] = {{"name", "beam"}, {"type", "flexible_invariants"}, {"invariants", inv}};
    j["outputs"] = json::array();
    change(j["bodies"][0]["invariants"]);
    return j;
  };
  expectInputError([&] { parseScene(given([](json& i) { i["s_xy"] = json::array({json::array({1.0})}); })); },
                   {"invariants", "s_xy", "24 x 24", "got 1 x 1"});
  expectInputError([&] { parseScene(given([](json& i) { i["s_yy"][0][1] = 5.0; })); }, {"beam", "s_yy", "symmetric"});
  expectInputError([&] { parseScene(given([](json& i) { i.erase("position_shape_y"); })); }, {"position_shape_y"});
  expectInputError([&] { parseScene(given([](json& i) { i["r_xy"] = json::array({json::array({1.0})}); })); },
                   {"invariants", "r_xy", "24 x 24", "got 1 x 1"});
  expectInputError([&] { parseScene(given([](json& i) { i["h_z"] = i["s_xy"]; })); }, {"beam", "h_z", "symmetric"});
  expectInputError([&] { parseScene(given([](json& i) { i["points"][0]["rotation_shape"] = json::array(); })); },
                   {"points[0]", "rotation_shape"});
}

TEST(SpatialFlexibleScene, ExampleElasticSliderCrankFollowsTheRigidClosedFormWithinTheRodsStrain) {
  // examples/spatial_slider_crank_elastic.json, the first 0.1 s (half a crank turn): the
  // slider stays within 2e-4 m of the rigid closed form s(theta) of
  // tests/test_spatial_scenes.cpp (the rod's strain: axial N L / EA ~ 6e-5 m at the peak
  // force of ~570 N, plus the shortening by bending), and the rod does bend (> 1e-5 m).
  Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json");
  scene.solver.tEnd = 0.1;
  scene.solver.progress = false;
  const System& sys = scene.system;
  const double r = 0.15, L = 0.45, h = 0.1, w = 10 * M_PI, th0 = 0.3;
  const auto s = [&](double th) { return r * std::cos(th) + std::sqrt(L * L - h * h - r * r * std::sin(th) * std::sin(th)); };
  const int xs = sys.coordinateOffset(sys.findBody("slider"));
  // the slider body's frame is its centre of mass, 0 in x from the universal joint's point
  double worst = 0.0, bend = 0.0;
  const SimulationSummary sum = simulate(sys, scene.solver, [&](const OutputSample& o) {
    worst = std::max(worst, std::abs(o.q[xs] - s(th0 + w * o.t)));
    const std::vector<double> d = scene.outputs[1].evaluate(sys, o.q, o.v);
    bend = std::max(bend, std::hypot(d[1], d[2]));
  });
  ASSERT_TRUE(sum.ok) << sum.message;
  EXPECT_LT(worst, 2e-4);
  EXPECT_GT(bend, 1e-5);
  std::printf("[ figures ] elastic spatial slider crank, 0.1 s: slider vs rigid closed form %.2e m, rod midpoint "
              "deflection up to %.2e m, %ld steps\n",
              worst, bend, static_cast<long>(sum.stats.steps));
}

TEST(SpatialFlexibleScene, ModesOfAClampedSceneBeamAreItsModelsAndTheContinuumFrequencies) {
  // A cantilever from a scene (8 elements, clamped node 0, fixed joint to the ground),
  // linearised about rest: its lowest modes are the beam model's natural frequencies
  // (the same K_ff and m_ff: 1e-9 relative) and the continuum's 3.516 / L^2 sqrt(EI / rho A)
  // in each bending plane (cubic elements: h^4 convergence, 8 elements ~1e-5; bound 1e-4).
  json j = pendulumScene();
  j["bodies"][0].erase("orientation");
  j["bodies"][0].erase("angular_velocity");
  j["bodies"][0]["y_axis"] = {0, 1, 0};
  j["bodies"][0]["beam"]["elements"] = 8;
  j["joints"][0]["type"] = "fixed";
  j["gravity"] = {0, 0, 0};
  j["outputs"] = json::array();
  const Scene s = parseScene(j);
  const System& sys = s.system;
  const std::vector<Mode> modes =
      modesAbout(sys, referenceStateAt(sys, 0.0, sys.initialCoordinates(), sys.initialVelocities()));
  const VecX w = flexBody(s).model()->naturalFrequencies();
  ASSERT_GE(modes.size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(modes[k].omega, w[k], 1e-9 * w[k]) << "mode " << k + 1;
  const BeamSection3d sec = rectangularSection3d(kWidth, kHeight, kE, kE / (2.0 * (1.0 + kNu)), kRho, 0.0);
  const double c = 3.516015 / (kLength * kLength), rhoA = kRho * sec.area;
  const double wz = c * std::sqrt(kE * sec.inertiaY / rhoA), wy = c * std::sqrt(kE * sec.inertiaZ / rhoA);
  EXPECT_NEAR(modes[0].omega, std::min(wy, wz), 1e-4 * std::min(wy, wz));
  EXPECT_NEAR(modes[1].omega, std::max(wy, wz), 1e-4 * std::max(wy, wz));
  std::printf("[ figures ] scene cantilever modes %.6f, %.6f rad/s; continuum %.6f, %.6f\n", modes[0].omega,
              modes[1].omega, std::min(wy, wz), std::max(wy, wz));
}

TEST(SpatialFlexibleScene, CraigBamptonKeysGiveTheStaticTipResponseExactly) {
  // The scene cantilever reduced by Craig-Bampton at its tip node (6 constraint modes, 2
  // fixed-interface modes): the static response to a tip force lies in the constraint
  // modes, so the deflection output at x (section forces, displacement) equals the nodal
  // model's to the round-off of the two solves (1e-9 relative).
  const Vec3 F(300.0, -2.0, 1.5);
  json j = pendulumScene();
  j["bodies"][0].erase("orientation");
  j["bodies"][0].erase("angular_velocity");
  j["bodies"][0]["y_axis"] = {0, 1, 0};
  j["outputs"] = json::array({json{{"type", "deflection"}, {"name", "p"}, {"body", "beam"}, {"point", {0.3, 0, 0}}}});
  auto deflection = [&](json scene) {
    const Scene s0 = parseScene(scene);
    const FfrInvariants3d& inv = flexBody(s0).invariants();
    const int nf = inv.numElastic();
    // the tip force as generalised forces: f = N_tip^T F (the tip node's shape)
    const FfrPoint3d& tip = inv.points.back();
    const VecX f = tip.shape.transpose() * F;
    const VecX qf = MatX(inv.kff).ldlt().solve(f);
    scene["bodies"][0]["elastic_coordinates"] = vectorJson(qf);
    const Scene s = parseScene(scene);
    EXPECT_EQ(flexBody(s).numElastic(), nf);
    return s.outputs[0].evaluate(s.system, s.system.initialCoordinates(), s.system.initialVelocities());
  };
  const std::vector<double> nodal = deflection(j);
  j["bodies"][0]["reduction"] = "craig_bampton";
  j["bodies"][0]["interface_nodes"] = {4};
  j["bodies"][0]["modes"] = 2;
  const std::vector<double> cb = deflection(j);
  ASSERT_EQ(cb.size(), nodal.size());
  const double forceScale = F.norm() * kLength;
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(cb[k], nodal[k], 1e-9 * std::abs(nodal[2]) + 1e-15) << "u " << k;
  for (size_t k = 3; k < 9; ++k) EXPECT_NEAR(cb[k], nodal[k], 1e-9 * forceScale) << "section force " << k;
  EXPECT_NEAR(cb[3], F.x(), 1e-9 * forceScale) << "N";
}

TEST(SpatialFlexibleScene, BeamTheoryKeyGivesTheRayleighAndTimoshenkoModelsOfTheApi) {
  // "beam_theory": "rayleigh" / "timoshenko" build FfrBeamOptions3d::theory: the mass
  // matrix, stiffness and the sections' second-order invariants of the API model (1e-14,
  // as above; the rectangle's shear factors are Cowper's in both), and a mass matrix that
  // differs from the Euler-Bernoulli one by the rotary inertia.
  for (const auto& [key, theory] : {std::pair<const char*, BeamTheory>{"rayleigh", BeamTheory::Rayleigh},
                                    std::pair<const char*, BeamTheory>{"timoshenko", BeamTheory::Timoshenko}}) {
    SCOPED_TRACE(key);
    json j = pendulumScene();
    j["bodies"][0]["beam_theory"] = key;
    const Scene scene = parseScene(j);
    const BeamSection3d s = rectangularSection3d(kWidth, kHeight, kE, kE / (2.0 * (1.0 + kNu)), kRho, 1e-4);
    FfrBeamOptions3d o;
    o.reference.type = ReferenceConditions3d::Type::Clamped;
    o.theory = theory;
    const FfrBeamModel3d api(BeamMesh3d::straight(kLength, 4, s, Vec3::Zero(), Vec3(0, 1, 0.2)), o, "api");
    const FfrInvariants3d &a = flexBody(scene).invariants(), &b = api.invariants();
    const double mscale = MatX(b.mff).cwiseAbs().maxCoeff(), kscale = MatX(b.kff).cwiseAbs().maxCoeff();
    expectMatrixNear(MatX(a.mff), MatX(b.mff), 1e-14, "m_ff", mscale);
    expectMatrixNear(MatX(a.kff), MatX(b.kff), 1e-14, "K_ff", kscale);
    for (int i = 0; i < 3; ++i) {
      expectMatrixNear(MatX(a.hI[i]), MatX(b.hI[i]), 1e-14, "H_i", mscale);
      for (int l = 0; l < 3; ++l) expectMatrixNear(MatX(a.rKL[i][l]), MatX(b.rKL[i][l]), 1e-14, "R_kl", mscale);
    }
    const Scene ebScene = parseScene(pendulumScene());
    const FfrInvariants3d& eb = flexBody(ebScene).invariants();
    EXPECT_GT(MatX(a.mff - eb.mff).cwiseAbs().maxCoeff(), 1e-6 * mscale);  // the rotary inertia
  }
  json j = pendulumScene();
  j["bodies"][0]["beam_theory"] = "shear";
  expectInputError([&] { parseScene(j); }, {"bodies[0] (\"beam\")", "beam_theory",
                                            "\"euler_bernoulli\", \"rayleigh\" or \"timoshenko\"", "shear"});
  // a section given by its constants has no shear factor unless the scene gives one
  json& sec = j["bodies"][0]["section"];
  const BeamSection3d s = rectangularSection3d(kWidth, kHeight, kE, kE / (2.0 * (1.0 + kNu)), kRho);
  sec.erase("width");
  sec.erase("height");
  sec["area"] = s.area;
  sec["inertia_y"] = s.inertiaY;
  sec["inertia_z"] = s.inertiaZ;
  sec["torsion_constant"] = s.torsionConstant;
  j["bodies"][0]["beam_theory"] = "timoshenko";
  expectInputError([&] { parseScene(j); }, {"beam", "Timoshenko", "shear_factor_y"});
  sec["shear_factor_y"] = 0.85;
  sec["shear_factor_z"] = 0.85;
  EXPECT_NO_THROW(parseScene(j));
  sec["shear_factor_z"] = -1.0;
  expectInputError([&] { parseScene(j); }, {"shear_factor_z", "must be > 0"});
}
