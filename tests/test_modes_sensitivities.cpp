// Eigenvalue sensitivities of `flexmbd modes --sensitivity PATH` (docs/modes.md,
// "Sensitivities of the modes"): a cantilever's bending frequencies against the
// closed forms df/dE = f / (2 E) and df/dh = f / h, the elastic slider crank's complex modes
// about its moving state against central differences of two `modes` runs, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "scene/scene_path.hpp"

namespace {

using nlohmann::json;

/// modes.csv as columns by name (every value a number; "nan" reads as NaN).
std::map<std::string, std::vector<double>> readModes(const fs::path& csv) {
  std::istringstream in(readFile(csv));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  {
    std::istringstream h(line);
    std::string c;
    while (std::getline(h, c, ',')) names.push_back(c);
  }
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::string c;
    for (std::size_t k = 0; k < names.size() && std::getline(r, c, ','); ++k) columns[names[k]].push_back(std::stod(c));
  }
  return columns;
}

/// A steel cantilever 1 m long, width 20 mm, height (in the plane of bending) 10 mm, 6
/// Euler-Bernoulli elements, clamped to the ground by a fixed joint, without gravity: its
/// modes are those of the beam's K phi = omega^2 M phi with M = rho A (...), K = E I (...)
/// on the bending and E A (...) on the axial coordinates (decoupled for a straight beam).
json cantilever() {
  return json::parse(R"({
    "name": "cantilever", "gravity": [0.0, 0.0],
    "bodies": [{"name": "beam", "type": "flexible",
                "section": {"width": 0.02, "height": 0.01, "youngs_modulus": 2.1e11, "density": 7850},
                "beam": {"length": 1.0, "elements": 6}, "reference": {"type": "clamped"}}],
    "joints": [{"name": "root", "type": "fixed", "bodies": ["ground", "beam"], "points": [[0.0, 0.0], [0.0, 0.0]]}],
    "solver": {"t_end": 1.0}
  })");
}

TEST_F(Cli, ModesSensitivityOfACantileverMatchesTheClosedForms) {
  const fs::path scene = writeScene("cantilever.json", cantilever());
  const std::string E = "bodies[0].section.youngs_modulus", h = "bodies[0].section.height";
  const CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                          " --count 3 --sensitivity '" + E + "' --sensitivity=" + shellQuote(h));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("d frequency_hz / d " + E), std::string::npos) << r.out;
  auto modes = readModes(dir_ / "out" / "modes.csv");
  for (const std::string c : {"frequency_hz", "omega_rad_s", "damping_ratio", "real", "imag"}) {
    ASSERT_EQ(modes["d" + c + "/d" + E].size(), 3u) << c;
    ASSERT_EQ(modes["d" + c + "/d" + h].size(), 3u) << c;
  }
  const std::vector<double>& f = modes["frequency_hz"];
  // The lowest three modes are the first three bending modes (the first axial one,
  // c / 4L = 1294 Hz, is above the third bending one, 147 Hz): f = lambda_k sqrt(E I /
  // (rho A)) of the discretised beam, I = b h^3 / 12, A = b h (e.g. Meirovitch, Elements of
  // Vibration Analysis, sec. 5.x), so f ∝ sqrt(E) and f ∝ h:
  //   df/dE = f / (2 E),   df/dh = f / h   (exact for the discrete model too).
  // Tolerances: E enters K linearly, so dK/dE by the five-point difference is exact up to
  // the round-off 0.95 eps |K| / step ~ 2e-13 relative (step 1e-3 E); the quotient
  // x^T K x / x^T M x of the lowest mode loses eps (omega_max / omega_1)^2 to cancellation
  // (|K| ~ omega_max^2 |M|, the axial modes of 6 elements up to ~1e5 rad/s against 52 rad/s:
  // 1e-9; measured 1.4e-10, 2.3e-12, 6.8e-13 for modes 1-3); 1e-8 holds it.
  const double kYoungsTolerance = 1e-8;
  // h enters K as h^3 (bending) and h (axial), M as h: polynomials of degree 3, whose
  // five-point difference is exact (its error is h^4 f^(5) / 30), so df/dh carries the same
  // round-off and cancellation as df/dE (measured 4.2e-11, 1.9e-12, 1e-16); 1e-8 holds it.
  const double kHeightTolerance = 1e-8;
  const double Ev = 2.1e11, hv = 0.01;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_GT(f[k], 1.0) << "mode " << k + 1 << " is not an elastic one";
    const double dfdE = modes["dfrequency_hz/d" + E][k], dfdh = modes["dfrequency_hz/d" + h][k];
    EXPECT_NEAR(dfdE / (f[k] / (2 * Ev)), 1.0, kYoungsTolerance) << "mode " << k + 1;
    EXPECT_NEAR(dfdh / (f[k] / hv), 1.0, kHeightTolerance) << "mode " << k + 1;
    std::printf("cantilever mode %zu (%.6g Hz): df/dE error %.3g, df/dh error %.3g (relative)\n", k + 1, f[k],
                dfdE / (f[k] / (2 * Ev)) - 1.0, dfdh / (f[k] / hv) - 1.0);
    // undamped: the eigenvalue stays imaginary (its real part is round-off, eps omega_max
    // ~ 2e-11 rad/s) and the damping ratio 0: it changes by less than 1e-12 per unit of
    // relative change of E; omega and Im s are 2 pi f (the columns' 12 digits: 1e-10)
    EXPECT_LT(std::fabs(modes["ddamping_ratio/d" + E][k] * Ev), 1e-12);
    EXPECT_NEAR(modes["domega_rad_s/d" + E][k], 2 * M_PI * dfdE, 1e-10 * std::fabs(2 * M_PI * dfdE));
    EXPECT_NEAR(modes["dimag/d" + E][k], 2 * M_PI * dfdE, 1e-10 * std::fabs(2 * M_PI * dfdE));
  }
}

