#include "joints/joint_outputs.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace flexmbd {

std::vector<std::string> jointOutputNames(SpatialJointType type) {
  switch (type) {
    case SpatialJointType::Revolute: return {"angle", "angle_dot"};
    case SpatialJointType::Prismatic: return {"displacement", "displacement_dot"};
    case SpatialJointType::Cylindrical: return {"angle", "displacement", "angle_dot", "displacement_dot"};
    case SpatialJointType::Universal: return {"angle1", "angle2", "angle1_dot", "angle2_dot"};
    case SpatialJointType::Spherical: return {"rx", "ry", "rz", "omega_x", "omega_y", "omega_z"};
    case SpatialJointType::Planar: return {"dx", "dy", "angle", "dx_dot", "dy_dot", "angle_dot"};
    case SpatialJointType::Fixed: return {};
  }
  return {};
}

std::vector<bool> jointOutputIsAngle(SpatialJointType type) {
  const std::vector<std::string> names = jointOutputNames(type);
  std::vector<bool> angle(names.size());
  for (std::size_t k = 0; k < names.size(); ++k) angle[k] = names[k] == "angle" || names[k] == "angle1" || names[k] == "angle2";
  return angle;
}

namespace {

/// The rotation of frame J about frame I's z axis: atan2(y_i . x_j, x_i . x_j) (as the
/// joint_angle driver, joints/spatial_drivers.hpp).
double angleAboutZ(const Mat3& Ci, const Mat3& Cj) { return std::atan2(Ci.col(1).dot(Cj.col(0)), Ci.col(0).dot(Cj.col(0))); }

/// The component of d = r_j - r_i along axis u of frame I and its rate
/// d/dt (u . d) = u . d' + (w_i x u) . d (u turns with frame I).
void alongAxis(const Vec3& u, const FrameMotion& fi, const FrameMotion& fj, double& value, double& rate) {
  const Vec3 d = fj.r - fi.r, dDot = fj.v - fi.v;
  value = u.dot(d);
  rate = u.dot(dDot) + fi.w.cross(u).dot(d);
}

}  // namespace

void jointOutputValues(SpatialJointType type, const FrameMotion& fi, const FrameMotion& fj, double* out) {
  const Mat3 &Ci = fi.axes, &Cj = fj.axes;
  const Vec3 w = fj.w - fi.w;  // relative angular velocity, world axes
  switch (type) {
    case SpatialJointType::Revolute:
      out[0] = angleAboutZ(Ci, Cj);
      out[1] = Ci.col(2).dot(w);
      return;
    case SpatialJointType::Prismatic: alongAxis(Ci.col(2), fi, fj, out[0], out[1]); return;
    case SpatialJointType::Cylindrical:
      out[0] = angleAboutZ(Ci, Cj);
      out[2] = Ci.col(2).dot(w);
      alongAxis(Ci.col(2), fi, fj, out[1], out[3]);
      return;
    case SpatialJointType::Universal: {
      // the cross has axes x_c = x_i, y_c = y_j, z_c = x_i x y_j; w = angle1' x_i + angle2' y_j
      const Vec3 xi = Ci.col(0), yj = Cj.col(1), zc = xi.cross(yj);
      out[0] = std::atan2(Ci.col(2).dot(yj), Ci.col(1).dot(yj));
      out[1] = std::atan2(Cj.col(2).dot(xi), Cj.col(2).dot(zc));
      out[2] = xi.dot(w);
      out[3] = yj.dot(w);
      return;
    }
    case SpatialJointType::Spherical: {
      const Eigen::AngleAxisd aa(Mat3(Ci.transpose() * Cj));  // R = C_i^T C_j, angle in [0, pi]
      const Vec3 rv = aa.angle() * aa.axis();
      const Vec3 wi = Ci.transpose() * w;
      for (int k = 0; k < 3; ++k) {
        out[k] = rv[k];
        out[3 + k] = wi[k];
      }
      return;
    }
    case SpatialJointType::Planar:
      alongAxis(Ci.col(0), fi, fj, out[0], out[3]);
      alongAxis(Ci.col(1), fi, fj, out[1], out[4]);
      out[2] = angleAboutZ(Ci, Cj);
      out[5] = Ci.col(2).dot(w);
      return;
    case SpatialJointType::Fixed: return;
  }
}

SpatialJointOutputs::SpatialJointOutputs(const System& sys) : sys_(sys) {
  for (int c = 0; c < sys.numConstraints(); ++c) {
    const auto* joint = dynamic_cast<const SpatialJoint*>(&sys.constraint(ConstraintIndex(c)));
    if (!joint) continue;
    const auto angle = jointOutputIsAngle(joint->type());
    if (angle.empty()) continue;
    Entry e{joint, {}, size_, static_cast<int>(angle.size()), {}};
    const JointFrame* frames[2] = {&joint->frameI(), &joint->frameJ()};
    for (int k = 0; k < 2; ++k) {
      e.pointId[k] = sys.body(joint->bodies()[k]).resolvePoint(frames[k]->point, "joint '" + joint->name() + "'");
    }
    entries_.push_back(std::move(e));
    isAngle_.insert(isAngle_.end(), angle.begin(), angle.end());
    size_ += static_cast<int>(angle.size());
  }
  last_.assign(size_, 0.0);
  current_.assign(size_, 0.0);
}

std::vector<std::string> SpatialJointOutputs::columnNames() const {
  std::vector<std::string> names;
  for (const Entry& e : entries_) {
    for (const auto& n : jointOutputNames(e.joint->type())) names.push_back(e.joint->name() + "." + n);
  }
  return names;
}

FrameMotion SpatialJointOutputs::motion(Entry& e, int k, const VecX& q, const VecX& v) const {
  const BodyIndex b = e.joint->bodies()[k];
  const Body& body = sys_.body(b);
  const JointFrame& frame = k == 0 ? e.joint->frameI() : e.joint->frameJ();
  FrameKinematics& f = e.kin[k];
  body.frameKinematics(q.segment(sys_.coordinateOffset(b), body.numCoordinates()), frame.point, e.pointId[k], nullptr,
                       nullptr, f);
  const auto vb = v.segment(sys_.velocityOffset(b), body.numVelocities());
  FrameMotion m;
  m.r = f.r;
  m.axes.noalias() = f.A * frame.axes;  // the frame's axes in world axes
  m.v.noalias() = f.Jr * vb;
  m.w.noalias() = f.Jw * vb;
  return m;
}

void SpatialJointOutputs::append(const VecX& q, const VecX& v, std::vector<double>& out) {
  for (Entry& e : entries_) {
    const FrameMotion fi = motion(e, 0, q, v), fj = motion(e, 1, q, v);
    jointOutputValues(e.joint->type(), fi, fj, current_.data() + e.offset);
  }
  for (int k = 0; k < size_; ++k) {
    if (started_ && isAngle_[k]) {
      // unwrap: the step from the previous value, taken in (-pi, pi]
      current_[k] = last_[k] + std::remainder(current_[k] - last_[k], 2.0 * M_PI);
    }
    last_[k] = current_[k];
    out.push_back(current_[k]);
  }
  started_ = true;
}

}  // namespace flexmbd
