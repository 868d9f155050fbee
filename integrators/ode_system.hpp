/// @file
/// A first-order system y' = f(t, y) with root functions g(t, y), as integrated by
/// CvodeSolver. Implementations may throw from rhs() and roots(): the solver stores the
/// exception and rethrows it (it never crosses the SUNDIALS callbacks).
#pragma once

#include "core/types.hpp"

namespace flexmbd {

class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  virtual int size() const = 0;
  /// ydot = f(t, y); y and ydot have size() entries.
  virtual void rhs(double t, const double* y, double* ydot) const = 0;
  virtual int numRoots() const { return 0; }
  /// g(t, y), numRoots() entries; a sign change is an event located by the solver.
  virtual void roots(double /*t*/, const double* /*y*/, double* /*g*/) const {}
};

}  // namespace flexmbd