/// Worst |derivative of `modes --sensitivity` - central difference of two `modes` runs| over
/// the listed modes, and the largest |difference|.
struct Comparison {
  double worst = 0.0, largest = 0.0;
};

TEST_F(Cli, ModesSensitivityOfTheElasticSliderCrankMatchesTwoModesRuns) {
  // The elastic slider crank (examples/slider_crank_elastic.json, 4 elements) about its state
  // at t_start, in motion (crank at 150 rad/s): G turns with the motion, the modes are
  // complex (Coriolis and the moving basis), so the left and right null vectors differ.
  json j = json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) + "/examples/slider_crank_elastic.json"));
  j["bodies"][1]["beam"]["elements"] = 4;
  const std::vector<std::string> paths = {"bodies[2].mass", "drivers[0].law.speed", "bodies[1].section.height"};
  const fs::path scene = writeScene("crank.json", j);
  std::string options;
  for (const std::string& p : paths) options += " --sensitivity '" + p + "'";
  const int count = 4;
  const std::string common = " --count " + std::to_string(count) + " --quiet";
  CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "base").string()) + common +
                    options);
  ASSERT_EQ(r.status, 0) << r.err;
  auto base = readModes(dir_ / "base" / "modes.csv");
  // Runs at p (1 +- 1e-4): truncation d^2 |f'''| p^3 / 6 ~ 1e-8 relative for these smooth
  // dependences, and the reference state is projected to its Newton tolerance in each run
  // (1e-13 of the state): 2e-6 of the largest derivative holds both. The columns are
  // written with 12 significant digits: each value carries 5e-12 of the column's largest,
  // which the quotient turns into 2 x 5e-12 max |c| / (2e-4 p) (kDigitsNoise).
  const double kRelStep = 1e-4, kRelativeTolerance = 2e-6, kDigitsNoise = 5e-12;
  for (const std::string& p : paths) {
    const double value = flexmbd::sceneNumber(j, p);
    ASSERT_NE(value, 0.0) << p;
    std::map<std::string, std::vector<double>> side[2];
    for (int s = 0; s < 2; ++s) {
      json at = j;
      const double v = value * (s == 0 ? 1 + kRelStep : 1 - kRelStep);
      flexmbd::setSceneNumber(at, p, v);
      const std::string name = s == 0 ? "plus" : "minus";
      r = run("modes " + shellQuote(writeScene(name + ".json", at).string()) + " --out " +
              shellQuote((dir_ / name).string()) + common);
      ASSERT_EQ(r.status, 0) << r.err;
      side[s] = readModes(dir_ / name / "modes.csv");
    }
    // (the real parts are round-off: the model is undamped, its modes' Re s ~ eps omega_max)
    for (const std::string c : {"frequency_hz", "imag"}) {
      Comparison cmp;
      double scale = 0.0;
      for (int k = 0; k < count; ++k) scale = std::max(scale, std::fabs(base[c][k]));
      const double noise = 2 * kDigitsNoise * scale / (2 * kRelStep * std::fabs(value));
      for (int k = 0; k < count; ++k) {
        const double fd = (side[0][c][k] - side[1][c][k]) / (2 * kRelStep * value);
        cmp.worst = std::max(cmp.worst, std::fabs(base["d" + c + "/d" + p][k] - fd));
        cmp.largest = std::max(cmp.largest, std::fabs(fd));
      }
      std::printf("elastic slider crank modes d%s/d%s: worst %.3g of the largest %.3g\n", c.c_str(), p.c_str(),
                  cmp.worst / cmp.largest, cmp.largest);
      if (c == "frequency_hz") {
        EXPECT_GT(cmp.largest, 0.0) << p;
      }
      EXPECT_LE(cmp.worst, kRelativeTolerance * cmp.largest + noise) << c << " / " << p << ": noise " << noise;
    }
  }
}

