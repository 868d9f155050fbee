#include "io/vtk_writer.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "bodies/fe_stress.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "joints/spatial_joint.hpp"
#include "core/errors.hpp"
#include "tensegrity/tensegrity_structure.hpp"

namespace flexmbd {
namespace {

constexpr int kVtkLine = 3;      // VTK_LINE
constexpr int kVtkPolyLine = 4;  // VTK_POLY_LINE
constexpr int kVtkPolygon = 7;   // VTK_POLYGON

/// One frame: points (3D), cells (of type cellType, or of cellTypes[k] where given),
/// named point/cell arrays and the string arrays of its field data.
struct Grid {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> cells;
  int cellType = kVtkPolyLine;
  std::vector<int> cellTypes;  ///< per cell; cells beyond its size are of cellType
  std::vector<std::pair<std::string, std::vector<double>>> pointScalars, cellScalars;
  std::vector<std::pair<std::string, std::vector<Eigen::Vector3d>>> pointVectors;
  std::vector<std::pair<std::string, std::vector<int>>> cellInts;
  std::vector<std::pair<std::string, std::vector<std::string>>> fieldStrings;
};

/// A name inside an XML comment: "--" may not appear there.
std::string commentSafe(std::string s) {
  for (std::size_t k = s.find("--"); k != std::string::npos; k = s.find("--", k)) s.replace(k, 2, "- ");
  return s;
}

std::string timeText(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", t);
  return buf;
}

/// Writes the frame as an ASCII .vtu; a frame that cannot be written whole is removed.
void writeVtu(const std::filesystem::path& path, const Grid& g, double t) {
  std::ofstream out(path);
  if (!out) throw OutputWriteError("cannot write '" + path.string() + "' at t = " + timeText(t));
  out.precision(12);
  out << "<?xml version=\"1.0\"?>\n";
  for (const auto& [name, values] : g.fieldStrings) {
    out << "<!-- " << name << ":";
    for (std::size_t k = 0; k < values.size(); ++k) out << (k ? ", " : " ") << commentSafe(values[k]);
    out << " -->\n";
  }
  out << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n";
  if (!g.fieldStrings.empty()) {
    // String arrays in ASCII: the character codes of every string, each string ended by 0
    // (as vtkXMLWriter writes them); ParaView reads them back as strings.
    out << "<FieldData>\n";
    for (const auto& [name, values] : g.fieldStrings) {
      out << "<DataArray type=\"String\" Name=\"" << name << "\" NumberOfTuples=\"" << values.size()
          << "\" format=\"ascii\">\n";
      for (const std::string& v : values) {
        for (char c : v) out << static_cast<int>(static_cast<signed char>(c)) << ' ';  // as VTK: short(char)
        out << "0\n";
      }
      out << "</DataArray>\n";
    }
    out << "</FieldData>\n";
  }
  out << "<Piece NumberOfPoints=\"" << g.points.size() << "\" NumberOfCells=\"" << g.cells.size()
      << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : g.points) out << p.x() << " " << p.y() << " " << p.z() << "\n";
  out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& l : g.cells) {
    for (int i : l) out << i << " ";
    out << "\n";
  }
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  long offset = 0;
  for (const auto& l : g.cells) out << (offset += static_cast<long>(l.size())) << " ";
  out << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t k = 0; k < g.cells.size(); ++k) out << (k < g.cellTypes.size() ? g.cellTypes[k] : g.cellType) << " ";
  out << "\n</DataArray>\n</Cells>\n";
  if (!g.pointScalars.empty() || !g.pointVectors.empty()) {
    out << "<PointData";
    if (!g.pointScalars.empty()) out << " Scalars=\"" << g.pointScalars.front().first << "\"";
    out << ">\n";
    for (const auto& [name, values] : g.pointScalars) {
      out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (double v : values) out << v << "\n";
      out << "</DataArray>\n";
    }
    for (const auto& [name, values] : g.pointVectors) {
      out << "<DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
      for (const auto& d : values) out << d.x() << " " << d.y() << " " << d.z() << "\n";
      out << "</DataArray>\n";
    }
    out << "</PointData>\n";
  }
  if (!g.cellScalars.empty() || !g.cellInts.empty()) {
    out << "<CellData>\n";
    for (const auto& [name, values] : g.cellScalars) {
      out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (double v : values) out << v << "\n";
      out << "</DataArray>\n";
    }
    for (const auto& [name, values] : g.cellInts) {
      out << "<DataArray type=\"Int32\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (int v : values) out << v << "\n";
      out << "</DataArray>\n";
    }
    out << "</CellData>\n";
  }
  out << "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  out.close();
  if (!out) {
    std::error_code ec;
    std::filesystem::remove(path, ec);  // no partial frame
    throw OutputWriteError("cannot write '" + path.string() + "' at t = " + timeText(t) + " (disk full?)");
  }
}

