// The VTK output: files per output time and a collection, points on the deformed beam
// axis consistent with the joints, section forces as point data.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <map>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bodies/ffr_body_2d.hpp"
#include "bodies/body_geometry.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/rotation_3d.hpp"
#include "scene/scene.hpp"
#include "results/vtk_writer.hpp"
#include "tensegrity/tensegrity_structure.hpp"
#include "problems/ffr_test_models.hpp"
#include "tests/test_support.hpp"

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

TEST(BodyGeometry, SurfacesAreClosedOutwardAndEncloseThePolyhedronVolume) {
  // Every directed edge of a closed, consistently oriented surface is matched by its
  // reverse exactly once; the enclosed volume (1/6) sum p0 . (p1 x p2) over the faces'
  // fan triangles (divergence theorem) is positive for outward faces and equals the
  // polyhedron's: a box's a b c; an n-sided prism's n/2 sin(2 pi/n) r^2 h (the cylinder's
  // and, with ro^2 - ri^2, the tube's); for the sphere of n meridians within 3 % of 4/3 pi
  // r^3 from below (inscribed). Offsets and rotations do not change a closed volume.
  const int n = 24;
  const auto check = [&](const SolidShape& s, double expected, double tol) {
    const SurfaceMesh m = surfaceMesh(s, n);
    std::map<std::pair<int, int>, int> edges;
    double volume = 0.0;
    for (const auto& f : m.faces) {
      for (std::size_t k = 0; k < f.size(); ++k) ++edges[{f[k], f[(k + 1) % f.size()]}];
      for (std::size_t k = 1; k + 1 < f.size(); ++k) {
        volume += m.points[f[0]].dot(m.points[f[k]].cross(m.points[f[k + 1]])) / 6.0;
      }
    }
    for (const auto& [e, count] : edges) {
      EXPECT_EQ(count, 1) << "edge " << e.first << "-" << e.second;
      EXPECT_EQ(edges.count({e.second, e.first}), 1u) << "edge " << e.first << "-" << e.second << " has no twin";
    }
    EXPECT_NEAR(volume / expected, 1.0, tol) << static_cast<int>(s.type);
  };
  const double prism = n / 2.0 * std::sin(2 * M_PI / n);
  SolidShape box;
  box.size = Vec3(0.3, 0.2, 0.1);
  check(box, 0.006, 1e-14);
  SolidShape cyl;
  cyl.type = SolidShape::Type::Cylinder;
  cyl.radius = 0.05;
  cyl.length = 0.4;
  cyl.axis = 0;
  cyl.offset = Vec3(1.0, -2.0, 0.5);
  cyl.orientation = quaternionRotation(quaternionFromAxisAngle(Vec3(1, 1, 0), 0.3));
  check(cyl, prism * 0.0025 * 0.4, 1e-12);  // rounding of the rotated, offset points
  SolidShape tube = cyl;
  tube.type = SolidShape::Type::Tube;
  tube.innerRadius = 0.04;
  tube.axis = 1;
  check(tube, prism * (0.0025 - 0.0016) * 0.4, 1e-12);
  SolidShape sphere;
  sphere.type = SolidShape::Type::Sphere;
  sphere.radius = 0.1;
  const double exact = 4.0 / 3.0 * M_PI * 1e-3;
  check(sphere, 0.985 * exact, 0.015);
  // the axis: a cylinder along body y has its points' extent 0.4 along y
  cyl.axis = 1;
  cyl.offset = Vec3::Zero();
  cyl.orientation = Mat3::Identity();
  double ymax = 0.0;
  for (const Vec3& p : surfaceMesh(cyl, n).points) ymax = std::max(ymax, p.y());
  EXPECT_NEAR(ymax, 0.2, 1e-15);
}

TEST(VtkWriter, GeometryIsDrawnAsPolygonsWhereTheBodyIs) {
  // A spatial box body turned and moved, with a box "geometry" offset in it: the drawn
  // corners are R + A (offset + corner) (to the 12 digits the file holds); a planar body
  // with a cylinder; cells of type VTK_POLYGON (7) after the bodies' lines.
  nlohmann::json j = nlohmann::json::parse(R"({"dimension": 3, "bodies": [{"name": "b", "type": "rigid",
      "mass": 1, "inertia": [1, 1, 1], "position": [0.5, -1, 2], "orientation": {"axis": [0, 0, 1], "angle": 0.5},
      "geometry": [{"type": "box", "size": [0.2, 0.1, 0.1], "offset": [0.1, 0, 0]}]}]})");
  const Scene sc = parseScene(j);
  ASSERT_EQ(sc.geometry.size(), 1u);
  const fs::path dir = fs::temp_directory_path() / ("flexmbd_vtkgeo_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  OutputSample o;
  o.q = sc.system.initialCoordinates();
  o.v = sc.system.initialVelocities();
  {
    VtkWriter vtk(dir, sc.system, "bodies", 4, sc.geometry);
    vtk.write(o);
  }
  std::string vtu = read(dir / "bodies_000000.vtu");
  std::vector<int> types = intArray(vtu, "types");
  ASSERT_EQ(std::count(types.begin(), types.end(), 7), 6);  // the box's faces
  const std::vector<double> pts = dataArray(vtu, "");
  const Mat3 A = quaternionRotation(quaternionFromAxisAngle(Vec3(0, 0, 1), 0.5));
  const Vec3 corner = Vec3(0.5, -1, 2) + A * Vec3(0.1 + 0.1, 0.05, 0.05);  // the last of the 8 corners
  const std::size_t last = pts.size() - 3;
  EXPECT_LT((Vec3(pts[last], pts[last + 1], pts[last + 2]) - corner).norm(), 1e-11);
  EXPECT_EQ(dataArray(vtu, "elastic_displacement").size(), pts.size());  // point data for every point
  fs::remove_all(dir);
  // planar: a crank with a cylinder about its pin (axis z): drawn, not "not drawn"
  nlohmann::json p = nlohmann::json::parse(R"({"bodies": [{"name": "crank", "type": "rigid", "mass": 1,
      "inertia": 0.1, "geometry": {"type": "cylinder", "radius": 0.02, "length": 0.01}}]})");
  const Scene ps = parseScene(p);
  o.q = ps.system.initialCoordinates();
  o.v = ps.system.initialVelocities();
  {
    VtkWriter vtk(dir, ps.system, "bodies", 4, ps.geometry);
    EXPECT_TRUE(vtk.bodiesNotDrawn().empty());
    vtk.write(o);
  }
  vtu = read(dir / "bodies_000000.vtu");
  types = intArray(vtu, "types");
  EXPECT_EQ(std::count(types.begin(), types.end(), 7), 24 + 2);  // side facets and two ends
  fs::remove_all(dir);
  // geometry has no mass, and flexible bodies do not take it
  p["bodies"][0]["geometry"]["mass"] = 1.0;
  testsupport::expectInputError([&] { parseScene(p); }, {"bodies[0] (\"crank\").geometry", "mass", "viewing only"});
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
