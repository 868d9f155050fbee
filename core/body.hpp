/// @file
/// The interface every body implements: its coordinates, mass matrix, forces and the
/// kinematics of its material points (what joints and forces attach to).
#pragma once

#include <string>
#include <vector>

#include "core/matrix_sink.hpp"
#include "core/point_kinematics.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// What a coordinate measures; integrators scale their absolute tolerances by it.
enum class CoordinateKind { Position, Angle, Elastic };

/// A body contributes to the equations of motion  M(q) v' = Q(t, q, v) + ...
/// All methods are const and pure: a body holds only constant data.
/// The concrete bodies: RigidBody2d, FfrBody2d (planar), RigidBody3d, FfrBody3d
/// (spatial: beams, FE exports, SID data), Ground; added to a System with System::addBody (or the builders'
/// addRigidBody(sys, ...), ...), which gives each its offsets in q and v.
class Body {
 public:
  /// @param name unique in the system (among bodies, constraints and forces).
  explicit Body(std::string name) : name_(std::move(name)) {}
  virtual ~Body() = default;
  Body(const Body&) = delete;
  Body& operator=(const Body&) = delete;

  const std::string& name() const { return name_; }  ///< The name given at construction.

  /// Number of generalised coordinates nq.
  virtual int numCoordinates() const = 0;
  /// Number of velocities nv (default nq: the velocities are the coordinate rates).
  /// Everything the body returns below is in velocity space (mass matrix nv x nv, forces
  /// nv) and differentiated with respect to the coordinates (nv x nq), unless stated.
  virtual int numVelocities() const { return numCoordinates(); }

  // ----- the kinematic equation q' = T(q) v (docs/spatial.md) ---------------------
  /// True when T = I (planar bodies): the assembly then takes its fast paths.
  virtual bool velocitiesAreCoordinateRates() const { return true; }
  /// T(q) (nq x nv): its structural non-zeros only, added into T (the same entries at
  /// every q; a flexible body's elastic part is the identity, so a large body writes
  /// O(nq) entries, never a dense nq x nv block). Default: the identity.
  virtual void addCoordinateRateMatrix(const ConstVecRef& q, const MatrixSink& T) const;
  /// A left inverse T+(q) (nv x nq, T+ T = I) with ker T+ the directions along which no
  /// material point moves (a quaternion's length): the derivative of any body-point
  /// quantity f(q) is f_q = (f_q T) T+ = G T+. Structural non-zeros only, added into
  /// Tinv. Default: the identity.
  virtual void addCoordinateRateInverse(const ConstVecRef& q, const MatrixSink& Tinv) const;
  /// Dense T(q) (nq x nv) into T (resized): for small models and tests.
  void coordinateRateMatrix(const ConstVecRef& q, MatX& T) const;
  /// Dense T+(q) (nv x nq) into Tinv (resized): for small models and tests.
  void coordinateRateInverse(const ConstVecRef& q, MatX& Tinv) const;
  /// out += T(q) w.
  virtual void addCoordinateRate(const ConstVecRef& q, const ConstVecRef& w, Eigen::Ref<VecX> out) const {
    (void)q;
    out += w;
  }
  /// K += d(T(q) w)/dq for a fixed w (nq x nq). Default (T = I): nothing.
  virtual void addCoordinateRateJacobian(const ConstVecRef& q, const ConstVecRef& w, const MatrixSink& K) const {
    (void)q; (void)w; (void)K;
  }
  /// out = q (+) dv: the coordinates after a velocity-space increment dv (Newton
  /// corrections and projections work in velocity space). Default: q + dv.
  virtual void applyIncrement(const ConstVecRef& q, const ConstVecRef& dv, Eigen::Ref<VecX> out) const {
    out = q + dv;
  }
  /// The coordinates whose values the velocities `vcols` (ascending, body-local) move,
  /// ascending: the coordinate support of a point with velocity support vcols.
  /// Default (T = I): the same indices.
  virtual std::vector<int> coordinatesOfVelocities(const std::vector<int>& vcols) const { return vcols; }
  /// Names of the velocities as results columns ("<body>.<name>"). Default: the
  /// coordinate names with "_dot".
  virtual std::vector<std::string> velocityNames() const;
  /// Names of the coordinates, as they appear in results files ("x", "y", "theta").
  virtual std::vector<std::string> coordinateNames() const = 0;
  /// The first numFrameCoordinates() coordinates describe the reference (rigid) motion;
  /// the rest are elastic. Consistent initialisation keeps the given elastic values and
  /// moves the frame coordinates (a body is not deformed to assemble the mechanism).
  virtual int numFrameCoordinates() const { return numCoordinates(); }
  /// The first numFrameVelocities() velocities are the frame's (default: all but the
  /// elastic ones, whose velocities are their rates).
  virtual int numFrameVelocities() const { return numVelocities() - (numCoordinates() - numFrameCoordinates()); }
  /// The kind of each coordinate (default: frame coordinates are positions, the others
  /// elastic).
  virtual std::vector<CoordinateKind> coordinateKinds() const {
    std::vector<CoordinateKind> k(numCoordinates(), CoordinateKind::Elastic);
    for (int i = 0; i < numFrameCoordinates(); ++i) k[i] = CoordinateKind::Position;
    return k;
  }
  /// The kind of each velocity (default: that of the coordinate it is the rate of).
  virtual std::vector<CoordinateKind> velocityKinds() const { return coordinateKinds(); }
  /// Coordinates (nq) and velocities (nv) given at construction (initial guess).
  virtual VecX initialCoordinates() const = 0;
  virtual VecX initialVelocities() const = 0;  ///< @copydoc initialCoordinates