Eigen::Vector3d in3d(const Vec2& p) { return {p.x(), p.y(), 0.0}; }

/// Appends a rigid body's geometry surfaces (polygon cells) at state q.
void addSurfaces(const Body& body, const ConstVecRef& q, const std::vector<SurfaceMesh>& surfaces, Grid& g) {
  if (surfaces.empty()) return;
  // the body frame's pose: a spatial body's centre of mass and rotation; a planar body's
  // points in its plane (z kept: the plane is z = 0, the body turns about z)
  const auto* r3 = dynamic_cast<const RigidBody3d*>(&body);
  const Vec3 c = r3 ? body.centreOfMass(q) : Vec3::Zero();
  const Mat3 A = r3 ? RigidBody3d::rotationOf(q) : Mat3::Identity();
  const auto world = [&](const Vec3& u) -> Eigen::Vector3d {
    if (r3) return c + A * u;
    const Vec2 p = body.pointKinematics(q, u.head<2>(), false).r;
    return {p.x(), p.y(), u.z()};
  };
  g.cellTypes.resize(g.cells.size(), g.cellType);
  for (const SurfaceMesh& m : surfaces) {
    const int first = static_cast<int>(g.points.size());
    for (const Vec3& u : m.points) g.points.push_back(world(u));
    for (const std::vector<int>& f : m.faces) {
      std::vector<int> cell(f.size());
      for (std::size_t k = 0; k < f.size(); ++k) cell[k] = first + f[k];
      g.cells.push_back(std::move(cell));
      g.cellTypes.push_back(kVtkPolygon);
    }
  }
}


}  // namespace

// ----- the collection -----------------------------------------------------------------------

VtkCollection::VtkCollection(const std::filesystem::path& dir, std::string prefix)
    : dir_(dir), prefix_(std::move(prefix)) {
  std::error_code ec;
  if (std::filesystem::exists(dir_, ec) && !std::filesystem::is_directory(dir_, ec)) {
    throw InputError("--vtk: '" + dir_.string() + "' exists and is not a directory (the VTK frames are written "
                     "into it): remove it or give another --out");
  }
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw InputError("--vtk: cannot create the folder '" + dir_.string() + "': " + ec.message());
}

std::filesystem::path VtkCollection::nextFrame() const {
  char name[64];
  std::snprintf(name, sizeof(name), "_%06ld.vtu", static_cast<long>(times_.size()));
  return dir_ / (prefix_ + name);
}

void VtkCollection::add(double t) {
  times_.push_back(t);
  const std::filesystem::path path = dir_ / (prefix_ + ".pvd");
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (size_t k = 0; k < times_.size(); ++k) {
    char name[64];
    std::snprintf(name, sizeof(name), "_%06zu.vtu", k);
    out << "<DataSet timestep=\"" << times_[k] << "\" file=\"" << prefix_ << name << "\"/>\n";
  }
  out << "</Collection>\n</VTKFile>\n";
}

// ----- multibody systems ----------------------------------------------------------------------

