/// @file
/// The base of joints that hold a point of body j at zero distance from a frame of body i
/// along some of the frame's axes: point_on_line (the two normals of the line) and
/// point_in_plane (the plane's normal), spatial.
#pragma once

#include <string>
#include <vector>

#include "joints/spatial_drivers.hpp"

namespace flexmbd {

/// h_e = x_{a_e}^i . (r_j - r_i) = 0 for the chosen axes a_e of frame i, whose origin is
/// point i and whose z axis is `z` (x and y: frameAxesFromZ); frame j is point j with the
/// body's axes (Haug1989, ch. 9, the gap equations of the cylindrical and planar joints).
/// Reactions: the force on body j at its point, -sum_e lambda_e x_{a_e}^i (world axes), no moment.
class PointGapJoint : public FramePairConstraint {
 public:
  /// `zName` names z in messages ("direction", "normal").
  /// @throws InputError if a point or z is not finite, z is zero, or the bodies are the same.
  PointGapJoint(std::string name, BodyIndex bodyI, const Vec3& pointI, const Vec3& z, const std::string& zName,
                BodyIndex bodyJ, const Vec3& pointJ, std::vector<int> axes);
  int numEquations() const override { return static_cast<int>(gaps_.size()); }
  void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const override;
  std::vector<std::string> reactionNames() const override { return {"fx", "fy", "fz"}; }
  VecX reactions(const BodyStates& bodies, const VecX& lambda) const override;

 private:
  std::vector<FrameEquation> gaps_;  ///< AxisGap of each chosen axis
};

}  // namespace flexmbd
