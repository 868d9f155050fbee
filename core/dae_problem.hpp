/// @file
/// The interface the time integrators see: a DAE F(t, y, y') = 0 with a fixed sparse
/// Jacobian pattern. The engine's assembled model (DaeSystem) is one; the hand-coded
/// benchmark problems are others, integrated by the same integrators.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "core/sparse_pattern.hpp"
#include "core/types.hpp"

namespace flexmbd {

/// Scratch memory of one evaluating thread (an integrator owns one): what a residual or
/// Jacobian needs besides its arguments, sized from the model once, so that evaluations
/// allocate nothing and the problem itself holds no mutable state.
class DaeScratch {
 public:
  virtual ~DaeScratch() = default;
};

class DaeProblem {
 public:
  virtual ~DaeProblem() = default;

  /// Number of unknowns n of y (and of equations in F).
  virtual int size() const = 0;
  /// Pattern of dF/dy + cj dF/dy' (square, n), fixed for the whole run.
  virtual const SparsePattern& pattern() const = 0;
  /// Per unknown: 1 if it takes part in the local error test (differential), 0 if not
  /// (multipliers and other algebraic variables).
  virtual VecX differentialIds() const = 0;
  /// Elimination groups for KLU's constrained orderings (integrators/klu_ordering.hpp),
  /// size n: 0 elastic unknowns, 1 frame unknowns, 2 multipliers. Default: none (KLU's
  /// own ordering).
  virtual std::vector<int64_t> eliminationGroups() const { return {}; }

  /// Scratch for residual() and jacobian(), made once per integrator (or thread).
  virtual std::unique_ptr<DaeScratch> makeScratch() const { return std::make_unique<DaeScratch>(); }

  /// F = F(t, y, y'); y, y', F of size n. Allocates nothing (scratch from makeScratch()).
  virtual void residual(double t, const double* y, const double* yp, double* F, DaeScratch& scratch) const = 0;
  /// J += dF/dy + cj dF/dy' at the pattern's positions. J(cj = 0) is dF/dy, and
  /// J(1) - J(0) is dF/dy' (used by integrators that need the two apart).
  virtual void jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J,
                        DaeScratch& scratch) const = 0;

  /// Whether addRateJacobianProduct() is provided (otherwise an integrator that needs
  /// dF/dy' x forms it from J(1) - J(0)).
  virtual bool providesRateJacobianProduct() const { return false; }
  /// r += dF/dy' x at (t, y, y'), without assembling a Jacobian; x and r of size n.
  /// Allocates nothing. Only where providesRateJacobianProduct().
  virtual void addRateJacobianProduct(double /*t*/, const double* /*y*/, const double* /*yp*/,
                                      const double* /*x*/, double* /*r*/, DaeScratch& /*scratch*/) const {
    throw std::logic_error("DaeProblem::addRateJacobianProduct: not provided by this problem");
  }

  /// The same with a scratch made for the call (tests, tools; allocates).
  void residual(double t, const double* y, const double* yp, double* F) const {
    residual(t, y, yp, F, *makeScratch());
  }
  void jacobian(double t, const double* y, const double* yp, double cj, JacobianSink& J) const {
    jacobian(t, y, yp, cj, J, *makeScratch());
  }
};

}  // namespace flexmbd
