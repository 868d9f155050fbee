// Forward sensitivities of the elastic and spatial models against central differences of
// whole runs ("Validation"; docs/sensitivities.md, "Accuracy"): the elastic
// slider crank with a nodal rod (the rod's Young's modulus and section height, the slider's
// mass) and with a modal rod (the crank's speed), outputs the rod's midpoint deflection and
// the slider's position; the spatial slider crank (the slider's mass, the rod's attachment
// point; the motor's torque, a reaction, the slider's position).
//
// How each tolerance is made: the difference of whole runs at p (1 +- d) differs from the
// exact derivative by (1) its truncation error, O(d^2) ~ 1e-8 here, and (2) the runs'
// global errors e, which do not cancel between the two runs (other step sequences): at most
// 2 e / (2 d |p|) in the quotient, about rtol / d of the derivative's scale. Halving d (1e-4
// to 5e-5) moves the quotients by 3e-8 .. 9e-6 of the largest, not by 3/4 of a truncation
// error: (2) dominates. The sensitivity itself is integrated with the run's tolerances. The
// tolerance is (1) + (2) with a margin, relative to the largest |derivative| of the output
// over the run; the measured figures are in docs/sensitivities.md.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "sensitivity_test_support.hpp"

namespace {

/// One comparison: parameter (its index in the run and its path), output column, and the
/// tolerance relative to the largest |derivative| of the column over the run.
struct Check {
  std::size_t parameter;
  std::string path, column;
  double relativeTolerance;
};

/// Runs `scene` with sensitivities to `paths`, and for every check the central difference
/// of whole runs at relative step `relStep` (one pair of runs per parameter); prints and
/// asserts worst |sensitivity - difference| < tolerance x largest |difference|.
void checkAgainstWholeRuns(const std::string& label, const json& scene, const std::vector<std::string>& paths,
                           const std::vector<Check>& checks, double relStep) {
  const SensitivityRun run = runWithSensitivities(scene, paths);
  ASSERT_TRUE(run.summary.ok) << run.summary.message;
  std::vector<std::vector<std::vector<double>>> fd(paths.size());
  for (const Check& c : checks) {
    if (fd[c.parameter].empty()) fd[c.parameter] = wholeRunDifference(scene, c.path, relStep);
    const auto [worst, largest] = compareWithDifference(run, c.parameter, fd[c.parameter], c.column);
    std::printf("%s d%s/d%s: worst %.3g of the largest %.3g (tolerance %.3g)\n", label.c_str(), c.column.c_str(),
                c.path.c_str(), worst / largest, largest, c.relativeTolerance);
    EXPECT_GT(largest, 0.0) << c.column << " / " << c.path << ": the output does not depend on the parameter";
    EXPECT_LT(worst, c.relativeTolerance * largest) << c.column << " / " << c.path << ": largest " << largest;
  }
}

/// The elastic slider crank of examples/slider_crank_elastic.json (steel rod 0.30 m, 8 x 8
/// mm, crank 150 rad/s) with `elements` nodal beam elements, or `modes` normal modes of
/// them, over `tEnd` (the rod's first bending period is about 5 ms), tolerances rtol, atol.
json elasticSliderCrank(int elements, int modes, double tEnd, double rtol, double atol) {
  json j = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json"));
  json& rod = j["bodies"][1];
  EXPECT_EQ(rod["name"], "rod");
  rod["beam"]["elements"] = elements;
  if (modes > 0) rod["modes"] = modes;
  j["solver"]["rtol"] = rtol;
  j["solver"]["atol"] = atol;
  j["solver"]["t_end"] = tEnd;
  j["solver"]["output_step"] = tEnd / 20;
  return j;
}

TEST(SensitivitiesElastic, NodalRodMatchesWholeRuns) {
  // 2 nodal elements, 5 ms (a bending period), rtol 1e-9 (0.35 s, 10000 steps a run). The
  // rod's Young's modulus and section height, the slider's mass; the midpoint deflection
  // (~2 mm) and the slider's position, which the rod's axial strain moves.
  const json scene = elasticSliderCrank(2, 0, 0.005, 1e-9, 1e-11);
  const std::vector<std::string> paths = {"bodies[1].section.youngs_modulus", "bodies[1].section.height",
                                          "bodies[2].mass"};
  // Whole runs at p (1 +- 1e-4): truncation d^2 |c_ppp| p^2 / 6 ~ 1e-8 relative; the runs'
  // global errors at rtol 1e-9 (~1e-9 of the state) give e / (d |p| |dc/dp|) ~ 1e-5 of the
  // derivative; the sensitivity's own error is of the state's order. 1e-4 holds them.
  const double kTolerance = 1e-4;
  std::vector<Check> checks;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    checks.push_back({i, paths[i], "mid.uy", kTolerance});
    checks.push_back({i, paths[i], "slider.x", kTolerance});
  }
  checkAgainstWholeRuns("nodal rod", scene, paths, checks, 1e-4);
}

/// The crank's speed of an elastic slider crank: the deflection and the slider against
/// whole runs at p (1 +- 1e-4).
void checkCrankSpeed(const std::string& label, const json& scene, double tolerance) {
  const std::string speed = "drivers[0].law.speed";
  checkAgainstWholeRuns(label, scene, {speed}, {{0, speed, "mid.uy", tolerance}, {0, speed, "slider.x", tolerance}},
                        1e-4);
}