TEST_F(Cli, ModesSensitivityOfARepeatedEigenvalueIsNotANumber) {
  // A spatial cantilever of square section bends alike in its two planes: its lowest
  // eigenvalue is double (equal to round-off), not differentiable (the pair may split in
  // any direction); the derivative is written as nan, the simple modes' are numbers.
  const double side = 0.02;
  const json beam = {{"name", "square cantilever"}, {"dimension", 3}, {"gravity", {0, 0, 0}},
                     {"bodies", {{{"name", "beam"}, {"type", "flexible"},
                                  {"section", {{"width", side}, {"height", side}, {"youngs_modulus", 2.1e11},
                                               {"poisson_ratio", 0.3}, {"density", 7850.0}}},
                                  {"beam", {{"length", 1.0}, {"elements", 4}}}, {"reference", {{"type", "clamped"}}}}}},
                     {"joints", {{{"name", "root"}, {"type", "fixed"}, {"bodies", {"ground", "beam"}},
                                  {"frames", {{{"point", {0, 0, 0}}}, {{"point", {0, 0, 0}}}}}}}},
                     {"solver", {{"t_end", 1}}}};
  const fs::path scene = writeScene("square.json", beam);
  const std::string E = "bodies[0].section.youngs_modulus";
  const CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                          " --count 3 --quiet --sensitivity '" + E + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  auto modes = readModes(dir_ / "out" / "modes.csv");
  const std::vector<double>& f = modes["frequency_hz"];
  ASSERT_EQ(f.size(), 3u);
  EXPECT_NEAR(f[0] / f[1], 1.0, 1e-9);  // the pair
  EXPECT_TRUE(std::isnan(modes["dfrequency_hz/d" + E][0]));
  EXPECT_TRUE(std::isnan(modes["dfrequency_hz/d" + E][1]));
  // the third is the first of the second bending pair (104.7 Hz; torsion is near 800 Hz),
  // whose partner is the fourth: seen because one mode more than listed is computed
  EXPECT_TRUE(std::isnan(modes["dfrequency_hz/d" + E][2]));
}

TEST_F(Cli, ModesSensitivityBadInputExitsTwoNamingTheParameter) {
  const fs::path scene = writeScene("cantilever.json", cantilever());
  struct Case {
    std::string options, expected;
  };
  for (const Case& c : {Case{"--sensitivity 'bodies[3].mass'", "no element [3]"},
                        Case{"--sensitivity 'bodies[0].section.colour'", "no key 'colour'"},
                        Case{"--sensitivity 'bodies[0].beam.elements'", "sensitivity parameter 'bodies[0].beam.elements'"},
                        Case{"--sensitivity 'bodies[0].name'", "expected a number"},
                        Case{"--sensitivity", "needs a scene path"},
                        Case{"--sensitivity 'bodies[0].section.height' --sweep root:0:1:2", "--sweep"},
                        Case{"--sensitivity 'bodies[0].section.height' --at 0.5", "--at"}}) {
    const CliResult r = run("modes " + shellQuote(scene.string()) + " --out " + shellQuote((dir_ / "out").string()) +
                            " --quiet " + c.options);
    EXPECT_EQ(r.status, 2) << c.options << ": " << r.err;
    EXPECT_TRUE(IsOneErrorLine(r.err)) << c.options;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.options << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out" / "modes.csv")) << c.options;
  }
}

}  // namespace