  /// Total mass (for checks and the Newton-Euler balance).
  virtual double mass() const = 0;
  /// M += mass matrix M(q) (nv x nv, symmetric positive definite), structural non-zeros only.
  virtual void addMassMatrix(const ConstVecRef& q, const MatrixSink& M) const = 0;
  /// out += M(q) a (the residual's inertia term, without forming M).
  virtual void addMassTimes(const ConstVecRef& q, const ConstVecRef& a, Eigen::Ref<VecX> out) const = 0;
  /// K += d(M(q) a)/dq for a fixed vector a (nv x nq).
  virtual void addMassMatrixDerivative(const ConstVecRef& q, const ConstVecRef& a,
                                       const MatrixSink& K) const = 0;
  /// Q += internal generalised forces: quadratic velocity forces (and, for flexible
  /// bodies, elastic and damping forces).
  virtual void addInternalForces(const ConstVecRef& q, const ConstVecRef& v, VecX& Q) const = 0;
  /// dQdq += d(internal forces)/dq, dQdv += d(internal forces)/dv.
  virtual void addInternalForceJacobians(const ConstVecRef& q, const ConstVecRef& v,
                                         const MatrixSink& dQdq, const MatrixSink& dQdv) const = 0;
  /// Q += generalised gravity force for the acceleration of gravity g (world axes; planar
  /// bodies take its x-y components: the plane carries the rest).
  virtual void addGravityForce(const ConstVecRef& q, const Vec3& g, VecX& Q) const = 0;
  /// K += d(gravity force)/dq.
  virtual void addGravityJacobian(const ConstVecRef& q, const Vec3& g, const MatrixSink& K) const = 0;
  /// Dense mass matrix (small systems, outputs and tests).
  MatX massMatrix(const ConstVecRef& q) const {
    MatX M = MatX::Zero(numVelocities(), numVelocities());
    addMassMatrix(q, M);
    return M;
  }
  /// Potential energy of gravity (zero at the world origin) and internal (elastic) energy.
  virtual double gravityPotential(const ConstVecRef& q, const Vec3& g) const = 0;
  /// Internal (elastic) energy at q; zero for rigid bodies.
  virtual double internalPotential(const ConstVecRef& q) const { (void)q; return 0.0; }
  /// The constant mass, stiffness and damping matrices of the body's elastic coordinates
  /// (nf x nf, sparse, views valid as long as the body), for modal analyses (the BDF
  /// order limit, linearisation); all null for a body without elastic coordinates.
  struct ElasticMatrices {
    const SpMat* mass = nullptr;       ///< M_ff
    const SpMat* stiffness = nullptr;  ///< K_ff
    const SpMat* damping = nullptr;    ///< D_ff
  };
  virtual ElasticMatrices elasticMatrices() const { return {}; }  ///< See ElasticMatrices.
  /// True if internal forces dissipate energy (damping).
  virtual bool isDissipative() const { return false; }

