#include "tensegrity/member_contact_detector.hpp"

#include <algorithm>
#include <cmath>

#include "tensegrity/segment_closest_points.hpp"

namespace flexmbd {

MemberContactDetector::MemberContactDetector(const TensegrityStructure& s) : s_(s) {
  const std::vector<MemberRef> m = s.members();
  double scale = 0.0;
  for (std::size_t a = 0; a < m.size(); ++a) {
    const auto [ai, aj] = s.memberNodes(m[a]);
    scale = std::max(scale, (s.node(ai).position - s.node(aj).position).norm());
    for (std::size_t b = a + 1; b < m.size(); ++b) {
      const auto [bi, bj] = s.memberNodes(m[b]);
      if (ai == bi || ai == bj || aj == bi || aj == bj) continue;  // sharing a node: never a contact
      pairs_.push_back({m[a], m[b], ai, aj, bi, bj, s.memberRadius(m[a]) + s.memberRadius(m[b])});
    }
  }
  // Distance tolerance: 1e-10 of the longest member, far below any radius of interest
  // and above the round-off of the closest-point computation.
  tolerance_ = 1e-10 * std::max(scale, 1e-300);
}

Eigen::Vector3d MemberContactDetector::nodePoint(const VecX& x, int node) const {
  const int d = s_.dimension();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  p.head(d) = x.segment(d * node, d);
  return p;
}

void MemberContactDetector::start(double t, const VecX& x, std::vector<TensegrityEvent>& out) {
  for (Pair& p : pairs_) {
    const SegmentClosestPoints c =
        closestPointsOfSegments(nodePoint(x, p.ai), nodePoint(x, p.aj), nodePoint(x, p.bi), nodePoint(x, p.bj));
    p.inContact = c.distance <= p.reach + tolerance_;
    if (p.inContact) {
      TensegrityEvent e;
      e.type = TensegrityEvent::Type::Contact;
      e.t = t;
      e.member = s_.memberName(p.a);
      e.other = s_.memberName(p.b);
      e.point = 0.5 * (c.c1 + c.c2);
      out.push_back(e);
    }
  }
}

void MemberContactDetector::advance(double t0, const VecX& x0, double t1, const VecX& x1,
                                    std::vector<TensegrityEvent>& out) {
  constexpr int kMaxAdvances = 100000;  // conservative advancement steps per pair and interval
  for (Pair& p : pairs_) {
    const Eigen::Vector3d a0 = nodePoint(x0, p.ai), a1 = nodePoint(x0, p.aj);
    const Eigen::Vector3d b0 = nodePoint(x0, p.bi), b1 = nodePoint(x0, p.bj);
    const Eigen::Vector3d da0 = nodePoint(x1, p.ai) - a0, da1 = nodePoint(x1, p.aj) - a1;
    const Eigen::Vector3d db0 = nodePoint(x1, p.bi) - b0, db1 = nodePoint(x1, p.bj) - b1;
    auto closest = [&](double s) {
      return closestPointsOfSegments(a0 + s * da0, a1 + s * da1, b0 + s * db0, b1 + s * db1);
    };
    if (p.inContact) {
      // Still touching, or separated at the end of the interval (then it may be reported again).
      if (closest(1.0).distance > p.reach + tolerance_) p.inContact = false;
      continue;
    }
    // Broad phase: swept bounding boxes inflated by the reach.
    const Eigen::Vector3d aMin = a0.cwiseMin(a1).cwiseMin(a0 + da0).cwiseMin(a1 + da1).array() - p.reach;
    const Eigen::Vector3d aMax = a0.cwiseMax(a1).cwiseMax(a0 + da0).cwiseMax(a1 + da1).array() + p.reach;
    const Eigen::Vector3d bMin = b0.cwiseMin(b1).cwiseMin(b0 + db0).cwiseMin(b1 + db1);
    const Eigen::Vector3d bMax = b0.cwiseMax(b1).cwiseMax(b0 + db0).cwiseMax(b1 + db1);
    if ((aMax.array() < bMin.array()).any() || (bMax.array() < aMin.array()).any()) continue;
    // Conservative advancement: the closest points are convex combinations of the end
    // points, so the distance changes at most at rate L = max|da| + max|db| per unit s.
    const double rate = std::max(da0.norm(), da1.norm()) + std::max(db0.norm(), db1.norm());
    double s = 0.0;
    for (int k = 0; k < kMaxAdvances; ++k) {
      const SegmentClosestPoints c = closest(s);
      const double gap = c.distance - p.reach;
      if (gap <= tolerance_) {
        p.inContact = true;
        TensegrityEvent e;
        e.type = TensegrityEvent::Type::Contact;
        e.t = t0 + s * (t1 - t0);
        e.member = s_.memberName(p.a);
        e.other = s_.memberName(p.b);
        e.point = 0.5 * (c.c1 + c.c2);
        out.push_back(e);
        break;
      }
      if (rate <= 0.0) break;
      s += gap / rate;
      if (s > 1.0) break;
    }
  }
}

}  // namespace flexmbd
