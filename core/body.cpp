#include "core/body.hpp"

#include <numeric>

namespace flexmbd {

std::vector<int> Body::pointSupport(const Vec2& point) const {
  (void)point;
  std::vector<int> all(numCoordinates());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

}  // namespace flexmbd
