/// @file
/// Spatial flexible body in the floating frame of reference formulation.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "bodies/ffr_beam_model_3d.hpp"
#include "bodies/ffr_invariants_3d.hpp"
#include "bodies/rigid_body_3d.hpp"
#include "core/body.hpp"

namespace flexmbd {

/// Coordinates q = (R (3), p (4), q_f (nf)): frame origin (world), Euler parameters of the
/// frame, elastic coordinates. Velocities v = (R' (3, world axes), w (3, body axes), q_f').
/// A material point at u = u0 + N q_f (body axes) is at r = R + A(p) u and moves with
/// r' = R' - A u~ w + A N q_f'.
///
/// Choice: R' in WORLD axes, as RigidBody3d. Then the translational rows of a point's
/// Jacobian are the identity, gravity is m g, and T = diag(I, 1/2 L(p)^T, I) as for the
/// rigid body; the price is that the R-w and R-f mass blocks carry A(p) (Shabana2005, ch. 5:
/// m_RR = m I, m_Rtheta = -A s~, m_Rf = A S-bar), so the mass matrix depends on p. Body-axis
/// R' would make M independent of p but put A into every point Jacobian and into gravity.
///
/// Mass matrix (docs/spatial-flexible.md, "Spatial FFR body"; Shabana2005, ch. 5):
///   M = [ m I    -A s~        A S-bar  ]   s = int rho u dV = first moment + S-bar q_f
///       [        I(q_f)       Y(q_f)   ]   I = int rho u~^T u~ dV = tr(J) 1 - J, J = int rho u u^T dV
///       [ sym.                m_ff     ]   Y = int rho u~ N dV
/// Quadratic velocity forces, elastic K_ff q_f and damping D_ff q_f' are in
/// addInternalForces (with a beam model that has geometric stiffening, dU/dq_f of its
/// strain energy instead of K_ff q_f). The length of p is a gauge, as for RigidBody3d.
///
/// Nodes: a node's section frame is A_node = A (I + skew(Ntheta q_f)), first order in the
/// small nodal rotations theta = Ntheta q_f like the linear element (not exactly
/// orthonormal: the error is O(|theta|^2)); its world angular velocity is taken as
/// A (w + Ntheta q_f'), which equals that of A_node up to O(|theta| |theta'|).
class FfrBody3d final : public Body {
 public:
  /// @param name the body's name.
  /// @param invariants the body's inertia invariants and elastic matrices.
  /// @param initial frame ORIGIN (not the centre of mass), orientation, origin velocity
  ///        (world) and angular velocity (body axes).
  /// @param qf0, qf0dot initial elastic coordinates and rates (empty: zero).
  /// @throws InputError naming the body if the invariants' sizes are inconsistent, an
  ///         entry is not finite, S_lk != S_kl^T, the mass is not positive, or the initial
  ///         state is invalid.
  FfrBody3d(std::string name, FfrInvariants3d invariants, const FrameState3d& initial, VecX qf0 = {},
            VecX qf0dot = {});

  /// From a beam mesh model: its invariants, and its strain energy (with geometric
  /// stiffening if the model has it on) for the elastic forces and their Jacobian.
  /// @throws InputError as above, or if `model` is null.
  FfrBody3d(std::string name, std::shared_ptr<const FfrBeamModel3d> model, const FrameState3d& initial,
            VecX qf0 = {}, VecX qf0dot = {});

  const FfrInvariants3d& invariants() const { return inv_; }
  /// m_ff, K_ff, D_ff: the modal analysis of the integrator choice, the elastic tolerances
  /// and the BDF stability check use them as for planar bodies.
  ElasticMatrices elasticMatrices() const override { return {&inv_.mff, &inv_.kff, &inv_.dff}; }
  /// The generating beam model, or null (invariants given directly).
  const FfrBeamModel3d* model() const { return model_.get(); }
  int numElastic() const { return nf_; }

  int numCoordinates() const override { return 7 + nf_; }
  int numVelocities() const override { return 6 + nf_; }
  int numFrameCoordinates() const override { return 7; }
  int numFrameVelocities() const override { return 6; }
  std::vector<std::string> coordinateNames() const override;
  std::vector<std::string> velocityNames() const override;
  std::vector<CoordinateKind> coordinateKinds() const override;
  std::vector<CoordinateKind> velocityKinds() const override;
  VecX initialCoordinates() const override;
  VecX initialVelocities() const override;
  double mass() const override { return inv_.mass; }

  bool velocitiesAreCoordinateRates() const override { return false; }
  void addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const override;
  void addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const override;
  void addCoordinateRate(const ConstVecRef& q, const ConstVecRef& w, Eigen::Ref<VecX> out) const override;
  void addCoordinateRateJacobian(const ConstVecRef& q, const ConstVecRef& w, const MatrixSink& K) const override;
  void applyIncrement(const ConstVecRef& q, const ConstVecRef& dv, Eigen::Ref<VecX> out) const override;
  std::vector<int> coordinatesOfVelocities(const std::vector<int>& vcols) const override;

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
  bool isDissipative() const override;

