/// @file
/// Closest points of two segments in 3D (planar segments: z = 0). The clamped
/// segment-segment algorithm of Ericson2005, sec. 5.1.9.
#pragma once

#include <Eigen/Core>

namespace flexmbd {

struct SegmentClosestPoints {
  double s = 0.0;                         ///< parameter on segment 1, point p1 + s (q1 - p1)
  double t = 0.0;                         ///< parameter on segment 2
  Eigen::Vector3d c1 = Eigen::Vector3d::Zero();  ///< closest point on segment 1
  Eigen::Vector3d c2 = Eigen::Vector3d::Zero();  ///< closest point on segment 2
  double distance = 0.0;                  ///< |c1 - c2|
};

/// Closest points between segments [p1, q1] and [p2, q2]; degenerate (zero-length)
/// segments are handled as points.
SegmentClosestPoints closestPointsOfSegments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                                             const Eigen::Vector3d& p2, const Eigen::Vector3d& q2);

}  // namespace flexmbd
