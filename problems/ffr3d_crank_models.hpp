// The elastic slider crank of examples/slider_crank_elastic.json (rigid crank 0.15 m at
// 150 rad/s, steel rod 0.30 m, 8 mm x 8 mm, pinned-pinned, rigid slider) rebuilt of
// spatial bodies in the x-y plane, the rod an FfrBody3d: shared by
// tests/test_ffr_spatial_validation.cpp and benchmarks/bench_spatial_flexible.cpp.
//
// Joints (non-redundant in space, as the rigid in-plane crank of test_spatial_dynamics):
// revolute bearing about world z (5 equations), spherical joint at the crank pin (3),
// universal joint at the rod's far end (4: its cross is the slider's y arm and the rod's
// z arm, so it locks the rod's spin about its own axis), prismatic rail along world x (5),
// angle driver of the crank (1): 3 x 6 frame velocities - 18 = 0, the rod's elastic
// coordinates free. Nothing else restrains the out-of-plane motion: the model is
// symmetric about the x-y plane (sections symmetric, every load in the plane), so the
// out-of-plane coordinates start at zero and stay there.
//
// The rod's 3D section: the planar A and in-plane I (int y^2 dA = Iz) and E, rho; the
// out-of-plane Iy = 2 Iz (so that no out-of-plane bending mode has the frequency of an
// in-plane one: the modal model picks its in-plane modes by their shapes), the square's
// St Venant J, G = E / 2.6.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_body_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/system.hpp"
#include "joints/spatial_drivers.hpp"
#include "joints/spatial_joint.hpp"

namespace flexmbd::test3d {

struct ElasticCrank3d {
  System sys;
  BodyIndex crank, rod, slider;
  ConstraintIndex motor;
  std::shared_ptr<const FfrBeamModel3d> model;
  const FfrBody3d* rodBody = nullptr;
  int midNode = -1;  ///< the rod's node at (0.15, 0, 0)
};

/// The rod's beam model: N elements, pinned-pinned; `inPlaneModes` > 0 keeps the first
/// that many in-plane modes (chosen among the first 12 by their shapes), 0 nodal.
inline std::shared_ptr<const FfrBeamModel3d> planarCrankRod3d(int N, int inPlaneModes, double eScale = 1.0) {
  constexpr double b = 0.008, E = 2e11, rho = 7870.0;
  BeamSection3d s = rectangularSection3d(b, b, E * eScale, E * eScale / 2.6, rho, 0.0);
  s.inertiaY = 2.0 * s.inertiaZ;  // out of plane: stiffer, frequencies apart from the in-plane ones
  FfrBeamOptions3d o;
  o.reference.type = ReferenceConditions3d::Type::PinnedPinned;
  const BeamMesh3d mesh = BeamMesh3d::straight(0.30, N, s);
  if (inPlaneModes > 0) {
    FfrBeamOptions3d probe = o;
    probe.modes = std::min(12, 6 * N);
    const FfrBeamModel3d all(mesh, probe, "body 'rod'");
    const MatX B(all.basis());
    for (int k = 0; k < B.cols() && static_cast<int>(o.modeSet.size()) < inPlaneModes; ++k) {
      double in = 0.0, out = 0.0;
      for (int r = 0; r < B.rows(); ++r) {
        const int c = r % 6;
        (c == 0 || c == 1 || c == 5 ? in : out) += B(r, k) * B(r, k);
      }
      if (out < 1e-20 * in) o.modeSet.push_back(k + 1);
    }
  }
  return std::make_shared<const FfrBeamModel3d>(mesh, o, "body 'rod'");
}

/// The spatial elastic crank. `planarInertia`: the rod is built from the model's
/// invariants less the section's in-plane rotary inertia rho Iz L (the planar element
/// keeps the centre line's only, docs/spatial-flexible.md), so that its in-plane
/// equations are the planar body's; false: FfrBody3d(name, model, ...) as it is.
inline std::unique_ptr<ElasticCrank3d> planarElasticCrank3d(std::shared_ptr<const FfrBeamModel3d> model,
                                                           bool planarInertia, double speed = 150.0) {
  auto c = std::make_unique<ElasticCrank3d>();
  System& sys = c->sys;
  c->model = model;
  auto rigid = [&](const std::string& name, double m, const Vec3& J, const Vec3& com) {
    RigidBody3dProperties p;
    p.mass = m;
    p.inertia = J.asDiagonal();
    FrameState3d s;
    s.position = com;
    return sys.addBody(std::make_unique<RigidBody3d>(name, p, s));
  };
  // planar crank: m 0.1, J 1.875e-4 about its centre of mass at 0.075 m; slider 0.075552, 1e-6
  c->crank = rigid("crank", 0.1, Vec3(0.1 * 1.875e-4, 1.875e-4, 1.875e-4), Vec3(0.075, 0, 0));
  FrameState3d r0;
  r0.position = Vec3(0.15, 0, 0);
  std::unique_ptr<FfrBody3d> rod;
  if (planarInertia) {
    FfrInvariants3d inv = model->invariants();
    double rhoIzL = 0.0;
    for (const auto& el : model->elements()) rhoIzL += el.section().density * el.section().inertiaZ * el.length();
    inv.secondMoment(1, 1) -= rhoIzL;
    rod = std::make_unique<FfrBody3d>("rod", std::move(inv), r0);
  } else {
    rod = std::make_unique<FfrBody3d>("rod", model, r0);
  }
  c->rodBody = rod.get();
  c->rod = sys.addBody(std::move(rod));
  c->slider = rigid("slider", 0.075552, Vec3(1e-6, 1e-6, 1e-6), Vec3(0.45, 0, 0));
  c->midNode = c->rodBody->resolvePoint(Vec3(0.15, 0, 0), "crank model");
  JointFrame origin, crankAxis, crankPin, rodStart, rodEnd, sliderCross, rail, railOnSlider;
  crankAxis.point = Vec3(-0.075, 0, 0);
  crankPin.point = Vec3(0.075, 0, 0);
  rodEnd.point = Vec3(0.30, 0, 0);
  sliderCross.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // x along world y
  rodEnd.axes.col(0) = Vec3::UnitY();
  rodEnd.axes.col(1) = Vec3::UnitZ();  // the cross: y along the rod's z axis
  rodEnd.axes.col(2) = Vec3::UnitX();
  rail.axes = rodEnd.axes;  // prismatic along frame z = world x
  railOnSlider.axes = rail.axes;
  sys.addConstraint(std::make_unique<SpatialJoint>("O1", SpatialJointType::Revolute, kGround, origin, c->crank, crankAxis));
  sys.addConstraint(std::make_unique<SpatialJoint>("O2", SpatialJointType::Spherical, c->crank, crankPin, c->rod, rodStart));
  sys.addConstraint(std::make_unique<SpatialJoint>("O3", SpatialJointType::Universal, c->slider, sliderCross, c->rod, rodEnd));
  sys.addConstraint(std::make_unique<SpatialJoint>("P", SpatialJointType::Prismatic, kGround, rail, c->slider, railOnSlider));
  c->motor = sys.addConstraint(std::make_unique<SpatialJointAngleDriver>("motor", kGround, origin, c->crank, crankAxis,
                                                                        makeConstantSpeedLaw(speed, 0.0)));
  sys.finalize();
  return c;
}

}  // namespace flexmbd::test3d