  using Body::pointKinematics;
  /// @throws InputError: a spatial body has no planar point kinematics.
  void pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                       bool withHessians, PointKinematics& out) const override;
  /// The index of the node at `point` in invariants().points (1e-9 relative tolerance).
  int resolvePoint(const Vec3& point, const std::string& user) const override;
  /// Frame velocities 0..5 and 6 + the elastic coordinates the node's N and Ntheta use.
  std::vector<int> pointSupport(const Vec3& point, int pointId) const override;
  using Body::frameKinematics;
  void frameKinematics(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                       const std::vector<int>* qcols, FrameKinematics& out) const override;
  void addFrameCurvature(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                         const std::vector<int>* qcols, const Vec3& wr, const Vec3& ww,
                         Eigen::Ref<MatX> out) const override;
  Vec3 centreOfMass(const ConstVecRef& q) const override;

  // ----- helpers for outputs and tests (own coordinates q) --------------------------
  /// The deformation at a point of the generating beam mesh's axis.
  struct BeamDeflection {
    Vec3 displacement = Vec3::Zero();       ///< elastic displacement u = N q_f, body axes
    Vec3 position = Vec3::Zero();           ///< deformed position, world axes: R + A (u0 + u)
    Vec3 worldDisplacement = Vec3::Zero();  ///< A u
    BeamSectionForces3d sectionForces;      ///< element axes (BeamElement3d)
  };
  /// At `xi` in [0, 1] along element `element` of model() (FfrBeamModel3d::locate finds
  /// them for a point of the undeformed axis).
  /// @throws InputError naming the body if it was not made from a beam mesh.
  BeamDeflection beamDeflection(const ConstVecRef& q, int element, double xi) const;
  /// A(p / |p|).
  static Mat3 rotationOf(const ConstVecRef& q) { return quaternionRotation(q.segment<4>(3)); }
  /// int rho u dV (body axes).
  Vec3 firstMomentAt(const ConstVecRef& q) const;
  /// I(q_f) = int rho u~^T u~ dV about the frame origin, body axes (Shabana2005, eq. 5.110).
  Mat3 inertiaAt(const ConstVecRef& q) const;

 private:
  int nodeIndex(const Vec3& point, int pointId) const;
  /// A node and its motion at q_f: u = u0 + N q_f, theta = Ntheta q_f (Shabana2005, ch. 5).
  struct NodeMotion {
    const FfrPoint3d& point;
    Vec3 u, theta;
  };
  NodeMotion nodeMotion(const Vec3& point, int pointId, const ConstVecRef& qf) const;
  /// J(q_f) = int rho u u^T dV.
  Mat3 secondMomentAt(const ConstVecRef& qf) const;
  /// quadratic(k, l) += qf^T R_kl qf for k <= l (sectionRotation_).
  void addSectionRotationMoment(const ConstVecRef& qf, Mat3& quadratic) const;
  /// J(q_f) from its quadratic part, (qf^T (S_kl + R_kl) qf) in the upper triangle (k <= l).
  Mat3 secondMomentFrom(const ConstVecRef& qf, const Mat3& quadratic) const;
  /// dJ/dq_f,k.
  Mat3 secondMomentDerivative(const ConstVecRef& qf, int k) const;
  /// Column k of Y(q_f) = int rho u~ N dV (Shabana2005, ch. 5).
  Vec3 skewShapeColumn(const ConstVecRef& qf, int k) const;

  /// The checks of the invariants and the initial state, and the constants derived from
  /// them (after inv_ is bound).
  void setUp();

  std::shared_ptr<const FfrBeamModel3d> model_;  // generating mesh model, or null
  FfrInvariants3d ownInvariants_;                // given directly; empty with a model
  const FfrInvariants3d& inv_;                   // ownInvariants_ or model_->invariants()
  int nf_ = 0;
  FrameState3d initial_;
  VecX qf0_, qf0dot_;
  Mat3X x0_;                 // int rho u0~ N dV (3 x nf), constant
  std::vector<std::vector<int>> nodeSupport_;  // per node: the elastic coordinates its shapes use
  std::array<SpMat, 3> w_;   // W_x = S_yz - S_zy, W_y = S_zx - S_xz, W_z = S_xy - S_yx (skew):
                             // int rho (N a) x (N b) dV = (a^T W_i b)_i
  /// A symmetric matrix R of a pair k <= l of body axes (the pairs' arrays of the invariants,
  /// those present and not zero).
  struct PairTerm {
    int k, l;
    SpMat R;
  };
  /// R_kl: J gains qf^T R_kl qf at (k, l) and (l, k) (FfrInvariants3d::rKL, the
  /// cross-sections' second-order rotation).
  std::vector<PairTerm> sectionRotation_;
  /// G_kl: Q_f gains -(1 or 2) w_k w_l G_kl qf (FfrInvariants3d::spinStiffness; 2 for k < l).
  std::vector<PairTerm> spinStiffening_;
  /// H_i of the invariants (FfrInvariants3d::hI), or empty matrices (nf x nf, no entries)
  /// when absent: Y = int rho u~ N dV gains (qf^T H_i)_i, Q_theta -(qf'^T H_i qf')_i -
  /// w x (qf^T H_i qf')_i.
  std::array<SpMat, 3> h_;
  bool hasCoupling_ = false;
};

}  // namespace flexmbd
