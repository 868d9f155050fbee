// flexmbd view (app/view_command.cpp, viewer/html_viewer.cpp, viewer/viewer.js): the page's
// data against closed forms and the run's own outputs, its errors, and the page opened in
// a real browser (headless Chromium): it renders (the canvas not blank), without console
// errors, with the frames and bodies of the run. Screenshots are kept in
// <build>/tests/artifacts/ (look at them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "cli_fixture.hpp"

namespace {

/// Float32 positions of coordinates up to 4 m: rounding 2.4e-7 m at most, and the results
/// file's 17 digits add nothing.
constexpr double kFloat32Position = 1e-6;

const fs::path kChromium = "/usr/bin/chromium";

/// The page's data (the JSON of <script id="flexmbd-data">).
nlohmann::json pageData(const fs::path& html) {
  const std::string text = readFile(html);
  const std::string open = "<script id=\"flexmbd-data\" type=\"application/json\">";
  const std::size_t a = text.find(open);
  const std::size_t b = text.find("</script>", a);
  if (a == std::string::npos || b == std::string::npos) throw std::runtime_error("no data in " + html.string());
  return nlohmann::json::parse(text.substr(a + open.size(), b - a - open.size()));
}

/// Base64 (RFC 4648) to Float32, decoded here independently of the engine's encoder.
std::vector<float> float32(const std::string& b64) {
  std::vector<unsigned char> bytes;
  unsigned v = 0;
  int bits = 0;
  for (char c : b64) {
    int d = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52
            : c == '+' ? 62 : c == '/' ? 63 : -1;
    if (d < 0) continue;  // padding
    v = (v << 6) | static_cast<unsigned>(d);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<unsigned char>((v >> bits) & 0xff));
    }
  }
  std::vector<float> out(bytes.size() / 4);
  std::memcpy(out.data(), bytes.data(), out.size() * 4);
  return out;
}

/// The results file as rows of numbers with its header.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int col(const std::string& name) const {
    for (std::size_t k = 0; k < header.size(); ++k) {
      if (header[k] == name) return static_cast<int>(k);
    }
    throw std::runtime_error("no column " + name);
  }
};

Table readTable(const fs::path& csv) {
  Table t;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) t.header.push_back(c);
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::vector<double> row;
    for (std::string c; std::getline(s, c, ',');) row.push_back(std::strtod(c.c_str(), nullptr));  // "nan" too
    t.rows.push_back(row);
  }
  return t;
}

int jointIndex(const nlohmann::json& d, const std::string& name) {
  for (std::size_t k = 0; k < d["joints"].size(); ++k) {
    if (d["joints"][k] == name) return static_cast<int>(k);
  }
  throw std::runtime_error("no joint " + name);
}

/// What the page reported in Chromium (its element flexmbd-status), and a screenshot.
nlohmann::json openInBrowser(const fs::path& html, const fs::path& screenshot) {
  const std::string common = shellQuote(kChromium.string()) +
                             " --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader "
                             "--window-size=1280,860 --virtual-time-budget=3000 ";
  const fs::path dom = html.parent_path() / "dom.html";
  const std::string url = shellQuote("file://" + fs::absolute(html).string());
  std::system((common + "--dump-dom " + url + " >" + shellQuote(dom.string()) + " 2>/dev/null").c_str());
  fs::create_directories(screenshot.parent_path());
  std::system((common + "--screenshot=" + shellQuote(screenshot.string()) + " " + url + " >/dev/null 2>&1").c_str());
  const std::string text = readFile(dom);
  const std::string open = "<pre id=\"flexmbd-status\" hidden=\"\">";
  const std::size_t a = text.find(open);
  if (a == std::string::npos) return nlohmann::json{{"ok", false}, {"errors", {"no status element in the DOM"}}};
  const std::size_t b = text.find("</pre>", a);
  return nlohmann::json::parse(text.substr(a + open.size(), b - a - open.size()));
}

fs::path artifacts() { return fs::path(FLEXMBD_BINARY_DIR) / "tests" / "artifacts"; }

class View : public Cli {};

