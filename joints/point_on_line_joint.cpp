#include "joints/point_on_line_joint.hpp"

#include "core/component_kind.hpp"
#include "core/magnitude_checks.hpp"
#include "joints/drivers.hpp"

namespace flexmbd {

// ----- planar -------------------------------------------------------------------------

PointOnLineJoint::PointOnLineJoint(std::string name, BodyIndex bodyI, const Vec2& pointI, BodyIndex bodyJ,
                                   const Vec2& pointJ, const Vec2& direction)
    : TwoPointConstraint(std::move(name), bodyI, pointI, bodyJ, pointJ) {
  direction_ = unitDirection(direction, "joint '" + this->name() + "': direction");  // finite, not zero
}

void PointOnLineJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  const PointPair& p = pair(bodies, withHessians, out.work);
  double s = 0.0;
  out.H.resize(1);
  projectOnRotatingAxis(p, perp(direction_), s, out.work.row, withHessians ? &out.H[0] : nullptr, out.work.row2);
  out.h.setConstant(1, s);
  out.G = out.work.row;
}

VecX PointOnLineJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  const double phiI = bodies[0].point(pointI(), bodies.pointId(0), false).phi;
  return -lambda[0] * (rotation(phiI) * perp(direction_));
}

std::unique_ptr<Constraint> PointOnLineJoint::makeDriver(const std::string& quantity, std::string name,
                                                         TimeLawPtr law) const {
  if (quantity != "displacement") return nullptr;
  return std::make_unique<JointDisplacementDriver>(std::move(name), bodies()[0], pointI(), bodies()[1], pointJ(),
                                                   direction_, std::move(law));
}

ConstraintIndex addPointOnLineJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec2& pointI,
                                    BodyIndex bodyJ, const Vec2& pointJ, const Vec2& direction) {
  return sys.addConstraint(std::make_unique<PointOnLineJoint>(name, bodyI, pointI, bodyJ, pointJ, direction));
}

// ----- spatial ------------------------------------------------------------------------

std::unique_ptr<Constraint> PointOnLineJoint3d::makeDriver(const std::string& quantity, std::string name,
                                                           TimeLawPtr law) const {
  if (quantity != "displacement") return nullptr;
  return std::make_unique<SpatialJointDisplacementDriver>(std::move(name), bodies()[0], frameI_, bodies()[1],
                                                          frameJ_, std::move(law));
}

ConstraintIndex addPointOnLineJoint(System& sys, const std::string& name, BodyIndex bodyI, const Vec3& pointI,
                                    BodyIndex bodyJ, const Vec3& pointJ, const Vec3& direction) {
  return sys.addConstraint(std::make_unique<PointOnLineJoint3d>(name, bodyI, pointI, bodyJ, pointJ, direction));
}

// ----- the scene kind -----------------------------------------------------------------

ComponentKind pointOnLineJointKind() {
  ComponentKind k;
  k.section = "joints";
  k.type = "point_on_line";
  k.dimensions = KindDimensions::Both;
  k.summary = "A point of the second body stays on a line fixed in the first; it slides along the line and the "
              "bodies turn freely (a joint_displacement driver prescribes its position along the line).";
  k.keys = {
      {"bodies", KeyType::BodyPair, "", "The body carrying the line, then the body carrying the point."},
      {"points", KeyType::PointPair, "m",
       "A point of the line in the first body's axes, then the point in the second body's axes."},
      {"direction", KeyType::Direction, "", "The line's direction in the first body's axes."},
  };
  k.build = [](System& sys, const ComponentArgs& a) {
    const auto [bi, bj] = a.bodyPair("bodies");
    const auto p = a.pointPair("points");
    const Vec3 d = a.direction("direction");
    if (a.dimension() == 2) {
      addPointOnLineJoint(sys, a.name(), bi, Vec2(p[0].head<2>()), bj, Vec2(p[1].head<2>()), Vec2(d.head<2>()));
    } else {
      addPointOnLineJoint(sys, a.name(), bi, p[0], bj, p[1], d);
    }
  };
  return k;
}

}  // namespace flexmbd
