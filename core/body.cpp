#include "core/body.hpp"

#include <numeric>

#include "core/errors.hpp"

namespace flexmbd {

std::vector<int> Body::pointSupport(const Vec3& point, int pointId) const {
  (void)point; (void)pointId;
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

void Body::frameKinematics(const ConstVecRef&, const Vec3&, int, const std::vector<int>*, const std::vector<int>*,
                           FrameKinematics&) const {
  throw InputError("body '" + name() + "' is planar: spatial joints and forces need spatial bodies (\"dimension\": 3)");
}

void Body::addFrameCurvature(const ConstVecRef&, const Vec3&, int, const std::vector<int>*, const std::vector<int>*,
                             const Vec3&, const Vec3&, Eigen::Ref<MatX>) const {
  throw InputError("body '" + name() + "' is planar: spatial joints and forces need spatial bodies (\"dimension\": 3)");
}

std::vector<std::string> Body::velocityNames() const {
  std::vector<std::string> names = coordinateNames();
  for (auto& n : names) n += "_dot";
  return names;
}

}  // namespace flexmbd