TEST(SensitivitiesElastic, NodalRodCrankSpeedAtTightTolerances) {
  // The crank's speed of the nodal rod (2 elements, 5 ms) at rtol 1e-9, atol 1e-11: with
  // the three-point dF/dp (h = eps^(1/3) p) the error test chased its round-off in the
  // driver's rows down to h = 5e-15 and the run failed at t = 3.5 ms; the five-point
  // difference at h = 1e-3 p runs to the end (docs/sensitivities.md, "dF/dp"). Tolerance
  // as NodalRodMatchesWholeRuns.
  const double kTolerance = 1e-4;
  checkCrankSpeed("nodal rod", elasticSliderCrank(2, 0, 0.005, 1e-9, 1e-11), kTolerance);
}

TEST(SensitivitiesElastic, ModalRodMatchesWholeRuns) {
  // 8 elements reduced to 2 normal modes (examples/slider_crank_elastic_demo_modal.json),
  // 5 ms, rtol 1e-10: no axial stiffness left, so the runs are cheap and tight. The crank's
  // speed (the initial velocities and the driver): the deflection and the slider. (The
  // rod's Young's modulus and section height: ModalRodSectionMatchesWholeRuns.)
  // run noise ~1e-10 / 1e-4 = 1e-6 relative, x 2, plus truncation ~1e-8
  const double kTolerance = 1e-5;
  checkCrankSpeed("modal rod", elasticSliderCrank(8, 2, 0.005, 1e-10, 1e-12), kTolerance);
}

// The normal modes of a modal body are computed afresh in each perturbed scene; without a
// sign convention the modal coordinates of the scenes at p + h and p - h could stand for
// opposite shapes (measured before fixModeSigns: d mid.uy / dE exactly -1 times the whole
// runs' difference, d mid.uy / d height 370 times it). With it, both agree.
TEST(SensitivitiesElastic, ModalRodSectionMatchesWholeRuns) {
  const json scene = elasticSliderCrank(8, 2, 0.005, 1e-10, 1e-12);
  const std::vector<std::string> paths = {"bodies[1].section.youngs_modulus", "bodies[1].section.height"};
  const double kTolerance = 1e-5;  // as ModalRodMatchesWholeRuns
  checkAgainstWholeRuns("modal rod", scene, paths,
                        {{0, paths[0], "mid.uy", kTolerance}, {1, paths[1], "mid.uy", kTolerance}}, 1e-4);
}

TEST(SensitivitiesSpatial, RigidSliderCrankMatchesWholeRuns) {
  // examples/spatial_slider_crank.json (crank 1 rev/s, rod on a spherical and a universal
  // joint, slider on a rail) over 0.5 s at rtol 1e-10.
  json scene = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank.json"));
  scene["solver"]["rtol"] = 1e-10;
  scene["solver"]["atol"] = 1e-12;
  scene["solver"]["t_end"] = 0.5;
  scene["solver"]["output_step"] = 0.025;
  // the slider's mass, and the rod's end at the crank pin along the rod (its length)
  const std::vector<std::string> paths = {"bodies[2].mass", "joints[1].frames[1].point[0]"};
  const double kTolerance = 1e-5;  // run noise ~1e-10 / 1e-4 = 1e-6, x 2, plus truncation ~1e-8
  checkAgainstWholeRuns("spatial slider crank", scene, paths,
                        {{0, paths[0], "motor.effort", kTolerance},
                         {0, paths[0], "rail.fy", kTolerance},
                         {1, paths[1], "slider.x", kTolerance},
                         {1, paths[1], "motor.effort", kTolerance}},
                        1e-4);
}

TEST(SensitivitiesSpatial, FlexibleSliderCrankMatchesWholeRuns) {
  // examples/spatial_slider_crank_elastic.json (aluminium rod of spatial beam elements on a
  // spherical and a universal joint, geometric stiffening, crank at 5 rev/s) with 2
  // elements, 20 ms, rtol 1e-9 (before the initial sensitivities were projected onto the
  // differentiated constraints, projectOntoConstraints, the slider's mass failed at t = 0
  // at rtol <= 1e-8). The rod's Young's modulus against the midpoint deflection in both
  // bending planes, the slider's mass against the motor's torque.
  json scene = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/spatial_slider_crank_elastic.json"));
  EXPECT_EQ(scene["bodies"][1]["name"], "rod");
  scene["bodies"][1]["beam"]["elements"] = 2;
  scene["solver"]["rtol"] = 1e-9;
  scene["solver"]["atol"] = 1e-11;
  scene["solver"]["t_end"] = 0.02;
  scene["solver"]["output_step"] = 0.001;
  const std::vector<std::string> paths = {"bodies[1].section.youngs_modulus", "bodies[2].mass"};
  const double kTolerance = 5e-5;  // run noise rtol / d = 1e-5, x 3, plus truncation ~1e-8
  // the deflections are ~1e-5 of the model's size: the runs' absolute noise atol / d weighs
  // more on them (measured 3.8e-6 and 6.5e-5 of the largest derivative), x 3
  const double kDeflectionTolerance = 2e-4;
  checkAgainstWholeRuns("spatial flexible slider crank", scene, paths,
                        {{0, paths[0], "rod_mid.uy", kDeflectionTolerance},
                         {0, paths[0], "rod_mid.uz", kDeflectionTolerance},
                         {1, paths[1], "motor.effort", kTolerance}},
                        1e-4);
}

}  // namespace