VtkWriter::VtkWriter(const std::filesystem::path& dir, const System& sys, std::string prefix, int subdivisions,
                     const std::vector<BodyGeometry>& geometry, const std::vector<FeBodyDrawing>& feBodies)
    : collection_(dir, std::move(prefix)),
      sys_(sys),
      subdivisions_(std::max(1, subdivisions)),
      feBodies_(feBodies),
      feIndex_(sys.numBodies(), -1) {
  for (std::size_t k = 0; k < feBodies_.size(); ++k) feIndex_.at(feBodies_[k].body.value) = static_cast<int>(k);
  surfaces_.resize(sys.numBodies());
  for (const BodyGeometry& g : geometry) {
    for (const SolidShape& shape : g.shapes) surfaces_.at(g.body.value).push_back(surfaceMesh(shape));
  }
  rigidPoints_.resize(sys.numBodies());
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    if (const auto* rb = dynamic_cast<const RigidBody2d*>(&body)) {
      rigidPoints_[b] = {Vec2::Zero(), rb->com()};
    } else if (const auto* fb = dynamic_cast<const FfrBody2d*>(&body); fb && !fb->beamModel()) {
      // flexible_invariants: its attachment points are the only points it can place
      for (const FfrPoint& p : fb->invariants().points) rigidPoints_[b].push_back(p.position);
    }
  }
  const auto addPoint = [&](BodyIndex b, const Vec2& p) {
    if (b.value <= 0 || !dynamic_cast<const RigidBody2d*>(&sys.body(b))) return;
    auto& pts = rigidPoints_[b.value];
    for (const Vec2& q : pts) {
      if ((q - p).norm() < 1e-12) return;
    }
    pts.push_back(p);
  };
  for (int c = 0; c < sys.numConstraints(); ++c) {
    for (const auto& [b, p] : sys.constraint(ConstraintIndex(c)).attachments()) addPoint(b, p.head<2>());
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    for (const auto& [b, p] : sys.force(ForceIndex(f)).attachments()) addPoint(b, p.head<2>());
  }
  // spatial bodies: lines from the centre of mass to each joint frame on the body
  spatialPoints_.resize(sys.numBodies());
  for (int c = 0; c < sys.numConstraints(); ++c) {
    if (const auto* j = dynamic_cast<const SpatialJoint*>(&sys.constraint(ConstraintIndex(c)))) {
      spatialPoints_[j->bodies()[0].value].push_back(j->frameI().point);
      spatialPoints_[j->bodies()[1].value].push_back(j->frameJ().point);
    }
  }
  triad_ = 0.1 * sys.characteristicLength();
  for (int b = 1; b < sys.numBodies(); ++b) {
    const Body& body = sys.body(BodyIndex(b));
    const auto* fb = dynamic_cast<const FfrBody2d*>(&body);
    const auto* f3 = dynamic_cast<const FfrBody3d*>(&body);
    const bool spatial = dynamic_cast<const RigidBody3d*>(&body) != nullptr ||
                         (f3 && (f3->model() || !f3->invariants().points.empty()));
    if (rigidPoints_[b].empty() && !(fb && fb->beamModel()) && !spatial && surfaces_[b].empty()) {
      notDrawn_.push_back(body.name());
    }
  }
}

