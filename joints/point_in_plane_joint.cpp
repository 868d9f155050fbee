#include "joints/point_in_plane_joint.hpp"

#include "core/component_kind.hpp"

namespace flexmbd {

ConstraintIndex addPointInPlaneJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec3& pointI,
                                     BodyIndex bodyJ, const Vec3& pointJ, const Vec3& normal) {
  return sys.addConstraint(std::make_unique<PointInPlaneJoint>(name, bodyI, pointI, bodyJ, pointJ, normal));
}

ComponentKind pointInPlaneJointKind() {
  ComponentKind k;
  k.section = "joints";
  k.type = "point_in_plane";
  k.dimensions = KindDimensions::Spatial;
  k.summary = "A point of the second body stays in a plane fixed in the first; it moves freely in the plane and "
              "the bodies turn freely.";
  k.keys = {
      {"bodies", KeyType::BodyPair, "", "The body carrying the plane, then the body carrying the point."},
      {"points", KeyType::PointPair, "m",
       "A point of the plane in the first body's axes, then the point in the second body's axes."},
      {"normal", KeyType::Direction, "", "The plane's normal in the first body's axes."},
  };
  k.build = [](System& sys, const ComponentArgs& a) {
    const auto [bi, bj] = a.bodyPair("bodies");
    const auto p = a.pointPair("points");
    addPointInPlaneJoint(sys, a.name(), bi, p[0], bj, p[1], a.direction("normal"));
  };
  return k;
}

}  // namespace flexmbd
