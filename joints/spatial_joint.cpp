#include "joints/spatial_joint.hpp"

#include <Eigen/Dense>

#include "core/errors.hpp"
#include "core/rotation_3d.hpp"

namespace flexmbd {

const char* toString(SpatialJointType type) {
  switch (type) {
    case SpatialJointType::Spherical: return "spherical";
    case SpatialJointType::Revolute: return "revolute";
    case SpatialJointType::Prismatic: return "prismatic";
    case SpatialJointType::Cylindrical: return "cylindrical";
    case SpatialJointType::Universal: return "universal";
    case SpatialJointType::Fixed: return "fixed";
    case SpatialJointType::Planar: return "planar";
  }
  return "?";
}

namespace {

using Eq = SpatialJoint::Equation;

/// The constrained directions of each joint type (axes: 0 = x, 1 = y, 2 = z).
std::vector<Eq> equationsOf(SpatialJointType type) {
  const std::vector<Eq> point = {{Eq::Gap, 0, 0}, {Eq::Gap, 1, 0}, {Eq::Gap, 2, 0}};
  const std::vector<Eq> zAxis = {{Eq::AxisAxis, 2, 0}, {Eq::AxisAxis, 2, 1}};  // z_i stays normal to x_j, y_j
  const Eq twist{Eq::AxisAxis, 0, 1};                                          // x_i . y_j: rotation about z locked
  const std::vector<Eq> lateral = {{Eq::AxisGap, 0, 0}, {Eq::AxisGap, 1, 0}};  // no motion across z_i
  auto join = [](std::vector<Eq> a, const std::vector<Eq>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  switch (type) {
    case SpatialJointType::Spherical: return point;
    case SpatialJointType::Revolute: return join(point, zAxis);
    case SpatialJointType::Prismatic: return join(join(lateral, zAxis), {twist});
    case SpatialJointType::Cylindrical: return join(lateral, zAxis);
    case SpatialJointType::Universal: return join(point, {{Eq::AxisAxis, 0, 1}});
    case SpatialJointType::Fixed: return join(join(point, zAxis), {twist});
    case SpatialJointType::Planar: return {{Eq::AxisGap, 2, 0}, {Eq::AxisAxis, 2, 0}, {Eq::AxisAxis, 2, 1}};
  }
  return {};
}

}  // namespace

SpatialJoint::SpatialJoint(std::string name, SpatialJointType type, BodyIndex bodyI, const JointFrame& frameI,
                           BodyIndex bodyJ, const JointFrame& frameJ)
    : Constraint(std::move(name), {bodyI, bodyJ}), type_(type), frameI_(frameI), frameJ_(frameJ),
      equations_(equationsOf(type)) {
  const std::string who = "joint '" + this->name() + "'";
  if (bodyI == bodyJ) throw InputError(who + ": connects a body to itself; expected two different bodies");
  checkJointFrame(frameI, who + " frame 0");
  checkJointFrame(frameJ, who + " frame 1");
}

void SpatialJoint::evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const {
  evaluateFrameEquations(bodies, frameI_, frameJ_, equations_, withHessians, out);
}

VecX SpatialJoint::reactions(const BodyStates& bodies, const VecX& lambda) const {
  ConstraintEvaluation ev;
  evaluate(bodies, false, ev);
  const FrameKinematics& fi = ev.work.fi;
  const FrameKinematics& fj = ev.work.fj;
  const int ni = fi.numVelocities(), nj = fj.numVelocities();
  // generalised constraint force on a body: -G^T lambda over its columns (Haug1989); the wrench
  // (F, M) at the joint point that gives it: [Jr^T Jw^T] [F; M] = Q
  const bool onJ = nj > 0;
  const FrameKinematics& f = onJ ? fj : fi;
  const VecX Q = -(ev.G.middleCols(onJ ? ni : 0, onJ ? nj : ni).transpose() * lambda);
  MatX B(Q.size(), 6);
  B << f.Jr.transpose(), f.Jw.transpose();
  VecX wrench = B.colPivHouseholderQr().solve(Q);
  if (!onJ) wrench = -wrench;  // body j is the ground: the reaction on it, by Newton's third law
  return wrench;
}

}  // namespace flexmbd
