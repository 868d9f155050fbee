#include "core/body.hpp"

#include <algorithm>
#include <numeric>

#include "core/errors.hpp"

namespace flexmbd {

std::vector<int> Body::pointSupport(const Vec3& point, int pointId) const {
  (void)point; (void)pointId;
  std::vector<int> all(numVelocities());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

void Body::addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const {
  (void)q;
  for (int k = 0; k < std::min(numCoordinates(), numVelocities()); ++k) T.add(k, k, 1.0);
}

void Body::addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const {
  (void)q;
  for (int k = 0; k < std::min(numCoordinates(), numVelocities()); ++k) Tinv.add(k, k, 1.0);
}

void Body::coordinateRateMatrix(const ConstVecRef& q, MatX& T) const {
  T.setZero(numCoordinates(), numVelocities());
  addCoordinateRateMatrix(q, MatrixSink(T));
}

void Body::coordinateRateInverse(const ConstVecRef& q, MatX& Tinv) const {
  Tinv.setZero(numVelocities(), numCoordinates());
  addCoordinateRateInverse(q, MatrixSink(Tinv));
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
