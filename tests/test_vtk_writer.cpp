// The VTK output: files per output time and a collection, points on the deformed beam
// axis consistent with the joints, section forces as point data.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "io/scene.hpp"
#include "io/vtk_writer.hpp"
#include "tensegrity/tensegrity_structure.hpp"
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
  // The array's own tag: the first after <Points>, or the one holding Name="name".
  const size_t tag = name.empty() ? xml.find("<DataArray", xml.find("<Points>"))
                                  : xml.rfind("<DataArray", xml.find("Name=\"" + name + "\""));
  if (tag == std::string::npos || (!name.empty() && xml.find("Name=\"" + name + "\"") == std::string::npos)) return {};
  const size_t start = xml.find('>', tag) + 1;
  const size_t end = xml.find("</DataArray>", start);
  std::istringstream in(xml.substr(start, end - start));
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

/// The strings of the FieldData String array `name`: ASCII character codes, each string
/// ended by 0 (the format vtkXMLWriter uses for string arrays).
std::vector<std::string> stringArray(const std::string& xml, const std::string& name) {
  const size_t at = xml.find("<DataArray type=\"String\" Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const size_t start = xml.find('>', at) + 1;
  std::istringstream in(xml.substr(start, xml.find("</DataArray>", start) - start));
  std::vector<std::string> out(1);
  for (int c; in >> c;) {
    if (c == 0) {
      out.emplace_back();
    } else {
      out.back() += static_cast<char>(c);
    }
  }
  out.pop_back();  // after the last 0
  return out;
}

/// The integers of the DataArray named `name`.
std::vector<int> intArray(const std::string& xml, const std::string& name) {
  std::vector<int> out;
  for (double x : dataArray(xml, name)) out.push_back(static_cast<int>(x));
  return out;
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
  // The frame names its bodies: one entry per body drawn, one index per cell.
  std::vector<std::string> names;
  for (int b = 1; b < sys.numBodies(); ++b) names.push_back(sys.body(BodyIndex(b)).name());
  EXPECT_EQ(stringArray(vtu, "body_names"), names);
  const std::vector<int> index = intArray(vtu, "body_index");
  EXPECT_EQ(index.size(), dataArray(vtu, "offsets").size());
  for (int b : index) EXPECT_TRUE(b >= 0 && b < static_cast<int>(names.size())) << b;
  EXPECT_EQ(index.front(), 0);
  EXPECT_EQ(index.back(), static_cast<int>(names.size()) - 1);
  fs::remove_all(dir);
}

TEST(VtkWriter, InvariantsBodyIsDrawnThroughItsAttachmentPoints) {
  // examples/bari_slider_crank.json: the rod is a flexible_invariants body with two
  // attachment points, deformed by its initial elastic coordinates.
  const Scene scene = loadScene(std::string(FLEXMBD_SOURCE_DIR) + "/examples/bari_slider_crank.json");
  const System& sys = scene.system;
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_vtk_inv_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  OutputSample sample;
  sample.q = sys.initialCoordinates();
  sample.v = VecX::Zero(sample.q.size());
  sample.a = sample.v;
  sample.lambda = VecX::Zero(sys.numConstraintEquations());
  {
    VtkWriter vtk(dir, sys);
    vtk.write(sample);
  }
  const std::string vtu = read(dir / "bodies_000000.vtu");
  const std::vector<std::string> names = stringArray(vtu, "body_names");
  ASSERT_EQ(names, (std::vector<std::string>{"crank", "rod", "slider"}));
  EXPECT_NE(vtu.find("<!-- body_names: crank, rod, slider -->"), std::string::npos);
  // The rod's cell: its points are the attachment points where the body places them.
  const BodyIndex rod = sys.findBody("rod");
  const auto& body = dynamic_cast<const FfrBody2d&>(sys.body(rod));
  const std::vector<int> index = intArray(vtu, "body_index"), offsets = intArray(vtu, "offsets"),
                         connectivity = intArray(vtu, "connectivity");
  const std::vector<double> pts = dataArray(vtu, "");
  ASSERT_EQ(index.size(), 3u);
  ASSERT_EQ(index[1], 1);
  const int first = offsets[0], count = offsets[1] - offsets[0];
  ASSERT_EQ(count, static_cast<int>(body.invariants().points.size()));
  const auto q = sample.q.segment(sys.coordinateOffset(rod), body.numCoordinates());
  for (int k = 0; k < count; ++k) {
    const int p = connectivity[first + k];
    const Vec2 expected = body.pointKinematics(q, body.invariants().points[k].position, false).r;
    EXPECT_NEAR(pts[3 * p], expected.x(), 1e-9);
    EXPECT_NEAR(pts[3 * p + 1], expected.y(), 1e-9);
  }
  // Its elastic displacement is drawn (the example starts deformed).
  const std::vector<double> u = dataArray(vtu, "elastic_displacement");
  double largest = 0.0;
  for (int k = 0; k < count; ++k) {
    const int p = connectivity[first + k];
    largest = std::max({largest, std::fabs(u[3 * p]), std::fabs(u[3 * p + 1])});
  }
  EXPECT_GT(largest, 0.0);
  fs::remove_all(dir);
}

TEST(VtkWriter, SpatialBeamIsDrawnDeformedWithItsSectionForces) {
  // A spatial cantilever (clamped at node 0, frame = world) deformed by the static response
  // to a tip force F: the drawn axis ends at the deflected tip, and the section force
  // vector is (N, Qy, Qz) = F on every point, the section moment at the root (0, -Fz L,
  // Fy L) (BeamSectionForces3d's signs); the element is exact for this load, so to the
  // 12 digits the file holds (1e-9 relative).
  const double L = 0.8;
  const Vec3 F(300.0, -2.0, 1.5);
  nlohmann::json j = nlohmann::json::parse(R"({"dimension": 3, "bodies": [{"name": "beam", "type": "flexible",
      "section": {"width": 0.03, "height": 0.02, "youngs_modulus": 2e9, "shear_modulus": 8e8, "density": 2700},
      "beam": {"length": 0.8, "elements": 4}, "reference": {"type": "clamped"}}]})");
  const Scene s0 = parseScene(j);
  const auto& b0 = dynamic_cast<const FfrBody3d&>(s0.system.body(s0.system.findBody("beam")));
  const int nf = b0.numElastic();
  VecX f = VecX::Zero(nf);
  f.segment<3>(nf - 6) = F;
  const VecX qf = MatX(b0.invariants().kff).ldlt().solve(f);
  j["bodies"][0]["elastic_coordinates"] = std::vector<double>(qf.data(), qf.data() + nf);
  const Scene sc = parseScene(j);
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_vtk3_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  OutputSample o;
  o.q = sc.system.initialCoordinates();
  o.v = sc.system.initialVelocities();
  {
    VtkWriter vtk(dir, sc.system, "bodies", 4);
    EXPECT_TRUE(vtk.bodiesNotDrawn().empty());
    vtk.write(o);
  }
  const std::string vtu = read(dir / "bodies_000000.vtu");
  const std::vector<double> pts = dataArray(vtu, ""), force = dataArray(vtu, "section_force"),
                            moment = dataArray(vtu, "section_moment");
  ASSERT_EQ(pts.size(), 3u * 4 * 5);  // 4 elements, 5 points each
  ASSERT_EQ(force.size(), pts.size());
  ASSERT_EQ(moment.size(), pts.size());
  const Vec3 tip(pts[pts.size() - 3], pts[pts.size() - 2], pts[pts.size() - 1]);
  const Vec3 tipExpected = Vec3(L, 0.0, 0.0) + qf.segment<3>(nf - 6);
  EXPECT_LT((tip - tipExpected).norm(), 1e-9 * L) << tip.transpose();
  const double scale = F.norm() * L;
  for (size_t k = 0; k < force.size(); k += 3) {
    EXPECT_LT((Vec3(force[k], force[k + 1], force[k + 2]) - F).norm(), 1e-9 * scale) << "point " << k / 3;
  }
  EXPECT_LT((Vec3(moment[0], moment[1], moment[2]) - Vec3(0.0, -F.z() * L, F.y() * L)).norm(), 1e-9 * scale);
  fs::remove_all(dir);
}

