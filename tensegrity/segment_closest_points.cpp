#include "tensegrity/segment_closest_points.hpp"

#include <algorithm>

namespace flexmbd {

SegmentClosestPoints closestPointsOfSegments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                                             const Eigen::Vector3d& p2, const Eigen::Vector3d& q2) {
  // Ericson2005, sec. 5.1.9: minimise |p1 + s d1 - p2 - t d2|^2 over [0,1]^2.
  constexpr double kEps = 1e-300;
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= kEps && e <= kEps) {
    s = t = 0.0;
  } else if (a <= kEps) {
    s = 0.0;
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kEps) {
      t = 0.0;
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;  // >= 0; zero for parallel segments
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  SegmentClosestPoints out;
  out.s = s;
  out.t = t;
  out.c1 = p1 + s * d1;
  out.c2 = p2 + t * d2;
  out.distance = (out.c1 - out.c2).norm();
  return out;
}

}  // namespace flexmbd
