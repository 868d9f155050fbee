// The VTK output: files per output time and a collection, points on the deformed beam
// axis consistent with the joints, section forces as point data.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "io/vtk_writer.hpp"
#include "tests/ffr_test_models.hpp"

using namespace flexmbd;
namespace fs = std::filesystem;

namespace {

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The numbers of the first DataArray named `name` (or of the Points array if empty).
std::vector<double> dataArray(const std::string& xml, const std::string& name) {
  const std::string key = name.empty() ? "<Points>" : "Name=\"" + name + "\"";
  const size_t start = xml.find('>', xml.find("<DataArray", xml.find(key))) + 1;
  const size_t end = xml.find("</DataArray>", start);
  std::istringstream in(xml.substr(start, end - start));
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

}  // namespace

TEST(VtkWriter, WritesOneFilePerOutputAndTheBeamAxisMeetsTheJoints) {
  Scene s = testmodels::elasticSliderCrank(4, 1.0, 2, 0.05, 1e-6, 1e-8);
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_vtk_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  long outputs = 0;
  OutputSample last;
  {
    VtkWriter vtk(dir, s.system, "bodies", 4);
    const auto summary = simulate(s.system, s.solver, [&](const OutputSample& o) {
      vtk.write(o);
      last = o;
      ++outputs;
    });
    ASSERT_TRUE(summary.ok);
    EXPECT_EQ(vtk.filesWritten(), outputs);
  }
  const std::string pvd = read(dir / "bodies.pvd");
  long datasets = 0;
  for (size_t k = pvd.find("<DataSet"); k != std::string::npos; k = pvd.find("<DataSet", k + 1)) ++datasets;
  EXPECT_EQ(datasets, outputs);
  char name[64];
  std::snprintf(name, sizeof(name), "bodies_%06ld.vtu", outputs - 1);
  const std::string vtu = read(dir / name);
  const std::vector<double> pts = dataArray(vtu, "");
  ASSERT_EQ(pts.size() % 3, 0u);
  const std::vector<double> N = dataArray(vtu, "axial_force");
  EXPECT_EQ(N.size() * 3, pts.size());
  // The crank's tip (joint O2) is where the rod's axis starts: find both among the points.
  const System& sys = s.system;
  const BodyIndex crank = sys.findBody("crank");
  const Vec2 tip = sys.body(crank).pointKinematics(last.q.segment(sys.coordinateOffset(crank), 3), {0.15, 0}).r;
  int matches = 0;
  for (size_t k = 0; k < pts.size(); k += 3) {
    if ((Vec2(pts[k], pts[k + 1]) - tip).norm() < 1e-6) ++matches;  // written with 12 digits
  }
  EXPECT_GE(matches, 2);  // the crank's point and the rod's first point
  fs::remove_all(dir);
}
