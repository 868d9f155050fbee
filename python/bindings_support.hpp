// Helpers of the Python bindings (flexmbd_module.cpp, spatial_bindings.cpp): arguments
// converted with errors that name the function and the argument (TypeError for a wrong
// type, InputError (ValueError) for a wrong value), bodies and joints by index or name.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "core/errors.hpp"
#include "core/system.hpp"

namespace flexmbd::pybind {

namespace py = pybind11;

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

/// A body given as a BodyIndex or by name ("ground" included).
inline BodyIndex body(const System& sys, const py::handle& b, const char* fn = "body", const char* arg = "body") {
  if (py::isinstance<py::str>(b)) {
    const std::string name = b.cast<std::string>();
    return name == "ground" ? kGround : sys.findBody(name);  // InputError listing the known bodies
  }
  if (!py::isinstance<BodyIndex>(b)) badArgument(fn, arg, "a body name or a BodyIndex", b);
  return b.cast<BodyIndex>();
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

}  // namespace flexmbd::pybind
