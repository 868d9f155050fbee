/// @file
/// The interface of constraints: joints (scleronomic) and drivers (rheonomic).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/body.hpp"
#include "core/time_law.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// A body together with its current coordinates (a view, nothing is copied) and what a
/// constraint or force uses of it: the velocities `cols` and the coordinates `qcols`
/// (body-local, ascending; null: all). Derivatives are taken with respect to the used
/// velocities (first derivatives, nv_used columns) and the used coordinates (second
/// derivatives d/dq of first derivatives, nq_used columns); with T = I the two are the same.
struct BodyState {
  /// A view of body b's coordinates at `data` (nq of them) using the velocities `used`
  /// and the coordinates `usedCoordinates` (null: all; coordinates null: as `used`).
  BodyState(const Body& b, const double* data, const std::vector<int>* used = nullptr,
            const std::vector<int>* usedCoordinates = nullptr)
      : BodyState(b, data, b.numCoordinates(), used, usedCoordinates) {}
  /// The same with the body's number of coordinates known (System caches it: no virtual call).
  BodyState(const Body& b, const double* data, int numCoordinates, const std::vector<int>* used,
            const std::vector<int>* usedCoordinates)
      : body(b), q(data, numCoordinates), cols(used), qcols(usedCoordinates ? usedCoordinates : used) {}
  const Body& body;               ///< the body
  Eigen::Map<const VecX> q;        ///< its coordinates (all nq of them)
  const std::vector<int>* cols;    ///< the used velocities (body-local, ascending; null: all)
  const std::vector<int>* qcols;   ///< the used coordinates (body-local, ascending; null: all)
  /// Number of used velocities.
  int numUsed() const { return cols ? static_cast<int>(cols->size()) : body.numVelocities(); }
  /// Number of used coordinates.
  int numUsedCoordinates() const { return qcols ? static_cast<int>(qcols->size()) : body.numCoordinates(); }
  /// Kinematics of the body point `p` (identifier `id`: BodyStates::pointId) over the
  /// used coordinates, into `out` (no allocation once `out` has been filled before).
  void point(const Vec2& p, int id, bool withHessians, PointKinematics& out) const {
    body.pointKinematics(q, p, id, cols, withHessians, out);
  }
  /// The same, returned (allocates).
  PointKinematics point(const Vec2& p, int id, bool withHessians) const {
    PointKinematics out;
    point(p, id, withHessians, out);
    return out;
  }
  /// Spatial kinematics of the material frame at a body point, over the used columns.
  void frame(const Vec3& p, int id, FrameKinematics& out) const { body.frameKinematics(q, p, id, cols, qcols, out); }
  /// out += d(Jr^T wr + Jw^T ww)/dq over the used columns.
  void addCurvature(const Vec3& p, int id, const Vec3& wr, const Vec3& ww, Eigen::Ref<MatX> out) const {
    body.addFrameCurvature(q, p, id, cols, qcols, wr, ww, out);
  }
};

/// The bodies of one constraint or force element with their coordinates, in the
/// element's order; a fixed-capacity list (made per evaluation, so it lives on the stack).
class BodyStates {
 public:
  /// The most bodies one constraint or force element may connect.
  static constexpr int kMaxBodies = 4;
  /// @throws std::logic_error beyond kMaxBodies (System::addConstraint/addForce refuse
  /// such elements first).
  void add(const Body& b, const double* q, const std::vector<int>* used,
           const std::vector<int>* usedCoordinates = nullptr) {
    if (n_ == kMaxBodies) throw std::logic_error("BodyStates: more than kMaxBodies bodies");
    states_[n_++].emplace(b, q, used, usedCoordinates);
  }
  /// The same with the body's number of coordinates given (System: cached at finalize).
  void add(const Body& b, const double* q, int numCoordinates, const std::vector<int>* used,
           const std::vector<int>* usedCoordinates) {
    if (n_ == kMaxBodies) throw std::logic_error("BodyStates: more than kMaxBodies bodies");
    states_[n_++].emplace(b, q, numCoordinates, used, usedCoordinates);
  }
  int size() const { return n_; }  ///< Number of bodies (the element's bodies()).
  const BodyState& operator[](int k) const { return *states_[k]; }  ///< The state of bodies()[k].
  /// The body's identifier of the element's attachment k (in the order of its
  /// attachments()), resolved by System::finalize; Body::kAnyPoint when not resolved.
  int pointId(int k) const { return pointIds_ && k < numPointIds_ ? pointIds_[k] : Body::kAnyPoint; }
  /// Identifiers of the attachments (System: its table, which outlives the states).
  void setPointIds(const int* ids, int n) {
    pointIds_ = ids;
    numPointIds_ = n;
  }

 private:
  std::array<std::optional<BodyState>, kMaxBodies> states_;
  int n_ = 0;
  const int* pointIds_ = nullptr;
  int numPointIds_ = 0;
};

