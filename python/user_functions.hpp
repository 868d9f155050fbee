// Python callables as the engine's user functions (core/user_function.hpp):
// a py::function wrapped into the std::function the C++ API takes. Runs release the GIL
// (Scene._run); a wrapper takes it only while the callable runs, and turns a Python
// exception into a C++ exception whose message is "<type>: <message>", which the engine
// reports as a UserFunctionError naming the element (the run ends as a solver failure).
#pragma once

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/user_function.hpp"
#include "bindings_support.hpp"

namespace flexmbd::pybind {

/// A Python callable owned by C++ objects that live and are copied without the GIL: the
/// reference is shared by a C++ shared_ptr, and dropped with the GIL taken.
class HeldCallable {
 public:
  explicit HeldCallable(const py::object& f)
      : f_(f.inc_ref().ptr(), [](PyObject* p) {
          if (!Py_IsInitialized()) return;  // interpreter gone: leak the reference rather than touch Python
          py::gil_scoped_acquire gil;
          Py_DECREF(p);
        }) {}

  /// Calls the callable with `args` (the GIL taken for the call only) and converts its
  /// result to R. @throws std::runtime_error "<type>: <message>" if it raises, or names
  /// what it returned if that is not an R.
  template <class R, class... Args>
  R call(const char* expected, Args... args) const {
    py::gil_scoped_acquire gil;
    py::object r;
    try {
      r = py::reinterpret_borrow<py::object>(f_.get())(args...);
    } catch (py::error_already_set& e) {
      // Ctrl-C while the callable ran: the run ends as interrupted (guarded() polls the stop
      // check, which throws), and Python raises the KeyboardInterrupt after it
      if (e.matches(PyExc_KeyboardInterrupt) && PythonSignalCheck::keepInterrupt(e)) {
        throw std::runtime_error("KeyboardInterrupt");
      }
      throw std::runtime_error(pythonErrorText(e));
    }
    try {
      return r.cast<R>();
    } catch (const py::cast_error&) {
      throw std::runtime_error("TypeError: it returned " + pyRepr(r) + ", not " + expected);
    }
  }

 private:
  /// "ValueError: the message" of the exception being handled (the GIL held).
  static std::string pythonErrorText(py::error_already_set& e) {
    std::string type = "exception";
    std::string text;
    try {
      type = py::str(e.type().attr("__name__")).cast<std::string>();
      text = py::str(e.value()).cast<std::string>();
    } catch (...) {  // a str() that raises: keep what is known
    }
    return text.empty() ? type : type + ": " + text;
  }
  std::shared_ptr<PyObject> f_;  ///< one reference of the callable
};

/// True for a callable that is not one of the engine's law objects.
inline bool isUserCallable(const py::handle& h) {
  return !h.is_none() && PyCallable_Check(h.ptr()) && !py::isinstance<TimeLaw>(h) && !py::isinstance<SpringLaw>(h);
}

/// A user time law from a Python callable f(t) and optional df(t), ddf(t).
inline std::shared_ptr<TimeLaw> pythonTimeLaw(const py::object& f, const py::object& df, const py::object& ddf) {
  const auto fn = [](const py::object& g) -> UserTimeFunction {
    if (g.is_none()) return {};
    const HeldCallable held(g);
    return [held](double t) { return held.call<double>("a number", t); };
  };
  return std::const_pointer_cast<TimeLaw>(makeUserTimeLaw(fn(f), fn(df), fn(ddf)));
}

/// A user spring-damper law from a Python callable f(t, x, xdot) and an optional
/// derivative(t, x, xdot) -> (df/dx, df/dxdot).
inline std::shared_ptr<SpringLaw> pythonSpringLaw(const py::object& f, const py::object& derivative) {
  const HeldCallable held(f);
  SpringDerivative d;
  if (!derivative.is_none()) {
    const HeldCallable dHeld(derivative);
    d = [dHeld](double t, double x, double xdot) {
      return dHeld.call<std::array<double, 2>>("2 numbers (df/dx, df/dxdot)", t, x, xdot);
    };
  }
  return std::make_shared<SpringLaw>(
      [held](double t, double x, double xdot) { return held.call<double>("a number", t, x, xdot); }, std::move(d));
}

/// A time-law argument: None (no law), a TimeLaw, or a Python callable f(t) (a user law
/// with finite-difference derivatives). TypeError naming the argument otherwise.
inline std::shared_ptr<TimeLaw> lawArg(const py::handle& h, const char* fn, const char* arg) {
  if (h.is_none()) return nullptr;
  if (py::isinstance<TimeLaw>(h)) return h.cast<std::shared_ptr<TimeLaw>>();
  if (isUserCallable(h)) return pythonTimeLaw(py::reinterpret_borrow<py::object>(h), py::none(), py::none());
  badArgument(fn, arg, "a time law (flexmbd.constant_law(...), flexmbd.user_law(f), a callable f(t)) or None", h);
}

/// A spring-damper law argument: None, a SpringLaw or a Python callable f(t, x, xdot).
inline SpringLawPtr springLawArg(const py::handle& h, const char* fn) {
  if (h.is_none()) return nullptr;
  if (py::isinstance<SpringLaw>(h)) return h.cast<std::shared_ptr<SpringLaw>>();
  if (isUserCallable(h)) return pythonSpringLaw(py::reinterpret_borrow<py::object>(h), py::none());
  badArgument(fn, "law", "a spring law (flexmbd.spring_law(f, derivative)), a callable f(t, x, xdot) or None", h);
}

/// The linear law's parameters, or a user law: with a law, stiffness and damping must be
/// absent (None) or 0. @throws InputError naming the function otherwise.
inline void requireLinearOrLaw(const SpringLawPtr& law, const py::handle& k, const py::handle& c, const char* fn) {
  if (!law) {
    if (k.is_none()) badArgument(fn, "stiffness", "a number (or a law=)", k);
    return;
  }
  const auto zero = [](const py::handle& h) {
    return h.is_none() || ((py::isinstance<py::float_>(h) || py::isinstance<py::int_>(h)) && h.cast<double>() == 0.0);
  };
  if (!zero(k) || !zero(c)) {
    throw InputError(std::string(fn) +
                     ": both a law and stiffness/damping given; the law replaces k (x - x0) + c x' (give one of them)");
  }
}

}  // namespace flexmbd::pybind
