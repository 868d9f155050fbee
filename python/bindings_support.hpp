// Helpers of the Python bindings (flexmbd_module.cpp, spatial_bindings.cpp): arguments
// converted with errors that name the function and the argument (TypeError for a wrong
// type, InputError (ValueError) for a wrong value), bodies and joints by index or name.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <csignal>
#include <string>

#include "core/errors.hpp"
#include "core/stop_request.hpp"
#include "core/system.hpp"
#include "simulation/simulation.hpp"

namespace flexmbd::pybind {

namespace py = pybind11;

/// Ctrl-C during a run: while it lives, the run's stop check
/// (core/stop_request.hpp) gives Python's signal handlers a turn every 0.1 s (the GIL taken
/// for it); an exception one raises (KeyboardInterrupt) stops the run within its step, and
/// raiseIfInterrupted() raises it in Python once the run has returned. Made on the thread
/// of the run, without the GIL.
class PythonSignalCheck {
 public:
  PythonSignalCheck() : scope_(poll) { state() = State{}; }
  PythonSignalCheck(const PythonSignalCheck&) = delete;
  PythonSignalCheck& operator=(const PythonSignalCheck&) = delete;

  /// With the GIL: raises the signal handler's exception if the run was stopped by it.
  static void raiseIfInterrupted() {
    State& s = state();
    if (!s.type) return;
    PyErr_Restore(s.type, s.value, s.traceback);  // the references go to Python's error state
    s = State{};
    throw py::error_already_set();
  }

  /// With the GIL, in a Python user function that raised KeyboardInterrupt (Ctrl-C while
  /// it ran): keeps the exception for raiseIfInterrupted(), so that the run's next stop
  /// check ends it as an interruption. False if no check is installed on this thread.
  static bool keepInterrupt(py::error_already_set& e) {
    if (!detail::tStopPoll) return false;
    State& s = state();
    if (s.type) return true;
    e.restore();  // back into Python's error state, then taken from it
    PyErr_Fetch(&s.type, &s.value, &s.traceback);
    return true;
  }

 private:
  struct State {
    unsigned calls = 0;
    std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
    PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
  };
  static State& state() {
    thread_local State s;
    return s;
  }
  static void poll(double t) {
    State& s = state();
    if (s.type) throw RunInterrupted("interrupted in Python at t = " + std::to_string(t), SIGINT);
    if (++s.calls % 64 != 0) return;  // the clock read at most every 64 residuals
    const auto now = std::chrono::steady_clock::now();
    if (now - s.last < std::chrono::milliseconds(100)) return;
    s.last = now;
    {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() == 0) return;  // only the main thread runs handlers
      PyErr_Fetch(&s.type, &s.value, &s.traceback);
    }
    throw RunInterrupted("interrupted by KeyboardInterrupt in Python at t = " + std::to_string(t), SIGINT);
  }
  StopPollScope scope_;
};

inline std::string pyRepr(const py::handle& h) { return py::repr(h).cast<std::string>(); }

/// TypeError "<fn>: <arg> must be <expected>, got <repr>".
[[noreturn]] inline void badArgument(const char* fn, const char* arg, const char* expected, const py::handle& h) {
  throw py::type_error(std::string(fn) + ": " + arg + " must be " + expected + ", got " + pyRepr(h));
}

/// h as T (pybind11's conversions: lists, tuples, NumPy arrays), or TypeError naming arg.
template <class T>
T argumentAs(const py::handle& h, const char* fn, const char* arg, const char* expected) {
  if (h.is_none() || py::isinstance<py::str>(h) || py::isinstance<py::bool_>(h)) badArgument(fn, arg, expected, h);
  try {
    return h.cast<T>();
  } catch (const py::cast_error&) {
    badArgument(fn, arg, expected, h);
  }
}

inline double numberArg(const py::handle& h, const char* fn, const char* arg) {
  return argumentAs<double>(h, fn, arg, "a number");
}
inline Vec2 vec2Arg(const py::handle& h, const char* fn, const char* arg) {
  return argumentAs<Vec2>(h, fn, arg, "2 numbers (x, y)");
}
inline Vec3 vec3Arg(const py::handle& h, const char* fn, const char* arg) {
  return argumentAs<Vec3>(h, fn, arg, "3 numbers (x, y, z)");
}

/// A body of `sys` given as a BodyIndex or by name ("ground" included).
inline BodyIndex body(const System& sys, const py::handle& b, const char* fn = "body", const char* arg = "body") {
  if (py::isinstance<py::str>(b)) {
    const std::string name = b.cast<std::string>();
    return name == "ground" ? kGround : sys.findBody(name);  // InputError listing the known bodies
  }
  if (!py::isinstance<BodyIndex>(b)) badArgument(fn, arg, "a body name or a BodyIndex", b);
  const BodyIndex i = b.cast<BodyIndex>();
  if (i.value < 0 || i.value >= sys.numBodies()) {
    throw InputError(std::string(fn) + ": " + arg + ": no body with index " + std::to_string(i.value) +
                     " (the system has " + std::to_string(sys.numBodies()) + " bodies, the ground included)");
  }
  return i;
}

/// A joint given as a ConstraintIndex or by name.
inline ConstraintIndex joint(const System& sys, const py::handle& j, const char* fn = "joint",
                             const char* arg = "joint") {
  if (py::isinstance<py::str>(j)) {
    const std::string name = j.cast<std::string>();
    for (int c = 0; c < sys.numConstraints(); ++c) {
      if (sys.constraint(ConstraintIndex(c)).name() == name) return ConstraintIndex(c);
    }
    throw InputError("no joint named '" + name + "'");
  }
  if (!py::isinstance<ConstraintIndex>(j)) badArgument(fn, arg, "a joint name or a ConstraintIndex", j);
  return j.cast<ConstraintIndex>();
}

/// The spatial builders (spatial_bindings.cpp): classes and functions on the module,
/// methods on System.
void bindSpatial(py::module_& m, py::class_<System>& system);

/// The add_<type>_<kind> methods of the kinds declared through the registry
/// (component_bindings.cpp).
void bindComponentKinds(py::class_<System>& system);

}  // namespace flexmbd::pybind