void VtkWriter::write(const OutputSample& s) {
  Grid g;
  std::vector<double> axial, moment, vonMisesStress;
  std::vector<Eigen::Vector3d> displacement, sectionForce, sectionMoment;  // element axes
  std::vector<int> bodyIndex;
  std::vector<std::string> bodyNames;
  for (int b = 1; b < sys_.numBodies(); ++b) {
    const Body& body = sys_.body(BodyIndex(b));
    const auto q = s.q.segment(sys_.coordinateOffset(BodyIndex(b)), body.numCoordinates());
    const int cellsBefore = static_cast<int>(g.cells.size());
    const auto* fb = dynamic_cast<const FfrBody2d*>(&body);
    if (dynamic_cast<const RigidBody3d*>(&body)) {
      // an oriented body: a triad of its axes at the centre of mass (the cells' order: x, y,
      // z) and a line to each joint point
      const Vec3 c = body.centreOfMass(q);
      const Mat3 A = RigidBody3d::rotationOf(q);
      auto addLine = [&](const Vec3& a, const Vec3& b) {
        g.cells.push_back({static_cast<int>(g.points.size()), static_cast<int>(g.points.size()) + 1});
        for (const Vec3& p : {a, b}) {
          g.points.push_back(p);
          displacement.push_back(Vec3::Zero());
          axial.push_back(0.0);
          moment.push_back(0.0);
        }
      };
      for (int k = 0; k < 3; ++k) addLine(c, c + triad_ * A.col(k));
      for (const Vec3& p : spatialPoints_[b]) addLine(c, c + A * p);
    } else if (const auto* f3 = dynamic_cast<const FfrBody3d*>(&body)) {
      if (f3->model()) {
        // the deformed axis, each element in `subdivisions_` segments, with the section
        // forces (N, Qy, Qz) and moments (Mx, My, Mz) in element axes
        const int elements = static_cast<int>(f3->model()->elements().size());
        for (int e = 0; e < elements; ++e) {
          std::vector<int> line;
          for (int k = 0; k <= subdivisions_; ++k) {
            const double xi = static_cast<double>(k) / subdivisions_;
            const FfrBody3d::BeamDeflection d = f3->beamDeflection(q, e, xi);
            const BeamSectionForces3d& f = d.sectionForces;
            line.push_back(static_cast<int>(g.points.size()));
            g.points.push_back(d.position);
            displacement.push_back(d.worldDisplacement);
            axial.push_back(f.N);
            moment.push_back(std::hypot(f.My, f.Mz));
            sectionForce.push_back(Vec3(f.N, f.Qy, f.Qz));
            sectionMoment.push_back(Vec3(f.Mx, f.My, f.Mz));
          }
          g.cells.push_back(line);
        }
      } else if (feIndex_[b] >= 0) {
        // an fe_body: its outer surface through the deformed nodes (node a = point a)
        const FeBodyDrawing& fe = feBodies_[feIndex_[b]];
        const auto& pts = f3->invariants().points;
        const Mat3 A = FfrBody3d::rotationOf(q);
        const VecX qf = q.tail(f3->numElastic());
        const int first = static_cast<int>(g.points.size());
        for (std::size_t a = 0; a < fe.surface.points.size(); ++a) {
          const Vec3 u = pts[a].shape * qf;
          g.points.push_back(q.head<3>() + A * (pts[a].position + u));
          displacement.push_back(A * u);
          axial.push_back(0.0);
          moment.push_back(0.0);
          vonMisesStress.push_back(fe.stressShapes.size() == 0
                                       ? 0.0
                                       : vonMises(fe.stressShapes.middleRows<6>(6 * static_cast<int>(a)) * qf));
        }
        g.cellTypes.resize(g.cells.size(), g.cellType);
        for (const std::vector<int>& f : fe.surface.faces) {
          std::vector<int> cell(f.size());
          for (std::size_t k = 0; k < f.size(); ++k) cell[k] = first + f[k];
          g.cells.push_back(std::move(cell));
          g.cellTypes.push_back(kVtkPolygon);
        }
      } else if (!f3->invariants().points.empty()) {
        // given invariants: the line through its attachment points
        const auto& pts = f3->invariants().points;
        const Mat3 A = FfrBody3d::rotationOf(q);
        std::vector<int> line;
        for (std::size_t k = 0; k < pts.size(); ++k) {
          FrameKinematics fk;
          body.frameKinematics(q, pts[k].position, static_cast<int>(k), nullptr, nullptr, fk);
          line.push_back(static_cast<int>(g.points.size()));
          g.points.push_back(fk.r);
          displacement.push_back(A * (pts[k].shape * q.tail(f3->numElastic())));
          axial.push_back(0.0);
          moment.push_back(0.0);
        }
        g.cells.push_back(line);
      }
    } else if (fb && fb->beamModel()) {
      const int elements = static_cast<int>(fb->beamModel()->elements().size());
      for (int e = 0; e < elements; ++e) {
        std::vector<int> line;
        for (int k = 0; k <= subdivisions_; ++k) {
          const double xi = static_cast<double>(k) / subdivisions_;
          const FfrBody2d::BeamDeflection d = fb->beamDeflection(q, e, xi);
          line.push_back(static_cast<int>(g.points.size()));
          g.points.push_back(in3d(d.position));
          displacement.push_back(in3d(d.worldDisplacement));
          axial.push_back(d.sectionForces.x());
          moment.push_back(d.sectionForces.y());
        }
        g.cells.push_back(line);
      }
    } else if (!rigidPoints_[b].empty()) {
      std::vector<int> line;
      for (std::size_t k = 0; k < rigidPoints_[b].size(); ++k) {
        line.push_back(static_cast<int>(g.points.size()));
        g.points.push_back(in3d(body.pointKinematics(q, rigidPoints_[b][k], false).r));
        // invariants body: u = S_k q_f of its k-th point, world axes
        displacement.push_back(fb ? in3d(fb->worldElasticDisplacement(q, fb->invariants().points[k]))
                                  : Eigen::Vector3d::Zero());
        axial.push_back(0.0);
        moment.push_back(0.0);
      }
      g.cells.push_back(line);
    }
    addSurfaces(body, q, surfaces_[b], g);
    // bodies other than spatial beams carry no section force and moment vectors
    displacement.resize(g.points.size(), Vec3::Zero());
    axial.resize(g.points.size(), 0.0);
    moment.resize(g.points.size(), 0.0);
    sectionForce.resize(g.points.size(), Vec3::Zero());
    sectionMoment.resize(g.points.size(), Vec3::Zero());
    vonMisesStress.resize(g.points.size(), 0.0);
    if (static_cast<int>(g.cells.size()) > cellsBefore) {
      bodyIndex.resize(g.cells.size(), static_cast<int>(bodyNames.size()));
      bodyNames.push_back(body.name());
    }
  }
  g.pointScalars = {{"axial_force", std::move(axial)},
                    {"bending_moment", std::move(moment)},
                    {"von_mises", std::move(vonMisesStress)}};
  g.pointVectors = {{"elastic_displacement", std::move(displacement)},
                    {"section_force", std::move(sectionForce)},
                    {"section_moment", std::move(sectionMoment)}};
  g.cellInts = {{"body_index", std::move(bodyIndex)}};
  g.fieldStrings = {{"body_names", std::move(bodyNames)}};
  writeVtu(collection_.nextFrame(), g, s.t);
  collection_.add(s.t);
}

