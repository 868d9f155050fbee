#include "io/vtk_writer.hpp"

#include <cstdio>
#include <stdexcept>

#include "bodies/ffr_body_2d.hpp"
#include "bodies/rigid_body_2d.hpp"

namespace flexmbd {

VtkWriter::VtkWriter(const std::filesystem::path& dir, const System& sys, std::string prefix, int subdivisions)
    : dir_(dir), sys_(sys), prefix_(std::move(prefix)), subdivisions_(std::max(1, subdivisions)) {
  std::filesystem::create_directories(dir_);
  rigidPoints_.resize(sys.numBodies());
  for (int b = 1; b < sys.numBodies(); ++b) {
    if (const auto* rb = dynamic_cast<const RigidBody2d*>(&sys.body(BodyIndex(b)))) {
      rigidPoints_[b] = {Vec2::Zero(), rb->com()};
    }
  }
  const auto addPoint = [&](BodyIndex b, const Vec2& p) {
    auto& pts = rigidPoints_[b.value];
    if (b.value > 0 && !pts.empty()) {
      for (const Vec2& q : pts) {
        if ((q - p).norm() < 1e-12) return;
      }
      pts.push_back(p);
    }
  };
  for (int c = 0; c < sys.numConstraints(); ++c) {
    for (const auto& [b, p] : sys.constraint(ConstraintIndex(c)).attachments()) addPoint(b, p);
  }
  for (int f = 0; f < sys.numForces(); ++f) {
    for (const auto& [b, p] : sys.force(ForceIndex(f)).attachments()) addPoint(b, p);
  }
}

void VtkWriter::write(const OutputSample& s) {
  std::vector<Vec2> points;
  std::vector<Vec2> displacement;
  std::vector<double> axial, moment;
  std::vector<std::vector<int>> lines;
  for (int b = 1; b < sys_.numBodies(); ++b) {
    const Body& body = sys_.body(BodyIndex(b));
    const auto q = s.q.segment(sys_.coordinateOffset(BodyIndex(b)), body.numCoordinates());
    if (const auto* fb = dynamic_cast<const FfrBody2d*>(&body); fb && fb->beamModel()) {
      const FfrBeamModel& m = *fb->beamModel();
      const VecX qf = q.tail(m.numElastic());
      const Mat2 A = rotation(q[2]);
      for (int e = 0; e < static_cast<int>(m.elements().size()); ++e) {
        std::vector<int> line;
        for (int k = 0; k <= subdivisions_; ++k) {
          const double xi = static_cast<double>(k) / subdivisions_;
          const FfrPoint p = m.materialPoint(e, xi);
          const Vec2 u = p.shape * qf;
          line.push_back(static_cast<int>(points.size()));
          points.push_back(q.head<2>() + A * (p.position + u));
          displacement.push_back(A * u);
          const Vec2 nm = m.sectionForces(qf, e, xi);
          axial.push_back(nm.x());
          moment.push_back(nm.y());
        }
        lines.push_back(line);
      }
    } else if (!rigidPoints_[b].empty()) {
      std::vector<int> line;
      for (const Vec2& p : rigidPoints_[b]) {
        line.push_back(static_cast<int>(points.size()));
        points.push_back(body.pointKinematics(q, p, false).r);
        displacement.push_back(Vec2::Zero());
        axial.push_back(0.0);
        moment.push_back(0.0);
      }
      lines.push_back(line);
    }
  }
  char name[64];
  std::snprintf(name, sizeof(name), "_%06ld.vtu", static_cast<long>(times_.size()));
  const std::filesystem::path path = dir_ / (prefix_ + name);
  std::ofstream out(path);
  if (!out) throw OutputWriteError("cannot write '" + path.string() + "' at t = " + std::to_string(s.t));
  out.precision(12);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << points.size() << "\" NumberOfCells=\"" << lines.size()
      << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const Vec2& p : points) out << p.x() << " " << p.y() << " 0\n";
  out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& l : lines) {
    for (int i : l) out << i << " ";
    out << "\n";
  }
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  long offset = 0;
  for (const auto& l : lines) out << (offset += static_cast<long>(l.size())) << " ";
  out << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t k = 0; k < lines.size(); ++k) out << "4 ";  // VTK_POLY_LINE
  out << "\n</DataArray>\n</Cells>\n<PointData Scalars=\"axial_force\">\n"
      << "<DataArray type=\"Float64\" Name=\"axial_force\" format=\"ascii\">\n";
  for (double v : axial) out << v << "\n";
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"bending_moment\" format=\"ascii\">\n";
  for (double v : moment) out << v << "\n";
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"elastic_displacement\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (const Vec2& d : displacement) out << d.x() << " " << d.y() << " 0\n";
  out << "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  out.close();
  if (!out) {
    std::error_code ec;
    std::filesystem::remove(path, ec);  // no partial frame
    throw OutputWriteError("cannot write '" + path.string() + "' at t = " + std::to_string(s.t) + " (disk full?)");
  }
  times_.push_back(s.t);
  writeCollection();
}

void VtkWriter::writeCollection() const {
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

}  // namespace flexmbd
