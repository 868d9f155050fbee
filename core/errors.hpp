/// @file
/// Exception types of the engine. Every message names the object (body, joint, key)
/// that is wrong, what was found and what was expected.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace flexmbd {

/// Invalid user input: a scene key, a model parameter, a model built inconsistently.
/// The command line maps it to exit status 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// A model that is well formed but cannot be set up: it cannot be assembled from the
/// given positions, or it has redundant or conflicting constraints. Exit status 2.
class ModelError : public InputError {
 public:
  explicit ModelError(const std::string& message) : InputError(message) {}
};

/// A solver failed on well-formed input: the time integrator during a run (carries the
/// time reached and the last step size), or a solver outside a run that did not converge
/// (an eigensolver: time and step size NaN). The message holds the solver's reason.
/// Exit status 1.
class SolverError : public std::runtime_error {
 public:
  SolverError(const std::string& message, double time, double stepSize)
      : std::runtime_error(message), time_(time), stepSize_(stepSize) {}
  /// A solver outside a time integration (no time, no step size).
  explicit SolverError(const std::string& message) : SolverError(message, std::nan(""), std::nan("")) {}
  double time() const { return time_; }
  double stepSize() const { return stepSize_; }

 private:
  double time_;
  double stepSize_;
};

}  // namespace flexmbd