// ----- tensegrity structures ------------------------------------------------------------------

TensegrityVtkWriter::TensegrityVtkWriter(const std::filesystem::path& dir, const TensegrityStructure& s,
                                         std::string name, std::string prefix)
    : collection_(dir, std::move(prefix)), s_(s), name_(name.empty() ? "tensegrity" : std::move(name)) {}

void TensegrityVtkWriter::write(const TensegritySample& smp) {
  Grid g;
  g.cellType = kVtkLine;
  const int d = s_.dimension();
  std::vector<Eigen::Vector3d> velocity;
  for (int i = 0; i < s_.numNodes(); ++i) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
    for (int a = 0; a < d; ++a) {
      x[a] = smp.x[d * i + a];
      v[a] = smp.v[d * i + a];
    }
    g.points.push_back(x);
    velocity.push_back(v);
  }
  std::vector<double> force;
  std::vector<int> type, slack;
  std::vector<std::string> names;
  for (int i = 0; i < s_.numStruts(); ++i) {
    g.cells.push_back({s_.strut(i).nodeI, s_.strut(i).nodeJ});
    force.push_back(s_.strutForce(smp.x, i));  // N = EA (l - l0) / l0
    type.push_back(0);
    slack.push_back(0);
    names.push_back(s_.strut(i).name);
  }
  for (int c = 0; c < s_.numCables(); ++c) {
    g.cells.push_back({s_.cable(c).nodeI, s_.cable(c).nodeJ});
    force.push_back(smp.cableTension[c]);
    type.push_back(1);
    slack.push_back(smp.slack[c] ? 1 : 0);
    names.push_back(s_.cable(c).name);
  }
  g.pointVectors = {{"velocity", std::move(velocity)}};
  g.cellScalars = {{"axial_force", std::move(force)}};
  g.cellInts = {{"member_type", std::move(type)}, {"slack", std::move(slack)}};
  g.fieldStrings = {{"body_names", {name_}}, {"member_names", std::move(names)}};
  writeVtu(collection_.nextFrame(), g, smp.t);
  collection_.add(smp.t);
}

}  // namespace flexmbd
