#include "results/vtk_writer.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

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
    : collection_(dir, std::move(prefix)), drawer_(sys, subdivisions, geometry, feBodies) {}

void VtkWriter::write(const OutputSample& s) {
  Drawing d = drawer_.draw(s.q);
  Grid g;
  g.points = std::move(d.points);
  g.cells = std::move(d.cells);
  g.cellTypes.reserve(d.cellKinds.size());
  for (Drawing::CellKind k : d.cellKinds) g.cellTypes.push_back(k == Drawing::CellKind::Polygon ? kVtkPolygon : kVtkPolyLine);
  g.pointScalars = std::move(d.pointScalars);
  g.pointVectors = std::move(d.pointVectors);
  g.cellInts = {{"body_index", std::move(d.cellBody)}};
  g.fieldStrings = {{"body_names", std::move(d.bodyNames)}};
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
    force.push_back(s_.strutForce(smp.x, i));  // N = EA (l - l0) / l0 (Doc001)
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
