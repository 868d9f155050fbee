/// @file
/// Planar flexible body in the floating frame of reference formulation.
#pragma once

#include <memory>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_invariants.hpp"
#include "bodies/rigid_body_2d.hpp"
#include "core/body.hpp"

namespace flexmbd {

/// Coordinates q = (x, y, theta, q_1..q_nf): frame position, frame angle, elastic
/// coordinates. A material point is at r = R + A(theta) (u0 + N q_f). The mass matrix,
/// quadratic velocity vector and gravity force come from the constant invariants and
/// the current q_f (docs/flexible-bodies.md; Doc003; Shabana2005, ch. 5):
///   M = [ m I    S A s          A S-bar                 ]   s = int rho u dV
///       [        I0 + 2 I1.qf + qf^T m_ff qf   J0^T + qf^T S~ ]       = first moment + S-bar qf
///       [ sym.                                m_ff        ]
class FfrBody2d final : public Body {
 public:
  /// From invariants given directly (reduced models from other FE tools).
  /// @throws InputError naming the body if the invariants are invalid.
  FfrBody2d(std::string name, FfrInvariants invariants, const FrameState2d& initial);
  /// From a beam mesh (the model also supplies the strain energy, so geometric
  /// stiffening is available, and section forces for outputs).
  FfrBody2d(std::string name, std::shared_ptr<const FfrBeamModel> model, const FrameState2d& initial);

  /// Initial elastic coordinates and velocities (default zero: undeformed, at rest
  /// relative to the frame). Call before adding the body to a System.
  /// @throws InputError if the sizes are not numElastic() or values are not finite.
  FfrBody2d& setInitialElasticState(const VecX& qf, const VecX& qfDot);

  const FfrInvariants& invariants() const { return inv_; }
  /// The generating mesh model, or null if the body was given by its invariants.
  const FfrBeamModel* beamModel() const { return model_.get(); }
  int numElastic() const { return inv_.numElastic(); }

  int numCoordinates() const override { return 3 + inv_.numElastic(); }
  int numFrameCoordinates() const override { return 3; }
  std::vector<std::string> coordinateNames() const override;
  /// x, y: positions; theta: angle; q_1..q_nf: elastic.
  std::vector<CoordinateKind> coordinateKinds() const override {
    std::vector<CoordinateKind> k(numCoordinates(), CoordinateKind::Elastic);
    k[0] = k[1] = CoordinateKind::Position;
    k[2] = CoordinateKind::Angle;
    return k;
  }
  VecX initialCoordinates() const override;
  VecX initialVelocities() const override;
  double mass() const override { return inv_.mass; }
  void addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const override;
  void addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const override;
  void addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a, const MatrixSink& K) const override;
  void addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const override;
  void addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v, const MatrixSink& dQdq,
                                 const MatrixSink& dQdv) const override;
  void addGravityForce(const ConstVecRef& q, const Vec3& g, VecX& Q) const override;
  void addGravityJacobian(const ConstVecRef& q, const Vec3& g, const MatrixSink& K) const override;
  double gravityPotential(const ConstVecRef& q, const Vec3& g) const override;
  double internalPotential(const ConstVecRef& q) const override;
  bool isDissipative() const override { return inv_.dff.nonZeros() > 0 && inv_.dff.coeffs().cwiseAbs().maxCoeff() > 0.0; }
  /// Attachment points are the nodes (points of the invariants): r = R + A (u0 + N q_f),
  /// phi = theta + Nphi q_f (Shabana2005, ch. 5).
  ElasticMatrices elasticMatrices() const override { return {&inv_.mff, &inv_.kff, &inv_.dff}; }
  using Body::pointKinematics;
  void pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                       bool withHessians,
                       PointKinematics& out) const override;
  /// The frame coordinates and the elastic coordinates the node's shape depends on.
  std::vector<int> pointSupport(const Vec3& point, int pointId) const override;
  /// The index of the node at `point` in invariants().points (z must be 0).
  int resolvePoint(const Vec3& point, const std::string& user) const override;
  Vec3 centreOfMass(const ConstVecRef& q) const override;
  /// The centre of mass in the plane.
  Vec2 planarCentreOfMass(const ConstVecRef& q) const;
  /// Kinematics of any FfrPoint (e.g. a point inside an element, for outputs).
  PointKinematics pointKinematics(const ConstVecRef& q, const FfrPoint& p, bool withHessians = true) const;

  // ----- outputs, from the body's own coordinates q (numCoordinates(): x, y, theta, q_f) --
  /// The deformation at a point of the generating beam mesh's axis.
  struct BeamDeflection {
    Vec2 displacement = Vec2::Zero();       ///< elastic displacement u = N q_f, body axes (ux, uy)
    Vec2 sectionForces = Vec2::Zero();      ///< axial force N, bending moment M
    Vec2 position = Vec2::Zero();           ///< deformed position, world axes: R + A (u0 + u)
    Vec2 worldDisplacement = Vec2::Zero();  ///< A u
  };
  /// At `xi` in [0, 1] along element `element` of beamModel() (FfrBeamModel::locate finds
  /// them for a point of the undeformed axis).
  /// @throws InputError naming the body if it was not made from a beam mesh.
  BeamDeflection beamDeflection(const ConstVecRef& q, int element, double xi) const;
  /// Elastic displacement N q_f of a point of the invariants (e.g. invariants().points[k]),
  /// world axes: A(theta) N q_f.
  Vec2 worldElasticDisplacement(const ConstVecRef& q, const FfrPoint& p) const;

 private:
  int findPoint(const Vec2& point) const;
  /// The node `pointId` (resolvePoint), or the node at `point` when pointId is kAnyPoint.
  const FfrPoint& node(const Vec2& point, int pointId) const;
  /// Column k of the frame-elastic mass block (3 x nf); the frame-frame block is
  /// frameMassAt in the .cpp, at the rotation the caller has computed.
  Eigen::Vector3d frameElasticMassColumn(const Mat2& A, const ConstVecRef& qf, int k) const;
  void kinematicsOn(const ConstVecRef& q, const FfrPoint& p, const std::vector<int>* cols, bool withHessians,
                    PointKinematics& out) const;

  FfrInvariants ownInvariants_;                  // given directly; empty with a model
  std::shared_ptr<const FfrBeamModel> model_;    // generating mesh model, or null
  const FfrInvariants& inv_;                     // ownInvariants_ or model_->invariants()
  SpMat polar_;  // m_ff + R (FfrInvariants::polarQuadratic), the polar moment's quadratic part
  FrameState2d initial_;
  VecX initialQf_, initialQfDot_;
};

}  // namespace flexmbd
