#include "core/body.hpp"

#include <numeric>

namespace flexmbd {

std::vector<int> Body::pointSupport(const Vec2& point) const {
  (void)point;
  std::vector<int> all(numCoordinates());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

PointKinematics Body::pointKinematics(const ConstVecRef& q, const Vec2& point, const std::vector<int>& cols,
                                      bool withHessians) const {
  PointKinematics full = pointKinematics(q, point, withHessians);
  if (static_cast<int>(cols.size()) == numCoordinates()) return full;
  const int k = static_cast<int>(cols.size());
  PointKinematics p;
  p.r = full.r;
  p.phi = full.phi;
  p.Jr.resize(2, k);
  p.Jphi.resize(k);
  for (int a = 0; a < k; ++a) {
    p.Jr.col(a) = full.Jr.col(cols[a]);
    p.Jphi[a] = full.Jphi[cols[a]];
  }
  if (!withHessians) return p;
  p.Hrx.resize(k, k);
  p.Hry.resize(k, k);
  p.Hphi.resize(k, k);
  for (int b = 0; b < k; ++b) {
    for (int a = 0; a < k; ++a) {
      p.Hrx(a, b) = full.Hrx(cols[a], cols[b]);
      p.Hry(a, b) = full.Hry(cols[a], cols[b]);
      p.Hphi(a, b) = full.Hphi(cols[a], cols[b]);
    }
  }
  return p;
}

}  // namespace flexmbd