TEST_F(View, RigidSliderCrankJointsFollowTheClosedForm) {
  // examples/slider_crank_rigid.json: l1 = 1, l2 = 2; joint O2 (first on the crank at
  // (1, 0)) at (cos theta, sin theta), O3 at the slider, x = cos theta + sqrt(4 - sin^2 theta)
  const fs::path out = dir_ / "run";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --quiet").status, 0);
  const CliResult v = run("view " + shellQuote(out.string()));
  ASSERT_EQ(v.status, 0) << v.err;
  EXPECT_NE(v.out.find("view.html"), std::string::npos) << v.out;
  const nlohmann::json d = pageData(out / "view.html");
  const Table t = readTable(out / "results.csv");
  ASSERT_EQ(d["clips"].size(), 1u);
  const auto& clip = d["clips"][0];
  ASSERT_EQ(clip["times"].size(), t.rows.size());  // every output time is a frame
  EXPECT_EQ(d["bodies"], nlohmann::json({"crank", "rod", "slider"}));
  EXPECT_TRUE(d["planar"].get<bool>());
  const std::vector<float> jp = float32(clip["joint_positions"]);
  const int nj = static_cast<int>(d["joints"].size());
  ASSERT_EQ(jp.size(), 3u * nj * t.rows.size());
  const int o2 = jointIndex(d, "O2"), o3 = jointIndex(d, "O3");
  const int theta = t.col("crank.theta");
  for (std::size_t f = 0; f < t.rows.size(); ++f) {
    const double th = t.rows[f][theta];
    EXPECT_NEAR(jp[3 * (nj * f + o2)], std::cos(th), kFloat32Position) << "frame " << f;
    EXPECT_NEAR(jp[3 * (nj * f + o2) + 1], std::sin(th), kFloat32Position) << "frame " << f;
    const double x = std::cos(th) + std::sqrt(4.0 - std::sin(th) * std::sin(th));
    EXPECT_NEAR(jp[3 * (nj * f + o3)], x, 1e-5) << "frame " << f;  // the run's own rtol 1e-8 x 3 m, and float32
    EXPECT_NEAR(jp[3 * (nj * f + o3) + 1], 0.0, kFloat32Position) << "frame " << f;
  }
  // the plots: by default the bodies' positions, with units
  ASSERT_FALSE(d["plots"].empty());
  EXPECT_EQ(d["plots"][0]["name"], "crank.x");
  EXPECT_EQ(d["plots"][0]["unit"], "m");
  EXPECT_EQ(d["plot_times"].size(), t.rows.size());
}

TEST_F(View, ElasticRodDeflectionIsTheRunsDeflectionOutput) {
  // the demo's nodal rod (8 elements, 4 segments each): the drawing's point at the start of
  // element 5 is the rod's midpoint, where the scene's deflection output "mid" is; its
  // "deflection" colour is |u| = hypot(mid.ux, mid.uy) in every frame (a rotation keeps |u|)
  nlohmann::json scene = nlohmann::json::parse(readFile(std::string(FLEXMBD_SOURCE_DIR) +
                                                        "/examples/slider_crank_elastic_demo_nodal.json"));
  scene["solver"]["t_end"] = 0.02;
  const fs::path s = writeScene("nodal.json", scene), out = dir_ / "run";
  ASSERT_EQ(run("run " + shellQuote(s.string()) + " --out " + shellQuote(out.string()) + " --quiet").status, 0);
  ASSERT_EQ(run("view " + shellQuote(out.string())).status, 0);
  const nlohmann::json d = pageData(out / "view.html");
  const Table t = readTable(out / "results.csv");
  int rodCell = -1;
  for (std::size_t c = 0; c < d["cells"].size(); ++c) {
    if (d["bodies"][d["cell_body"][c].get<int>()] == "rod" && rodCell < 0) rodCell = static_cast<int>(c);
  }
  ASSERT_GE(rodCell, 0);
  const int mid = d["cells"][rodCell + 4][0];  // element 5's first point: x = 0.15 m of 0.30 m
  ASSERT_EQ(d["quantities"][0]["name"], "deflection");
  const std::vector<float> u = float32(d["clips"][0]["quantities"][0]);
  const int n = d["points"];
  const int ux = t.col("mid.ux"), uy = t.col("mid.uy");
  double largest = 0.0;
  for (std::size_t f = 0; f < t.rows.size(); ++f) {
    const double expected = std::hypot(t.rows[f][ux], t.rows[f][uy]);
    largest = std::max(largest, expected);
    // float32 of a deflection below 1 mm: 1e-10 m; and 1e-12 m for the output's own digits
    EXPECT_NEAR(u[n * f + mid], expected, 1e-9) << "frame " << f;
  }
  EXPECT_GT(largest, 1e-5);  // the rod does deflect: the comparison is not of zeros
  // the deformation scale needs the displacements
  EXPECT_FALSE(d["clips"][0]["displacements"].get<std::string>().empty());
}