  // ----- material points: where joints and forces attach ------------------------
  /// Identifier of "no identifier needed": every point of the body is material (rigid).
  static constexpr int kAnyPoint = -1;
  /// The body's identifier of its material point at body coordinates `point` (a node of
  /// a flexible body), resolved once by System::finalize so that evaluations do not
  /// search: the point kinematics below take it with the coordinates. Default kAnyPoint.
  /// @throws InputError naming `user` if the body has no material point there.
  virtual int resolvePoint(const Vec3& point, const std::string& user) const {
    (void)point; (void)user;
    return kAnyPoint;
  }
  /// The body velocities the velocity of the point (coordinates `point`, identifier
  /// `pointId` from resolvePoint) depends on (ascending; the coordinates are
  /// coordinatesOfVelocities of them). Default: all.
  virtual std::vector<int> pointSupport(const Vec3& point, int pointId) const;

  /// Kinematics of the material point with body-frame coordinates `point` (identifier
  /// `pointId` from resolvePoint) over the coordinates `cols` (ascending, a superset of
  /// pointSupport; null: all n), into `out` (Jr is 2 x cols.size(), and so on; see
  /// PointKinematics::reset). Joints on large flexible bodies use only the support, so
  /// their Jacobians do not grow with the body. The Hessians (Hrx, Hry, Hphi) only if
  /// withHessians. Allocates nothing once `out` has been filled for as many coordinates.
  virtual void pointKinematics(const ConstVecRef& q, const Vec2& point, int pointId, const std::vector<int>* cols,
                               bool withHessians, PointKinematics& out) const = 0;
  /// The same for a point not resolved before, returned (resolves it and allocates:
  /// outputs and tests). @throws InputError if the body has no material point there.
  PointKinematics pointKinematics(const ConstVecRef& q, const Vec2& point, bool withHessians = true) const {
    PointKinematics p;
    pointKinematics(q, point, resolvePoint(lift(point), "point"), nullptr, withHessians, p);
    return p;
  }
  /// The same over the coordinates `cols` (allocates: outputs and tests).
  PointKinematics pointKinematics(const ConstVecRef& q, const Vec2& point, const std::vector<int>& cols,
                                  bool withHessians) const {
    PointKinematics p;
    pointKinematics(q, point, resolvePoint(lift(point), "point"), &cols, withHessians, p);
    return p;
  }
  // ----- spatial kinematics (spatial joints and forces) ---------------------------
  /// Kinematics of the material frame at the body point `point` (body axes, identifier
  /// `pointId` from resolvePoint) over the used velocities `cols` and coordinates `qcols`
  /// (null: all), into `out`. Allocates nothing once `out` was filled for as many columns.
  /// @throws InputError if the body has no spatial kinematics (planar bodies, so far).
  virtual void frameKinematics(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                               const std::vector<int>* qcols, FrameKinematics& out) const;
  /// The same for a point not resolved before, over all columns, returned (resolves the
  /// point and allocates: scene checks, outputs and tests).
  FrameKinematics frameKinematics(const ConstVecRef& q, const Vec3& point) const {
    FrameKinematics f;
    frameKinematics(q, point, resolvePoint(point, "point"), nullptr, nullptr, f);
    return f;
  }
  /// out += d(Jr^T wr + Jw^T ww)/dq (nv_used x nq_used) for fixed weights wr, ww: the
  /// curvature of the point's motion that joint Jacobians need.
  virtual void addFrameCurvature(const ConstVecRef& q, const Vec3& point, int pointId, const std::vector<int>* cols,
                                 const std::vector<int>* qcols, const Vec3& wr, const Vec3& ww,
                                 Eigen::Ref<MatX> out) const;

  /// World position of the centre of mass (planar bodies: z = 0).
  virtual Vec3 centreOfMass(const ConstVecRef& q) const = 0;

 private:
  std::string name_;
};

}  // namespace flexmbd