TEST(VtkWriter, TensegrityFramesHoldNodesMembersForcesAndNames) {
  // A 2D triangle: two struts and a cable; the strut force is EA (l - l0) / l0.
  TensegrityStructure s(2);
  s.setMaxStrutsPerNode(2);
  s.addNode("a", Vec2(0, 0), 1.0, {true, true}, Vec2::Zero());
  s.addNode("b", Vec2(1, 0), 1.0, {false, false}, Vec2::Zero());
  s.addNode("c", Vec2(0, 1), 1.0, {false, false}, Vec2::Zero());
  s.addStrut("ab", 0, 1, 100.0, 0.9, 0.0, BarMassModel::Lumped);
  s.addStrut("ac", 0, 2, 100.0, 1.0, 0.0, BarMassModel::Lumped);
  s.addCable("bc", 1, 2, 50.0, 1.0, false);
  s.finalize();
  TensegritySample smp;
  smp.x = s.initialPositions();
  smp.v = VecX::Zero(smp.x.size());
  smp.cableTension = VecX::Constant(1, 7.5);
  smp.cableImpulse = VecX::Zero(1);
  smp.cableLength = VecX::Constant(1, std::sqrt(2.0));
  smp.slack = {false};
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_vtk_tens_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  {
    TensegrityVtkWriter vtk(dir, s, "");
    vtk.write(smp);
    EXPECT_EQ(vtk.filesWritten(), 1);
  }
  const std::string vtu = read(dir / "bodies_000000.vtu");
  EXPECT_EQ(stringArray(vtu, "body_names"), (std::vector<std::string>{"tensegrity"}));
  EXPECT_EQ(stringArray(vtu, "member_names"), (std::vector<std::string>{"ab", "ac", "bc"}));
  EXPECT_EQ(dataArray(vtu, "").size(), 9u);  // three nodes, z = 0
  EXPECT_EQ(intArray(vtu, "connectivity"), (std::vector<int>{0, 1, 0, 2, 1, 2}));
  EXPECT_EQ(intArray(vtu, "types"), (std::vector<int>{3, 3, 3}));  // VTK_LINE
  EXPECT_EQ(intArray(vtu, "member_type"), (std::vector<int>{0, 0, 1}));
  const std::vector<double> N = dataArray(vtu, "axial_force");
  ASSERT_EQ(N.size(), 3u);
  EXPECT_NEAR(N[0], 100.0 * (1.0 - 0.9) / 0.9, 1e-9);
  EXPECT_NEAR(N[1], 0.0, 1e-12);
  EXPECT_NEAR(N[2], 7.5, 1e-12);
  EXPECT_TRUE(fs::exists(dir / "bodies.pvd"));
  fs::remove_all(dir);
}