TEST_F(View, ModeShapesAreOneClipPerMode) {
  const fs::path out = dir_ / "modes";
  const CliResult m = run("modes " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/modes_blade.json") +
                          " --out " + shellQuote(out.string()) + " --count 3");
  ASSERT_EQ(m.status, 0) << m.err;
  ASSERT_EQ(run("view " + shellQuote(out.string())).status, 0);
  const nlohmann::json d = pageData(out / "view.html");
  ASSERT_EQ(d["clips"].size(), 3u);
  const Table modes = readTable(out / "modes.csv");
  for (int k = 0; k < 3; ++k) {
    const auto& c = d["clips"][k];
    EXPECT_EQ(c["time_unit"], "period");
    EXPECT_EQ(c["times"].size(), 16u);  // kShapeFrames of app/modes_command.cpp
    char hz[64];
    std::snprintf(hz, sizeof hz, "mode %d: %.6g Hz", k + 1, modes.rows[k][modes.col("frequency_hz")]);
    EXPECT_EQ(c["name"], hz);
  }
}

TEST_F(View, BadInputIsNamed) {
  // not a run folder
  CliResult r = run("view " + shellQuote((dir_ / "nothing").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("is not a folder"), std::string::npos) << r.err;
  // a run: an unknown column, a scene that is not the one that ran, a summary without scene_file
  const fs::path out = dir_ / "run";
  ASSERT_EQ(run("run " + shellQuote(kExample) + " --out " + shellQuote(out.string()) + " --quiet --t-end 0.5").status, 0);
  r = run("view " + shellQuote(out.string()) + " --columns crank.x,crank.thta");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column 'crank.thta'"), std::string::npos) << r.err;
  nlohmann::json other = example();
  other["bodies"][0]["name"] = "arm";
  for (auto& j : other["joints"]) {
    for (auto& b : j["bodies"]) {
      if (b == "crank") b = "arm";
    }
  }
  other["drivers"][0]["body"] = "arm";
  const fs::path otherScene = writeScene("other.json", other);
  r = run("view " + shellQuote(out.string()) + " --scene " + shellQuote(otherScene.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column 'arm.x'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--scene"), std::string::npos) << r.err;
  nlohmann::json summary = nlohmann::json::parse(readFile(out / "summary.json"));
  ASSERT_TRUE(summary.contains("scene_file"));
  EXPECT_EQ(fs::path(summary["scene_file"].get<std::string>()), fs::canonical(kExample));
  summary.erase("scene_file");
  std::ofstream(out / "summary.json") << summary.dump();
  r = run("view " + shellQuote(out.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("give it with --scene"), std::string::npos) << r.err;
  r = run("view " + shellQuote(out.string()) + " --scene " + shellQuote(kExample) + " --max-frames 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--max-frames must be a whole number from 2"), std::string::npos) << r.err;
  // --max-frames: evenly spread, the first and the last output kept
  ASSERT_EQ(run("view " + shellQuote(out.string()) + " --scene " + shellQuote(kExample) + " --max-frames 3").status, 0);
  const nlohmann::json d = pageData(out / "view.html");
  const Table t = readTable(out / "results.csv");
  ASSERT_EQ(d["clips"][0]["times"].size(), 3u);
  EXPECT_DOUBLE_EQ(d["clips"][0]["times"][0].get<double>(), t.rows.front()[0]);
  EXPECT_DOUBLE_EQ(d["clips"][0]["times"][2].get<double>(), t.rows.back()[0]);
}

// ----- in a real browser ----------------------------------------------------------------------

class Browser : public Cli {
 protected:
  void SetUp() override {
    if (!fs::exists(kChromium)) GTEST_SKIP() << "no " << kChromium << " (Debian chromium; scripts/setup.sh installs it)";
    Cli::SetUp();
  }
  /// Runs `scene` to t_end, writes its page, opens it; checks what the page reported.
  void check(const std::string& scene, double tEnd, const std::string& shot, int bodies) {
    const fs::path out = dir_ / "run";
    ASSERT_EQ(run("run " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/" + scene) + " --out " +
                  shellQuote(out.string()) + " --quiet --t-end " + std::to_string(tEnd)).status, 0);
    ASSERT_EQ(run("view " + shellQuote(out.string())).status, 0);
    const Table t = readTable(out / "results.csv");
    const nlohmann::json s = openInBrowser(out / "view.html", artifacts() / shot);
    EXPECT_TRUE(s["ok"].get<bool>()) << s.dump();
    EXPECT_EQ(s["errors"].size(), 0u) << s.dump();
    EXPECT_EQ(s.value("frames", 0), static_cast<int>(t.rows.size())) << s.dump();
    EXPECT_EQ(s.value("bodies", 0), bodies) << s.dump();
    // not blank: the bodies cover more than 0.1 % of the canvas (the demo's: about 3 %)
    const auto canvas = s.value("canvas", std::vector<int>{0, 0});
    EXPECT_GT(s.value("drawn_pixels", 0), 1e-3 * canvas[0] * canvas[1]) << s.dump();
    EXPECT_TRUE(fs::exists(artifacts() / shot));
  }
};

TEST_F(Browser, PlanarElasticSliderCrankRenders) { check("slider_crank_elastic_demo_nodal.json", 0.03, "viewer_planar.png", 3); }

TEST_F(Browser, SpatialElasticSliderCrankRenders) { check("spatial_slider_crank_elastic.json", 0.1, "viewer_spatial.png", 3); }

TEST_F(Browser, AModelWithoutJointsRenders) {
  // a body falling freely: no joint, so the page's joint arrays are empty (a rotor on
  // bushings drew nothing: "Cannot read properties of null")
  const nlohmann::json scene = nlohmann::json::parse(R"({"name": "falling box", "dimension": 3,
    "gravity": [0, 0, -9.81],
    "bodies": [{"name": "box", "type": "rigid", "mass": 2, "inertia": [0.1, 0.2, 0.3], "position": [0, 0, 1],
                "angular_velocity": [1, 2, 3]}],
    "solver": {"t_end": 0.2, "output_step": 0.01}})");
  const fs::path s = writeScene("falling.json", scene), out = dir_ / "run";
  ASSERT_EQ(run("run " + shellQuote(s.string()) + " --out " + shellQuote(out.string()) + " --quiet").status, 0);
  ASSERT_EQ(run("view " + shellQuote(out.string())).status, 0);
  const nlohmann::json st = openInBrowser(out / "view.html", artifacts() / "viewer_no_joints.png");
  EXPECT_TRUE(st["ok"].get<bool>()) << st.dump();
  EXPECT_EQ(st.value("joints", -1), 0) << st.dump();
  EXPECT_EQ(st.value("frames", 0), 21) << st.dump();
  EXPECT_GT(st.value("drawn_pixels", 0), 1000) << st.dump();
}

TEST_F(Browser, ModeShapesRender) {
  const fs::path out = dir_ / "modes";
  ASSERT_EQ(run("modes " + shellQuote(std::string(FLEXMBD_SOURCE_DIR) + "/examples/modes_blade.json") + " --out " +
                shellQuote(out.string()) + " --count 4").status, 0);
  ASSERT_EQ(run("view " + shellQuote(out.string())).status, 0);
  const nlohmann::json s = openInBrowser(out / "view.html", artifacts() / "viewer_modes.png");
  EXPECT_TRUE(s["ok"].get<bool>()) << s.dump();
  EXPECT_EQ(s.value("frames", 0), 4 * 16) << s.dump();
  EXPECT_GT(s.value("drawn_pixels", 0), 1000) << s.dump();
}

}  // namespace
