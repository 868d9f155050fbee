#include "viewer/system_drawing.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "bodies/fe_stress.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "joints/revolute_joint.hpp"
#include "joints/spatial_joint.hpp"

namespace flexmbd {
namespace {

Vec3 in3d(const Vec2& p) { return {p.x(), p.y(), 0.0}; }

bool isSpatialBody(const Body& body) {
  return dynamic_cast<const RigidBody3d*>(&body) != nullptr || dynamic_cast<const FfrBody3d*>(&body) != nullptr;
}

/// The point list of one state being drawn: a point with its quantities (zero unless set).
struct Pen {
  Drawing& d;
  std::vector<Vec3>& displacement;
  std::vector<double>& axial;
  std::vector<double>& moment;
  int add(const Vec3& p, const Vec3& u = Vec3::Zero(), double n = 0.0, double m = 0.0) {
    d.points.push_back(p);
    displacement.push_back(u);
    axial.push_back(n);
    moment.push_back(m);
    return static_cast<int>(d.points.size()) - 1;
  }
  void cell(std::vector<int> c, Drawing::CellKind kind) {
    d.cells.push_back(std::move(c));
    d.cellKinds.push_back(kind);
  }
};

/// Appends a rigid body's surfaces (polygons) at state q: a spatial body's centre of mass
/// and rotation place them; a planar body's points lie in its plane (z kept).
void addSurfaces(const Body& body, const ConstVecRef& q, const std::vector<SurfaceMesh>& surfaces, Pen& pen) {
  if (surfaces.empty()) return;
  const auto* r3 = dynamic_cast<const RigidBody3d*>(&body);
  const Vec3 c = r3 ? body.centreOfMass(q) : Vec3::Zero();
  const Mat3 A = r3 ? RigidBody3d::rotationOf(q) : Mat3::Identity();
  const auto world = [&](const Vec3& u) -> Vec3 {
    if (r3) return c + A * u;
    const Vec2 p = body.pointKinematics(q, u.head<2>(), false).r;
    return {p.x(), p.y(), u.z()};
  };
  for (const SurfaceMesh& m : surfaces) {
    const int first = static_cast<int>(pen.d.points.size());
    for (const Vec3& u : m.points) pen.add(world(u));
    for (const std::vector<int>& f : m.faces) {
      std::vector<int> cell(f.size());
      for (std::size_t k = 0; k < f.size(); ++k) cell[k] = first + f[k];
      pen.cell(std::move(cell), Drawing::CellKind::Polygon);
    }
  }
}

}  // namespace

Vec3 inertiaBoxSides(double mass, const Vec3& I) {
  Vec3 s2;
  // a_k^2 = 6 (I_j + I_l - I_k) / m, from the box's moments (MeriamKraige, table D/4)
  for (int k = 0; k < 3; ++k) s2[k] = 6.0 * (I.sum() - 2.0 * I[k]) / mass;
  Vec3 s = s2.cwiseMax(0.0).cwiseSqrt();
  const double floor = 1e-3 * s.maxCoeff();
  return s.cwiseMax(floor);
}

SystemDrawer::SystemDrawer(const System& sys, int subdivisions, const std::vector<BodyGeometry>& geometry,
                           const std::vector<FeBodyDrawing>& feBodies, bool inertiaBoxes)
    : sys_(sys), subdivisions_(std::max(1, subdivisions)), feBodies_(feBodies), feIndex_(sys.numBodies(), -1) {
  for (std::size_t k = 0; k < feBodies_.size(); ++k) feIndex_.at(feBodies_[k].body.value) = static_cast<int>(k);
  surfaces_.resize(sys.numBodies());
  for (const BodyGeometry& g : geometry) {
    for (const SolidShape& shape : g.shapes) surfaces_.at(g.body.value).push_back(surfaceMesh(shape));
  }
  if (inertiaBoxes) {
    for (int b = 1; b < sys.numBodies(); ++b) {
      const auto* r3 = dynamic_cast<const RigidBody3d*>(&sys.body(BodyIndex(b)));
      if (!r3 || !surfaces_[b].empty()) continue;
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(r3->inertia());
      SolidShape box;
      box.size = inertiaBoxSides(r3->mass(), eig.eigenvalues());
      box.orientation = eig.eigenvectors();
      if (box.orientation.determinant() < 0) box.orientation.col(2) *= -1.0;
      surfaces_[b].push_back(surfaceMesh(box));
    }
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
  if (inertiaBoxes) {
    // a planar rigid body whose points coincide (a slider) would be drawn as nothing: the
    // square plate of its inertia, J = m a^2 / 6 (MeriamKraige, table D/4), a kept within 2 % and 20 % of the model
    const double L = sys.characteristicLength();
    for (int b = 1; b < sys.numBodies(); ++b) {
      const auto* rb = dynamic_cast<const RigidBody2d*>(&sys.body(BodyIndex(b)));
      if (!rb || !surfaces_[b].empty()) continue;
      double span = 0.0;
      for (const Vec2& p : rigidPoints_[b]) span = std::max(span, (p - rigidPoints_[b].front()).norm());
      if (span > 1e-9 * L) continue;
      const double a = std::clamp(std::sqrt(6.0 * rb->inertia() / rb->mass()), 0.02 * L, 0.2 * L);
      SolidShape plate;
      plate.size = Vec3(a, a, 0.5 * a);
      plate.offset = Vec3(rb->com().x(), rb->com().y(), 0.0);
      surfaces_[b].push_back(surfaceMesh(plate));
    }
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

Drawing SystemDrawer::draw(const VecX& q) const {
  Drawing d;
  d.pointVectors = {{"elastic_displacement", {}}, {"section_force", {}}, {"section_moment", {}}};
  d.pointScalars = {{"axial_force", {}}, {"bending_moment", {}}, {"von_mises", {}}};
  for (int b = 1; b < sys_.numBodies(); ++b) {
    const Body& body = sys_.body(BodyIndex(b));
    const auto qb = q.segment(sys_.coordinateOffset(BodyIndex(b)), body.numCoordinates());
    const int cellsBefore = static_cast<int>(d.cells.size());
    drawBody(b, qb, d);
    if (static_cast<int>(d.cells.size()) > cellsBefore) {
      d.cellBody.resize(d.cells.size(), static_cast<int>(d.bodyNames.size()));
      d.bodyNames.push_back(body.name());
    }
  }
  drawJoints(q, d);
  return d;
}

void SystemDrawer::drawBody(int b, const ConstVecRef& q, Drawing& d) const {
  const Body& body = sys_.body(BodyIndex(b));
  const std::size_t first = d.points.size();
  // the body's points with their quantities (appended to d's arrays at the end)
  std::vector<Vec3> displacement, sectionForce, sectionMoment;
  std::vector<double> axial, moment, vonMisesStress;
  Pen pen{d, displacement, axial, moment};
  const auto* fb = dynamic_cast<const FfrBody2d*>(&body);
  if (dynamic_cast<const RigidBody3d*>(&body)) {
    // an oriented body: a triad of its axes at the centre of mass (the cells' order: x, y,
    // z) and a line to each joint point
    const Vec3 c = body.centreOfMass(q);
    const Mat3 A = RigidBody3d::rotationOf(q);
    const auto addLine = [&](const Vec3& a, const Vec3& e) {
      const int i = pen.add(a);
      pen.cell({i, pen.add(e)}, Drawing::CellKind::PolyLine);
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
          const FfrBody3d::BeamDeflection bd = f3->beamDeflection(q, e, xi);
          const BeamSectionForces3d& f = bd.sectionForces;
          line.push_back(pen.add(bd.position, bd.worldDisplacement, f.N, std::hypot(f.My, f.Mz)));
          sectionForce.resize(line.back() - first, Vec3::Zero());
          sectionMoment.resize(line.back() - first, Vec3::Zero());
          sectionForce.push_back(Vec3(f.N, f.Qy, f.Qz));
          sectionMoment.push_back(Vec3(f.Mx, f.My, f.Mz));
        }
        pen.cell(std::move(line), Drawing::CellKind::PolyLine);
      }
    } else if (feIndex_[b] >= 0) {
      // an fe_body: its outer surface through the deformed nodes (node a = point a)
      const FeBodyDrawing& fe = feBodies_[feIndex_[b]];
      const auto& pts = f3->invariants().points;
      const Mat3 A = FfrBody3d::rotationOf(q);
      const VecX qf = q.tail(f3->numElastic());
      const int base = static_cast<int>(d.points.size());
      for (std::size_t a = 0; a < fe.surface.points.size(); ++a) {
        const Vec3 u = pts[a].shape * qf;
        pen.add(q.head<3>() + A * (pts[a].position + u), A * u);
        vonMisesStress.push_back(fe.stressShapes.size() == 0
                                     ? 0.0
                                     : vonMises(fe.stressShapes.middleRows<6>(6 * static_cast<int>(a)) * qf));
      }
      for (const std::vector<int>& f : fe.surface.faces) {
        std::vector<int> cell(f.size());
        for (std::size_t k = 0; k < f.size(); ++k) cell[k] = base + f[k];
        pen.cell(std::move(cell), Drawing::CellKind::Polygon);
      }
    } else if (!f3->invariants().points.empty()) {
      // given invariants: the line through its attachment points
      const auto& pts = f3->invariants().points;
      const Mat3 A = FfrBody3d::rotationOf(q);
      std::vector<int> line;
      for (std::size_t k = 0; k < pts.size(); ++k) {
        FrameKinematics fk;
        body.frameKinematics(q, pts[k].position, static_cast<int>(k), nullptr, nullptr, fk);
        line.push_back(pen.add(fk.r, A * (pts[k].shape * q.tail(f3->numElastic()))));
      }
      pen.cell(std::move(line), Drawing::CellKind::PolyLine);
    }
  } else if (fb && fb->beamModel()) {
    const int elements = static_cast<int>(fb->beamModel()->elements().size());
    for (int e = 0; e < elements; ++e) {
      std::vector<int> line;
      for (int k = 0; k <= subdivisions_; ++k) {
        const double xi = static_cast<double>(k) / subdivisions_;
        const FfrBody2d::BeamDeflection bd = fb->beamDeflection(q, e, xi);
        line.push_back(pen.add(in3d(bd.position), in3d(bd.worldDisplacement), bd.sectionForces.x(),
                               bd.sectionForces.y()));
      }
      pen.cell(std::move(line), Drawing::CellKind::PolyLine);
    }
  } else if (!rigidPoints_[b].empty()) {
    std::vector<int> line;
    for (std::size_t k = 0; k < rigidPoints_[b].size(); ++k) {
      // invariants body: u = S_k q_f of its k-th point, world axes
      const Vec3 u = fb ? in3d(fb->worldElasticDisplacement(q, fb->invariants().points[k])) : Vec3::Zero();
      line.push_back(pen.add(in3d(body.pointKinematics(q, rigidPoints_[b][k], false).r), u));
    }
    pen.cell(std::move(line), Drawing::CellKind::PolyLine);
  }
  addSurfaces(body, q, surfaces_[b], pen);
  // the body's quantities after those of the bodies before it
  const std::size_t n = d.points.size() - first;
  d.pointVectors[0].second.insert(d.pointVectors[0].second.end(), displacement.begin(), displacement.end());
  sectionForce.resize(n, Vec3::Zero());
  sectionMoment.resize(n, Vec3::Zero());
  d.pointVectors[1].second.insert(d.pointVectors[1].second.end(), sectionForce.begin(), sectionForce.end());
  d.pointVectors[2].second.insert(d.pointVectors[2].second.end(), sectionMoment.begin(), sectionMoment.end());
  d.pointScalars[0].second.insert(d.pointScalars[0].second.end(), axial.begin(), axial.end());
  d.pointScalars[1].second.insert(d.pointScalars[1].second.end(), moment.begin(), moment.end());
  vonMisesStress.resize(n, 0.0);
  d.pointScalars[2].second.insert(d.pointScalars[2].second.end(), vonMisesStress.begin(), vonMisesStress.end());
}

void SystemDrawer::drawJoints(const VecX& q, Drawing& d) const {
  for (int c = 0; c < sys_.numConstraints(); ++c) {
    const Constraint& con = sys_.constraint(ConstraintIndex(c));
    const std::vector<Attachment> at = con.attachments();
    if (at.empty()) continue;  // drivers and other constraints without a place
    const Attachment& a = at.front();
    const Body& body = sys_.body(a.body);
    const auto qb = q.segment(sys_.coordinateOffset(a.body), body.numCoordinates());
    // ground: the point is in world axes; a planar revolute joint turns about z
    Vec3 r = a.point, axis = dynamic_cast<const RevoluteJoint*>(&con) ? Vec3(Vec3::UnitZ()) : Vec3(Vec3::Zero());
    const auto* sj = dynamic_cast<const SpatialJoint*>(&con);
    Mat3 A = Mat3::Identity();
    if (a.body.value > 0 && isSpatialBody(body)) {
      const FrameKinematics fk = body.frameKinematics(qb, a.point);
      r = fk.r;
      A = fk.A;
    } else if (a.body.value > 0) {
      r = in3d(body.pointKinematics(qb, a.point.head<2>(), false).r);
    }
    if (sj) {
      const SpatialJointType t = sj->type();
      const bool axial = t == SpatialJointType::Revolute || t == SpatialJointType::Prismatic ||
                         t == SpatialJointType::Cylindrical;
      axis = axial ? Vec3(A * sj->frameI().axes.col(2)) : Vec3::Zero();
    }
    d.jointNames.push_back(con.name());
    d.jointPoints.push_back(r);
    d.jointAxes.push_back(axis);
  }
}

}  // namespace flexmbd
