#include "core/body.hpp"

#include <numeric>

namespace flexmbd {

std::vector<int> Body::pointSupport(const Vec2& point) const {
  (void)point;
  std::vector<int> all(numVelocities());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

void Body::coordinateRateMatrix(const ConstVecRef& q, MatX& T) const {
  (void)q;
  T.setIdentity(numCoordinates(), numVelocities());
}

void Body::coordinateRateInverse(const ConstVecRef& q, MatX& Tinv) const {
  (void)q;
  Tinv.setIdentity(numVelocities(), numCoordinates());
}

std::vector<std::string> Body::velocityNames() const {
  std::vector<std::string> names = coordinateNames();
  for (auto& n : names) n += "_dot";
  return names;
}

}  // namespace flexmbd
