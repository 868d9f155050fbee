/// @file
/// The relative coordinates of spatial joints and their rates, for results tables
/// (docs/results.md, "Joint columns"; sign conventions in docs/spatial.md, "Joint
/// outputs"): what a joint lets move, measured as frame J relative to frame I in frame
/// I's axes.
#pragma once

#include <string>
#include <vector>

#include "core/system.hpp"
#include "joints/spatial_joint.hpp"

namespace flexmbd {

/// A joint frame's world motion: origin r, velocity v, axes (columns x, y, z, world) and
/// angular velocity w (world).
struct FrameMotion {
  Vec3 r = Vec3::Zero(), v = Vec3::Zero(), w = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
};

/// The names of a joint type's outputs, coordinates first, then their rates (the same
/// order, suffix "_dot"; spherical: the relative angular velocity "omega_x", ...):
///   revolute    angle, angle_dot
///   prismatic   displacement, displacement_dot
///   cylindrical angle, displacement, angle_dot, displacement_dot
///   universal   angle1, angle2, angle1_dot, angle2_dot
///   spherical   rx, ry, rz, omega_x, omega_y, omega_z
///   planar      dx, dy, angle, dx_dot, dy_dot, angle_dot
///   fixed       (none)
std::vector<std::string> jointOutputNames(SpatialJointType type);
/// Which of jointOutputNames(type) are angles defined modulo 2 pi (unwrapped over a run).
std::vector<bool> jointOutputIsAngle(SpatialJointType type);

/// The values of jointOutputNames(type) for frames I and J into out (its size), angles in
/// (-pi, pi]. Frame J relative to frame I, in frame I's axes (x_i, y_i, z_i):
///   angle about z_i: theta = atan2(y_i . x_j, x_i . x_j), rate z_i . (w_j - w_i);
///   displacement along z_i: s = z_i . d, d = r_j - r_i, rate z_i . d' + (w_i x z_i) . d;
///   universal: angle1 = atan2(z_i . y_j, y_i . y_j) of the cross about x_i, angle2 =
///     atan2(z_j . x_i, z_j . (x_i x y_j)) of body J about y_j; rates x_i . w, y_j . w
///     with w = w_j - w_i;
///   spherical: the rotation vector (axis times angle in [0, pi]) of R = C_i^T C_j and
///     w = C_i^T (w_j - w_i);
///   planar: dx = x_i . d, dy = y_i . d and the angle about z_i, with their rates.
void jointOutputValues(SpatialJointType type, const FrameMotion& fi, const FrameMotion& fj, double* out);

/// The outputs of every spatial joint of a system, with the angles unwrapped over the
/// states it is given in order (a joint that spins keeps adding 2 pi a turn, as long as
/// it turns less than half a turn between two outputs).
class SpatialJointOutputs {
 public:
  /// @pre sys is finalized and outlives this object.
  explicit SpatialJointOutputs(const System& sys);
  /// "<joint>.<name>" for every spatial joint, in the order of the system's constraints.
  std::vector<std::string> columnNames() const;
  int size() const { return size_; }
  /// Appends the values at (q, v) (global coordinates and velocities) to `out`; angles
  /// continue the previous call's (the first call: in (-pi, pi]). Allocates nothing once
  /// `out` has the capacity.
  void append(const VecX& q, const VecX& v, std::vector<double>& out);
  /// Forget the previous values (a new run).
  void reset() { started_ = false; }

 private:
  struct Entry {
    const SpatialJoint* joint;
    int pointId[2];
    int offset;  ///< of its values in last_
    int count;
    FrameKinematics kin[2];
  };
  FrameMotion motion(Entry& e, int k, const VecX& q, const VecX& v) const;

  const System& sys_;
  std::vector<Entry> entries_;
  std::vector<bool> isAngle_;
  std::vector<double> last_, current_;
  int size_ = 0;
  bool started_ = false;
};

}  // namespace flexmbd