/// A body point a constraint or force element attaches to (body axes; planar: z = 0).
struct Attachment {
  BodyIndex body;             ///< the body
  Vec3 point = Vec3::Zero();  ///< the point in body axes
};

/// Constraint equations g(q, t) = h(q) - f(t) = 0 of the constraint's bodies (Haug1989). Their
/// velocity form is G v_local = f'(t), v_local = [used velocities of body 0; of body 1; ...]
/// (see BodyState). The caller keeps one per constraint: evaluations into it reuse its memory.
struct ConstraintEvaluation {
  VecX h;               ///< h(q), m
  MatX G;               ///< velocity Jacobian, m x nv_local (= dh/dq when T = I)
  /// H_a = d(G_a^T)/dq_local, m matrices nv_local x nq_local (only when asked): the
  /// derivative of the constraint force direction. With T = I, the Hessian of h_a.
  std::vector<MatX> H;
  KinematicsWork work;  ///< working memory of evaluate()
};

/// The interface of joints and drivers: m equations g(q, t) = h(q) - f(t) = 0 (Haug1989) on the
/// coordinates of its bodies (ConstraintEvaluation), with their Jacobian G and, on
/// request, Hessians; drivers add a prescribed f(t). The system's multipliers lambda of
/// its equations give the reactions(). Added to a System with System::addConstraint
/// (or the builders' addRevoluteJoint(sys, ...), ...); evaluated through System's maps.
class Constraint {
 public:
  /// @param name unique in the system (among bodies, constraints and forces).
  /// @param bodies the bodies the equations act on, in the order of BodyStates.
  Constraint(std::string name, std::vector<BodyIndex> bodies)
      : name_(std::move(name)), bodies_(std::move(bodies)) {}
  virtual ~Constraint() = default;
  Constraint(const Constraint&) = delete;
  Constraint& operator=(const Constraint&) = delete;

  const std::string& name() const { return name_; }  ///< The name given at construction.
  /// The bodies whose coordinates enter h (ground included where it takes part).
  const std::vector<BodyIndex>& bodies() const { return bodies_; }

  /// Body points the constraint attaches to, resolved by System::finalize() into the
  /// identifiers BodyStates::pointId(k) gives in this order.
  virtual std::vector<Attachment> attachments() const { return {}; }
  /// The coordinates of bodies()[slot] that h depends on (ascending), if the
  /// constraint knows them better than System::finalize(), which takes the union of
  /// the supports of the attachment points on that body, or all of its coordinates.
  virtual std::optional<std::vector<int>> coordinatesUsed(int slot) const {
    (void)slot;
    return std::nullopt;
  }

  /// Number of equations m (rows of h and G).
  virtual int numEquations() const = 0;
  /// "revolute", "prismatic", "fixed", "body_coordinate", "joint_angle", ...
  virtual std::string typeName() const = 0;
  /// Drivers prescribe motion (do work); joints do not.
  virtual bool isDriver() const { return false; }
  /// The period of h when h is an angle known only modulo it (2 pi for a spatial joint
  /// angle, from atan2): g = h - f is then taken in (-period/2, period/2]. 0: none.
  virtual double equationPeriod() const { return 0.0; }

  /// h, G and, if withHessians, the Hessians of each equation (H is left as it was
  /// otherwise). Allocates nothing when `out` was filled by this constraint before.
  virtual void evaluate(const BodyStates& bodies, bool withHessians, ConstraintEvaluation& out) const = 0;
  /// Prescribed part f(t) and its exact derivatives (zero for joints).
  /// Allocates nothing when the vectors have the size m already.
  virtual void timeFunction(double t, VecX& f, VecX& df, VecX& ddf) const {
    (void)t;
    f.setZero(numEquations());
    df.setZero(numEquations());
    ddf.setZero(numEquations());
  }

  /// Names of the reaction outputs ("fx", "fy", "m" for joints, "effort" for drivers).
  virtual std::vector<std::string> reactionNames() const = 0;
  /// Reaction outputs from the multipliers lambda (m): for joints the force (world
  /// axes) and moment exerted on the last body at its joint point; for drivers the
  /// generalised force applied along the driven quantity.
  virtual VecX reactions(const BodyStates& bodies, const VecX& lambda) const = 0;

  /// A driver named `name` that prescribes this joint's free motion `quantity`
  /// ("displacement": along the joint's line) by `law`, or null when the joint has no
  /// such motion: the joint_displacement driver of a scene asks the joint for it, so a
  /// new joint offers its drivers here, without a change to the readers.
  virtual std::unique_ptr<Constraint> makeDriver(const std::string& quantity, std::string name,
                                                 TimeLawPtr law) const {
    (void)quantity;
    (void)name;
    (void)law;
    return nullptr;
  }

 private:
  std::string name_;
  std::vector<BodyIndex> bodies_;
};

}  // namespace flexmbd
