// The flexmbd Python module's compiled part (_flexmbd): thin pybind11 bindings of the
// C++ API. Scenes (from text, with the scene format's keys), the planar builders of
// builders/planar_builders.hpp, the beam model, time laws, solver settings, and a run
// that returns the results table (the columns of results.csv) and the summary (the keys
// of summary.json). The Python package (python/flexmbd/__init__.py) adds NumPy results,
// overrides of scene keys and the exceptions. docs/python.md.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "bodies/ffr_beam_model.hpp"
#include "bodies/ffr_body_2d.hpp"
#include "builders/planar_builders.hpp"
#include "builders/spatial_builders.hpp"
#include "core/errors.hpp"
#include "analysis/linearization.hpp"
#include "simulation/reference_by_run.hpp"
#include "simulation/simulation.hpp"
#include "scene/json_reader.hpp"
#include "results/results_writer.hpp"
#include "scene/scene.hpp"
#include "scene/scene_path.hpp"
#include "results/adjoint_results.hpp"
#include "results/sensitivity_results.hpp"
#include "linkage/kinematics_scene.hpp"
#include "tensegrity/tensegrity_scene.hpp"
#include "bindings_support.hpp"
#include "user_functions.hpp"

namespace py = pybind11;
using namespace flexmbd;
using namespace flexmbd::pybind;

namespace {

using Law = std::shared_ptr<TimeLaw>;
Law mutableLaw(TimeLawPtr p) { return std::const_pointer_cast<TimeLaw>(std::move(p)); }

/// What a run returns: the results table (row-major) and the summary as JSON text.
struct RunOutput {
  std::vector<std::string> columns;
  std::vector<double> data;
  long rows = 0;
  std::string summary;
  bool ok = false;
};

/// Runs a scene (finalizing its system first if needed). Called without the GIL: it
/// touches no Python object. InputError and ModelError propagate (translated to the
/// Python exceptions of the same names); every other failure is a failed summary with
/// the rows up to it (simulateKeepingFailures).
RunOutput runScene(Scene& scene, bool progress) {
  if (!scene.system.isFinalized()) scene.system.finalize();
  RunOutput out;
  out.columns = resultColumns(scene);
  SolverSettings settings = scene.solver;
  settings.progress = progress;
  checkSolverSettings(settings);
  std::vector<double> row;
  SpatialJointOutputs joints(scene.system);  // unwraps joint angles over the rows
  const SimulationSummary summary = simulateKeepingFailures(scene.system, settings, [&](const OutputSample& s) {
    resultRow(scene, out.columns, s, row, joints);
    out.data.insert(out.data.end(), row.begin(), row.end());
    ++out.rows;
  });
  out.ok = summary.ok;
  out.summary = summaryJson(summary, scene);
  return out;
}

/// The run of the scene `text` with forward sensitivities with respect to `paths`
/// (results/sensitivity_results.hpp): the table holds the scene's columns, then the
/// d<column>/d<path> columns, as results.csv of `flexmbd run --sensitivity`; the summary
/// has the "sensitivities" gradients.
RunOutput runSceneWithSensitivities(const std::string& text, const std::string& source,
                                    const std::vector<std::string>& paths, bool errorControl, bool progress) {
  Scene scene = parseSceneText(text, source);
  scene.solver.progress = progress;
  checkSolverSettings(scene.solver);
  const SensitivityScenes sensitivities = buildSensitivityScenes(text, source, scene, paths);
  RunOutput out;
  out.columns = resultColumns(scene);
  SensitivitySummary gradients(out.columns, sensitivities.parameters);
  const std::vector<std::string> added = sensitivityColumns(out.columns, sensitivities.parameters);
  SpatialJointOutputs joints(scene.system);
  std::vector<double> row;
  const SimulationSummary summary =
      runSensitivityScene(scene, sensitivities, errorControl, [&](const OutputSample& s, const std::vector<double>& d) {
        resultRow(scene, out.columns, s, row, joints);
        gradients.add(row, d);
        row.insert(row.end(), d.begin(), d.end());
        out.data.insert(out.data.end(), row.begin(), row.end());
        ++out.rows;
      });
  nlohmann::json json = nlohmann::json::parse(summaryJson(summary, scene));
  json["sensitivities"] = gradients.toJson(errorControl);
  out.columns.insert(out.columns.end(), added.begin(), added.end());
  out.ok = summary.ok;
  out.summary = json.dump();
  return out;
}

/// The run of the scene `text` with the gradients of the integral outputs `specs`
/// ("KIND:COLUMN") with respect to `paths` by the adjoint method (results/adjoint_results.hpp):
/// the table of a plain run; the summary's "sensitivities" has the values and gradients, as
/// `flexmbd run --adjoint`. A failed backward integration fails the run (rows kept).
RunOutput runSceneWithAdjoint(const std::string& text, const std::string& source, const std::vector<std::string>& paths,
                              const std::vector<std::string>& specs, bool progress) {
  Scene scene = parseSceneText(text, source);
  scene.solver.progress = progress;
  checkSolverSettings(scene.solver);
  const SensitivityScenes sensitivities = buildSensitivityScenes(text, source, scene, paths);
  RunOutput out;
  out.columns = resultColumns(scene);
  SpatialJointOutputs joints(scene.system);
  std::vector<double> row;
  const AdjointSummary adjoint = runAdjointScene(scene, sensitivities, specs, [&](const OutputSample& s) {
    resultRow(scene, out.columns, s, row, joints);
    out.data.insert(out.data.end(), row.begin(), row.end());
    ++out.rows;
  });
  SimulationSummary summary = adjoint.run;
  if (summary.ok && !adjoint.backwardOk) {
    summary.ok = false;
    summary.message = "the adjoint (backward) integration failed: " + adjoint.backwardMessage;
  }
  nlohmann::json json = nlohmann::json::parse(summaryJson(summary, scene));
  json["sensitivities"] = adjointJson(adjoint, sensitivities);
  out.ok = summary.ok;
  out.summary = json.dump();
  return out;
}

py::array_t<double> table(const RunOutput& r) {
  const py::ssize_t cols = static_cast<py::ssize_t>(r.columns.size());
  py::array_t<double> a({static_cast<py::ssize_t>(r.rows), cols});
  if (!r.data.empty()) std::memcpy(a.mutable_data(), r.data.data(), r.data.size() * sizeof(double));
  return a;
}

// ----- errors: the C++ types, the same messages ------------------------------------
/// InputError and ModelError as Python exceptions, and their translator.
void bindErrors(py::module_& m) {
  static py::exception<InputError> inputError(m, "InputError", PyExc_ValueError);
  static py::exception<ModelError> modelError(m, "ModelError", inputError.ptr());
  inputError.attr("__doc__") =
      "Invalid input (a scene key, an argument, a model that cannot be built): the engine's one-line message "
      "naming its location. A ValueError.";
  modelError.attr("__doc__") =
      "A model the engine refuses as a whole (redundant or inconsistent constraints, masses too far apart): "
      "an InputError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ModelError& e) {
      modelError(e.what());
    } catch (const InputError& e) {
      inputError(e.what());
    }
  });
}

// ----- indices, states, properties -----------------------------------------------------
/// BodyIndex, ConstraintIndex, ForceIndex, GROUND, FrameState2d and RigidBodyProperties.
void bindIndicesStatesAndProperties(py::module_& m) {
  py::class_<BodyIndex>(m, "BodyIndex", "The index of a body in its System (GROUND is body 0)")
      .def_readonly("value", &BodyIndex::value, "the index as an int")
      .def("__repr__", [](const BodyIndex& b) { return "BodyIndex(" + std::to_string(b.value) + ")"; });
  py::class_<ConstraintIndex>(m, "ConstraintIndex", "The index of a joint or driver in its System")
      .def_readonly("value", &ConstraintIndex::value, "the index as an int");
  py::class_<ForceIndex>(m, "ForceIndex", "The index of a force element in its System")
      .def_readonly("value", &ForceIndex::value, "the index as an int");
  m.attr("GROUND") = kGround;

  py::class_<FrameState2d>(m, "FrameState2d", "The state of a planar body frame (initial values of a body)")
      .def(py::init([](const Vec2& position, double angle, const Vec2& velocity, double angularVelocity) {
             return FrameState2d{position, angle, velocity, angularVelocity};
           }),
           py::arg("position") = Vec2::Zero(), py::arg("angle") = 0.0, py::arg("velocity") = Vec2::Zero(),
           py::arg("angular_velocity") = 0.0,
           "Position (m) and velocity (m/s) of the frame origin, angle (rad) and angular velocity (rad/s)")
      .def_readwrite("position", &FrameState2d::position, "origin of the frame (x, y), m")
      .def_readwrite("angle", &FrameState2d::angle, "rad")
      .def_readwrite("velocity", &FrameState2d::velocity, "velocity of the origin (m/s)")
      .def_readwrite("angular_velocity", &FrameState2d::angularVelocity, "rad/s");
  py::class_<RigidBodyProperties>(m, "RigidBodyProperties", "Mass and inertia of a planar rigid body (add_rigid_body)")
      .def(py::init([](double mass, double inertia, const Vec2& com) { return RigidBodyProperties{mass, inertia, com}; }),
           py::arg("mass"), py::arg("inertia"), py::arg("com") = Vec2::Zero(),
           "Mass (kg), rotational inertia about the centre of mass (kg m^2), centre of mass in body axes (m)")
      .def_readwrite("mass", &RigidBodyProperties::mass, "kg")
      .def_readwrite("inertia", &RigidBodyProperties::inertia, "about the centre of mass (kg m^2)")
      .def_readwrite("com", &RigidBodyProperties::com, "centre of mass, body axes (m)");
}

// ----- time laws (core/time_law.hpp) ----------------------------------------------------
// pybind11 holders cannot be shared_ptr<const T>: laws are held as shared_ptr<TimeLaw>
// (Law) and handed to the engine as TimeLawPtr (immutable there).
/// TimeLaw and the *_law functions.
void bindTimeLaws(py::module_& m) {
  py::class_<TimeLaw, Law>(m, "TimeLaw", "A function of time f(t) with its derivatives, for drivers and loads (the *_law functions)")
      .def("__call__", [](const TimeLaw& law, double t) {
        const LawValue v = law.evaluate(t);
        return py::make_tuple(v.f, v.df, v.ddf);
      }, "(f, f', f'') at t")
      .def_property_readonly("type_name", &TimeLaw::typeName, "the scene format's law type (\"constant\", ...)");
  m.def("constant_law", [](double v) { return mutableLaw(makeConstantLaw(v)); }, py::arg("value"), "f(t) = value");
  m.def("constant_speed_law", [](double w, double a0) { return mutableLaw(makeConstantSpeedLaw(w, a0)); },
        py::arg("speed"), py::arg("initial") = 0.0, "f(t) = initial + speed t");
  m.def("polynomial_law", [](std::vector<double> c) { return mutableLaw(makePolynomialLaw(std::move(c))); },
        py::arg("coefficients"), "f(t) = c0 + c1 t + c2 t^2 + ... of the coefficients [c0, c1, ...]");
  m.def("harmonic_law",
        [](double a, double w, double phase, double offset) { return mutableLaw(makeHarmonicLaw(a, w, phase, offset)); },
        py::arg("amplitude"), py::arg("omega"), py::arg("phase") = 0.0, py::arg("offset") = 0.0,
        "f(t) = offset + amplitude sin(omega t + phase)");
  m.def("spin_up_law", [](double w, double ramp, double a0) { return mutableLaw(makeSpinUpLaw(w, ramp, a0)); },
        py::arg("speed"), py::arg("ramp_time"), py::arg("initial") = 0.0,
        "An angle whose rate rises smoothly from 0 to speed over ramp_time, then constant");
  m.def("tabulated_law",
        [](std::vector<double> t, std::vector<double> v) { return mutableLaw(makeTabulatedLaw(std::move(t), std::move(v))); },
        py::arg("times"), py::arg("values"),
        "A natural cubic spline through (times, values), times increasing; linear beyond the table");
}

// ----- user functions (core/user_function.hpp; python/user_functions.hpp) ---------------
/// user_law, _time_law_calls, SpringLaw and spring_law.
void bindUserFunctions(py::module_& m) {
  m.def(
      "user_law",
      [](const py::object& f, const py::object& df, const py::object& ddf) {
        if (!isUserCallable(f)) badArgument("user_law", "f", "a callable f(t)", f);
        if (!df.is_none() && !isUserCallable(df)) badArgument("user_law", "derivative", "a callable f'(t) or None", df);
        if (!ddf.is_none() && !isUserCallable(ddf)) {
          badArgument("user_law", "second_derivative", "a callable f''(t) or None", ddf);
        }
        return pythonTimeLaw(f, df, ddf);
      },
      py::arg("f"), py::arg("derivative") = py::none(), py::arg("second_derivative") = py::none(),
      "A time law f(t) given by a Python callable (drivers, loads): f' and f'' from derivative(t) and "
      "second_derivative(t) if given, else by central differences (docs/python.md, User functions)");
  m.def(
      "_time_law_calls",
      [](const Law& law, long calls) {
        // benchmarks/bench_user_functions.py: `calls` evaluations of f(t) from C++ with the GIL
        // released, as in a run (a Python law takes the GIL for each): seconds taken
        if (!law || calls < 1) throw InputError("_time_law_calls: a time law and calls >= 1 expected");
        double sum = 0.0;
        std::chrono::steady_clock::time_point start;
        double seconds = 0.0;
        {
          py::gil_scoped_release release;
          start = std::chrono::steady_clock::now();
          for (long i = 0; i < calls; ++i) sum += law->value(1e-7 * static_cast<double>(i));
          seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        return py::make_tuple(seconds, sum);
      },
      py::arg("law"), py::arg("calls"), "(seconds, sum of the values) of `calls` evaluations without the GIL");
  py::class_<SpringLaw, std::shared_ptr<SpringLaw>>(m, "SpringLaw",
                                                     "A spring-damper law f(t, x, xdot) given by a callable "
                                                     "(flexmbd.spring_law), with its derivatives")
      .def(
          "__call__",
          [](const SpringLaw& law, double t, double x, double xdot) {
            const SpringLawValue v = law.evaluate(t, x, xdot, true);
            return py::make_tuple(v.f, v.dfdx, v.dfdxdot);
          },
          py::arg("t"), py::arg("x"), py::arg("xdot"), "(f, df/dx, df/dxdot) at (t, x, xdot)")
      .def_property_readonly("has_user_derivative", &SpringLaw::hasUserDerivative,
                             "True if the user gave (df/dx, df/dxdot); False: central differences");
  m.def(
      "spring_law",
      [](const py::object& f, const py::object& derivative) {
        if (!isUserCallable(f)) badArgument("spring_law", "f", "a callable f(t, x, xdot)", f);
        if (!derivative.is_none() && !isUserCallable(derivative)) {
          badArgument("spring_law", "derivative", "a callable (t, x, xdot) -> (df/dx, df/dxdot) or None", derivative);
        }
        return pythonSpringLaw(f, derivative);
      },
      py::arg("f"), py::arg("derivative") = py::none(),
      "A spring-damper law f(t, x, xdot) (x: length or joint angle) given by a Python callable, in place of "
      "k (x - x0) + c xdot; derivative(t, x, xdot) -> (df/dx, df/dxdot), else central differences");
}

// ----- flexible beams (bodies/ffr_beam_model.hpp) --------------------------------------
/// Planar beam sections, meshes, options and models.
void bindFlexibleBeams(py::module_& m) {
  py::class_<BeamSection>(m, "BeamSection", "Cross-section and material of a planar beam")
      .def(py::init([](double area, double inertia, double E, double rho, double damping) {
             BeamSection s;
             s.area = area;
             s.inertia = inertia;
             s.youngsModulus = E;
             s.density = rho;
             s.damping = damping;
             return s;
           }),
           py::arg("area"), py::arg("inertia"), py::arg("youngs_modulus"), py::arg("density"), py::arg("damping") = 0.0,
           "Area A (m^2), second moment of area I (m^4), E (Pa), density (kg/m^3), damping beta (s)")
      .def_readwrite("area", &BeamSection::area, "A (m^2)")
      .def_readwrite("inertia", &BeamSection::inertia, "second moment of area I (m^4)")
      .def_readwrite("youngs_modulus", &BeamSection::youngsModulus, "Young's modulus E (Pa)")
      .def_readwrite("density", &BeamSection::density, "rho (kg/m^3)")
      .def_readwrite("damping", &BeamSection::damping, "stiffness-proportional damping beta (s): D = beta K");
  m.def(
      "rectangular_section",
      [](double width, double height, double E, double rho, double damping) {
        BeamSection s = rectangularSection(width, height, E, rho);
        s.damping = damping;
        return s;
      },
      py::arg("width"), py::arg("height"), py::arg("youngs_modulus"), py::arg("density"), py::arg("damping") = 0.0,
      "A rectangular width x height section (bending about the axis parallel to the width), m, Pa, kg/m^3");
  py::class_<BeamMesh2d>(m, "BeamMesh2d", "A planar beam mesh: nodes (body frame) and 2-node elements with their sections")
      .def(py::init([](const std::vector<Vec2>& nodes, const std::vector<std::pair<int, int>>& elements,
                       const BeamSection& section) {
             BeamMesh2d mesh;
             mesh.nodes = nodes;
             for (const auto& [a, b] : elements) mesh.elements.push_back({a, b, section});
             return mesh;
           }),
           py::arg("nodes"), py::arg("elements"), py::arg("section"),
           "nodes [[x, y], ...] (body frame), elements [(i, j), ...] of one section")
      .def_static("straight", &BeamMesh2d::straight, py::arg("length"), py::arg("elements"), py::arg("section"),
                  py::arg("origin") = Vec2::Zero(), "A straight beam of equal elements along the body x axis from origin")
      .def_readonly("nodes", &BeamMesh2d::nodes, "the nodes' positions (body frame, m)");
  py::enum_<ReferenceConditions::Type>(m, "Reference",
                                          "Reference conditions of a planar beam's body frame (default PINNED_PINNED)")
      .value("PINNED_PINNED", ReferenceConditions::Type::PinnedPinned)
      .value("CLAMPED", ReferenceConditions::Type::Clamped)
      .value("FREE_FREE", ReferenceConditions::Type::FreeFree);
  py::enum_<ModalReduction>(m, "ModalReduction", "How a beam model's modes are chosen: normal modes or Craig-Bampton")
      .value("NORMAL", ModalReduction::Normal)
      .value("CRAIG_BAMPTON", ModalReduction::CraigBampton);
  py::class_<FfrBeamOptions>(m, "FfrBeamOptions",
                              "Options of a planar beam model: reference conditions, modes kept, stiffening")
      .def(py::init([](ReferenceConditions::Type type, int nodeA, int nodeB, int modes, std::vector<int> modeSet,
                       bool stiffening, ModalReduction reduction, std::vector<int> interfaceNodes, bool inertiaModes) {
             FfrBeamOptions o;
             o.reference.type = type;
             o.reference.nodeA = nodeA;
             o.reference.nodeB = nodeB;
             o.modes = modes;
             o.modeSet = std::move(modeSet);
             o.geometricStiffening = stiffening;
             o.reduction = reduction;
             o.interfaceNodes = std::move(interfaceNodes);
             o.inertiaModes = inertiaModes;
             return o;
           }),
           py::arg("reference") = ReferenceConditions::Type::PinnedPinned, py::arg("node_a") = 0,
           py::arg("node_b") = -1, py::arg("modes") = 0, py::arg("mode_set") = std::vector<int>{},
           py::arg("geometric_stiffening") = false, py::arg("reduction") = ModalReduction::Normal,
           py::arg("interface_nodes") = std::vector<int>{}, py::arg("inertia_modes") = false,
           "reference conditions (pinned-pinned between node_a and node_b = last by default), modes (0: nodal), "
           "mode_set, geometric stiffening, modal reduction (normal or Craig-Bampton with interface_nodes), "
           "inertia modes");
  py::class_<FfrBeamModel, std::shared_ptr<FfrBeamModel>>(
      m, "FfrBeamModel", "A planar beam mesh as a floating-frame body model (add_flexible_body)")
      .def(py::init([](BeamMesh2d mesh, const FfrBeamOptions& o, const std::string& owner) {
             return std::make_shared<FfrBeamModel>(std::move(mesh), o, owner);
           }),
           py::arg("mesh"), py::arg("options"), py::arg("owner") = "beam model",
           "The model of the mesh under the options; owner names it in messages")
      .def("natural_frequencies", &FfrBeamModel::naturalFrequencies, "rad/s, ascending (frame held fixed)")
      .def_property_readonly("num_elastic", &FfrBeamModel::numElastic, "number of elastic coordinates nf");
}

/// The planar builders as methods of System: bodies, joints, drivers, forces.
void bindPlanarBuilders(py::class_<System>& system) {
  system
      .def(
          "add_rigid_body",
          [](System& s, const std::string& name, const RigidBodyProperties& p, const FrameState2d& init) {
            return addRigidBody(s, name, p, init);
          },
          py::arg("name"), py::arg("properties"), py::arg("initial") = FrameState2d{},
          "A planar rigid body (RigidBodyProperties, FrameState2d): its BodyIndex")
      .def(
          "add_flexible_body",
          [](System& s, const std::string& name, std::shared_ptr<FfrBeamModel> model, const FrameState2d& init,
             std::optional<VecX> qf, std::optional<VecX> qfDot) {
            auto b = std::make_unique<FfrBody2d>(name, std::shared_ptr<const FfrBeamModel>(model), init);
            if (qf || qfDot) {
              const int nf = b->numElastic();
              b->setInitialElasticState(qf ? *qf : VecX::Zero(nf), qfDot ? *qfDot : VecX::Zero(nf));
            }
            return s.addBody(std::move(b));
          },
          py::arg("name"), py::arg("model"), py::arg("initial") = FrameState2d{},
          py::arg("elastic_coordinates") = py::none(), py::arg("elastic_velocities") = py::none(),
          "A planar FFR body of a beam model (FfrBeamModel), with its initial frame state and elastic "
          "coordinates and rates (None: zero): its BodyIndex")
      .def(
          "add_revolute_joint",
          [](System& s, const std::string& name, py::object bi, const Vec2& pi, py::object bj, const Vec2& pj) {
            return addRevoluteJoint(s, name, body(s, bi), pi, body(s, bj), pj);
          },
          py::arg("name"), py::arg("body_i"), py::arg("point_i"), py::arg("body_j"), py::arg("point_j"),
          "A planar revolute joint: point_i of body_i coincides with point_j of body_j (body axes)")
      .def(
          "add_prismatic_joint",
          [](System& s, const std::string& name, py::object bi, const Vec2& pi, py::object bj, const Vec2& pj,
             const Vec2& axis) { return addPrismaticJoint(s, name, body(s, bi), pi, body(s, bj), pj, axis); },
          py::arg("name"), py::arg("body_i"), py::arg("point_i"), py::arg("body_j"), py::arg("point_j"),
          py::arg("axis"),
          "A planar prismatic joint: point_j of body_j slides along axis (body_i axes) through point_i")
      .def(
          "add_fixed_joint",
          [](System& s, const std::string& name, py::object bi, const Vec2& pi, py::object bj, const Vec2& pj) {
            return addFixedJoint(s, name, body(s, bi), pi, body(s, bj), pj);
          },
          py::arg("name"), py::arg("body_i"), py::arg("point_i"), py::arg("body_j"), py::arg("point_j"),
          "A planar fixed joint: the points coincide and the relative angle keeps its initial value")
      .def(
          "add_body_coordinate_driver",
          [](System& s, const std::string& name, py::object b, const std::string& coordinate, const py::object& law) {
            Law l = lawArg(law, "add_body_coordinate_driver", "law");
            if (!l) badArgument("add_body_coordinate_driver", "law", "a time law or a callable f(t)", law);
            return addBodyCoordinateDriver(s, name, body(s, b), coordinate, std::move(l));
          },
          py::arg("name"), py::arg("body"), py::arg("coordinate"), py::arg("law"),
          "Drives one coordinate of a body (\"x\", \"y\", \"theta\") by a time law")
      .def(
          "add_joint_driver",
          [](System& s, const std::string& name, py::object j, const py::object& law) {
            Law l = lawArg(law, "add_joint_driver", "law");
            if (!l) badArgument("add_joint_driver", "law", "a time law or a callable f(t)", law);
            return addJointDriver(s, name, joint(s, j), std::move(l));
          },
          py::arg("name"), py::arg("joint"), py::arg("law"),
          "Drives a planar joint (revolute: its relative angle, prismatic: its displacement) by a time law")
      .def(
          "add_spring_damper",
          [](System& s, const std::string& name, py::object bi, const Vec2& pi, py::object bj, const Vec2& pj,
             const py::object& k, const py::object& c, const py::object& l0, const py::object& law) {
            constexpr const char* fn = "add_spring_damper";
            const SpringLawPtr userLaw = springLawArg(law, fn);
            requireLinearOrLaw(userLaw, k, c, fn);
            if (userLaw) return addSpringDamper(s, name, body(s, bi), pi, body(s, bj), pj, 0.0, 0.0, 0.0, userLaw);
            return addSpringDamper(s, name, body(s, bi), pi, body(s, bj), pj, numberArg(k, fn, "stiffness"),
                                   numberArg(c, fn, "damping"), numberArg(l0, fn, "free_length"));
          },
          py::arg("name"), py::arg("body_i"), py::arg("point_i"), py::arg("body_j"), py::arg("point_j"),
          py::arg("stiffness") = py::none(), py::arg("damping") = py::none(), py::arg("free_length") = py::none(),
          py::arg("law") = py::none(),
          "A spring-damper between two body points: stiffness (N/m) (l - free_length) + damping (N s/m) ldot, or law: a user law f(t, l, ldot) (flexmbd.spring_law or a "
          "callable)")
      .def(
          "add_rotational_spring_damper",
          [](System& s, const std::string& name, py::object j, const py::object& k, const py::object& c,
             const py::object& a0, const py::object& law) {
            constexpr const char* fn = "add_rotational_spring_damper";
            const SpringLawPtr userLaw = springLawArg(law, fn);
            requireLinearOrLaw(userLaw, k, c, fn);
            const double freeAngle = a0.is_none() && userLaw ? 0.0 : numberArg(a0, fn, "free_angle");
            if (userLaw) return addRotationalSpringDamper(s, name, joint(s, j), 0.0, 0.0, freeAngle, userLaw);
            return addRotationalSpringDamper(s, name, joint(s, j), numberArg(k, fn, "stiffness"),
                                             numberArg(c, fn, "damping"), freeAngle);
          },
          py::arg("name"), py::arg("joint"), py::arg("stiffness") = py::none(), py::arg("damping") = py::none(),
          py::arg("free_angle") = py::none(), py::arg("law") = py::none(),
          "A torsional spring-damper on a planar revolute joint: stiffness (N m/rad) (phi - free_angle) + damping phi_dot, or law: a user torque law tau(t, phi, phi_dot) "
          "(flexmbd.spring_law or a callable)")
      .def(
          "add_applied_load",
          [](System& s, const std::string& name, py::object b, const Vec2& point, const py::object& fx,
             const py::object& fy, const py::object& torque) {
            constexpr const char* fn = "add_applied_load";
            return addAppliedLoad(s, name, body(s, b), point, lawArg(fx, fn, "force_x"), lawArg(fy, fn, "force_y"),
                                  lawArg(torque, fn, "torque"));
          },
          py::arg("name"), py::arg("body"), py::arg("point"), py::arg("force_x") = py::none(),
          py::arg("force_y") = py::none(), py::arg("torque") = py::none(),
          "Force and torque laws (time laws or callables f(t)), world axes");
}

/// set_gravity, find_body, finalize and the numbering of the coordinates.
void bindSystemQueries(py::class_<System>& system) {
  system
      .def(
          "set_gravity",
          [](System& s, const py::object& g) {
            if (!py::isinstance<py::str>(g) && !g.is_none()) {
              try {
                s.setGravity(g.cast<Vec2>());  // planar
                return;
              } catch (const py::cast_error&) {
              }
            }
            s.setGravity(argumentAs<Vec3>(g, "set_gravity", "gravity", "2 numbers (planar) or 3 numbers (spatial)"));
          },
          py::arg("gravity"), "(gx, gy) for a planar model, (gx, gy, gz) for a spatial one (world axes)")
      .def("find_body", &System::findBody, py::arg("name"), "The BodyIndex of a body by name (InputError if none)")
      .def("finalize", &System::finalize, "Freezes the model: numbers the coordinates and checks the attachments")
      .def_property_readonly("is_finalized", &System::isFinalized, "True after finalize()")
      .def_property_readonly("num_bodies", &System::numBodies, "number of bodies, the ground included")
      .def_property_readonly("num_coordinates", [](const System& s) { return s.numCoordinates(); },
                             "number of coordinates nq (after finalize())")
      .def_property_readonly("num_velocities", [](const System& s) { return s.numVelocities(); },
                             "number of velocities nv (after finalize())")
      .def("coordinate_names", &System::coordinateNames, "\"crank.x\", ... for every coordinate, in order")
      .def("initial_coordinates", &System::initialCoordinates, "The coordinates given at construction (nq)")
      .def(
          "coordinate_offset",
          [](const System& s, py::object b) {
            const BodyIndex i = body(s, b, "coordinate_offset");
            if (i == kGround) {
              throw InputError("coordinate_offset: the ground has no coordinates (it does not move; expected a body "
                               "of the model)");
            }
            if (!s.isFinalized()) {
              throw InputError("coordinate_offset: the coordinates are numbered by finalize(): call it first");
            }
            return s.coordinateOffset(i);
          },
          py::arg("body"), "index of the body's first coordinate in the system's coordinates (after finalize())");
}

// ----- solver settings (simulation/simulation.hpp) ------------------------------------
/// SolverSettings.
void bindSolverSettings(py::module_& m) {
  py::class_<SolverSettings>(m, "SolverSettings",
                              "How a run integrates: the scene's \"solver\" object (docs/scene-format.md, \"Solver\")")
      .def(py::init<>(), "The defaults of a scene that omits every solver key")
      .def_readwrite("rtol", &SolverSettings::rtol, "relative tolerance")
      .def_readwrite("atol", &SolverSettings::atol, "absolute tolerance of frame positions (m)")
      // class tolerances: None = the default relative to atol and the model's sizes
      .def_readwrite("atol_angle", &SolverSettings::atolAngle, "absolute tolerance of angles (rad); None: atol / L")
      .def_readwrite("atol_elastic", &SolverSettings::atolElastic, "absolute tolerance of elastic coordinates; None: atol")
      .def_readwrite("atol_velocity", &SolverSettings::atolVelocity, "absolute tolerance of velocities (m/s); None: atol / (1 s)")
      .def(
          "override_tolerances",
          [](SolverSettings& s, std::optional<double> rtol, std::optional<double> atol) {
            overrideTolerances(s, rtol, atol);
          },
          py::arg("rtol") = py::none(), py::arg("atol") = py::none(),
          "rtol and/or atol as the command line's --rtol/--atol: every absolute tolerance set is scaled by "
          "atol / self.atol (rtol alone: rtol / self.rtol), so the classes keep their ratios")
      .def_readwrite("t_start", &SolverSettings::tStart, "start time (s)")
      .def_readwrite("t_end", &SolverSettings::tEnd, "end time (s)")
      .def_readwrite("output_step", &SolverSettings::outputStep, "output interval (s)")
      .def_readwrite("max_step", &SolverSettings::maxStepSize, "largest step (s); 0: no limit")
      .def_readwrite("max_steps", &SolverSettings::maxSteps, "most steps per output interval")
      .def_readwrite("max_total_steps", &SolverSettings::maxTotalSteps, "most steps of the whole run")
      .def_readwrite("max_order", &SolverSettings::maxOrder, "highest BDF order (1..5)")
      .def_readwrite("initial_step", &SolverSettings::initialStepSize, "first step tried (s); 0: the integrator's estimate")
      .def_readwrite("fd_jacobian", &SolverSettings::finiteDifferenceJacobian, "iteration matrix by finite differences (dense IDA only)")
      .def_readwrite("cross_singular", &SolverSettings::crossSingular, "cross singular positions with the augmented Lagrangian integrator")
      .def_property(
          "formulation", [](const SolverSettings& s) { return toString(s.formulation); },
          [](SolverSettings& s, const std::string& f) { s.formulation = parseFormulation(f); },
          "the DAE formulation by name (docs/formulations.md)")
      .def_property(
          "redundant_constraints", [](const SolverSettings& s) { return toString(s.redundantConstraints); },
          [](SolverSettings& s, const std::string& r) { s.redundantConstraints = parseRedundantConstraints(r); },
          "\"resolve\" (release dependent constraint equations) or \"refuse\"")
      .def_property(
          "integrator", [](const SolverSettings& s) { return toString(s.integrator); },
          [](SolverSettings& s, const std::string& i) { s.integrator = parseIntegrator(i); },
          "the integrator by name (\"auto\": chosen from the model)")
      .def("validate", &SolverSettings::validate, "InputError naming the setting that is out of range");
}

// ----- scenes and runs -----------------------------------------------------------------
/// The compiled Scene: its system, solver, outputs, modes and run.
void bindScene(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene", "The compiled scene behind flexmbd.Scene (use that class)")
      .def(py::init([](const std::string& name) {
             auto s = std::make_shared<Scene>();
             s->name = name;
             return s;
           }),
           py::arg("name") = "", "An empty scene of that name")
      .def_readwrite("name", &Scene::name, "the scene's name")
      .def_property_readonly("system", [](Scene& s) -> System& { return s.system; }, py::return_value_policy::reference_internal,
                             "the System")
      .def_property(
          "solver", [](Scene& s) -> SolverSettings& { return s.solver; },
          [](Scene& s, const SolverSettings& v) { s.solver = v; }, py::return_value_policy::reference_internal,
          "the SolverSettings")
      .def(
          "add_output_json",
          [](Scene& s, const std::string& text, bool spatial) {
            const nlohmann::json j = nlohmann::json::parse(text);
            const std::string where = "outputs[" + std::to_string(s.outputs.size()) + "]";
            s.outputs.push_back(parseOutputRequest(j, where, s.system, s.outputs, spatial, s.feBodies));
          },
          py::arg("json"), py::arg("spatial") = false, "Adds an output object of the scene format, given as JSON text")
      .def_property_readonly("output_columns", [](const Scene& s) {
        std::vector<std::string> c;
        for (const auto& o : s.outputs) {
          const auto n = o.columnNames();
          c.insert(c.end(), n.begin(), n.end());
        }
        return c;
      }, "the columns the outputs add to the results")
      .def(
          "modes",
          [](Scene& s, int count, bool steady, std::optional<double> at) {
            if (at && steady) {
              throw InputError("modes: at and steady cannot be combined (steady solves for the state at t_start)");
            }
            std::vector<Mode> modes;
            {
              py::gil_scoped_release release;
              if (!s.system.isFinalized()) s.system.finalize();
              const System& sys = s.system;
              const double t0 = s.solver.tStart;
              // at: the state a run reaches at that time (flexmbd modes --at); otherwise the
              // consistent state at t_start, the static equilibrium if it is at rest
              const ReleasedEquations released{s.solver.redundantConstraints == RedundantConstraints::Resolve, {}};
              const ReferenceState state =
                  at ? referenceStateByRun(sys, s.solver, *at)
                  : steady ? solveSteadyMotion(sys, t0, sys.initialCoordinates(), sys.initialVelocities())
                           : referenceStateAt(sys, t0, sys.initialCoordinates(), sys.initialVelocities(),
                                              released);
              ModesOptions o;
              o.count = count;
              modes = modesAbout(sys, state, o);
            }
            py::list out;
            for (const Mode& m : modes) {
              py::dict d;
              d["eigenvalue"] = m.eigenvalue;
              d["omega"] = m.omega;
              d["frequency_hz"] = m.frequencyHz;
              d["damping_ratio"] = m.dampingRatio;
              d["shape"] = Eigen::VectorXcd(m.shape);
              out.append(d);
            }
            return out;
          },
          py::arg("count") = 10, py::arg("steady") = false, py::arg("at") = py::none(),
          "Modes of the model linearised about its consistent initial state (static equilibrium if at rest, "
          "planar or spatial), steady=True about the steady motion at its initial velocities, or at=T about "
          "the state a run reaches at time T (analysis/linearization.hpp): "
          "dicts of eigenvalue, omega (rad/s), frequency_hz, damping_ratio, shape (velocity space)")
      .def_property_readonly("velocity_names", [](Scene& s) {
        if (!s.system.isFinalized()) s.system.finalize();
        return s.system.velocityNames();
      }, "the velocities' names (finalizes the system)")
      .def(
          "_run",
          [](Scene& s, bool progress) {
            RunOutput r;
            {
              py::gil_scoped_release release;  // several runs may go on in threads
              const PythonSignalCheck ctrlC;
              r = runScene(s, progress);
            }
            PythonSignalCheck::raiseIfInterrupted();
            return py::make_tuple(r.columns, table(r), r.summary, r.ok);
          },
          py::arg("progress") = false);
}

// ----- kinematic analysis of linkages (linkage/, Doc000) -------------------------------
/// run_kinematics_text.
void bindKinematics(py::module_& m) {
  m.def(
      "run_kinematics_text",
      [](const std::string& text, const std::string& source) {
        const KinematicsScene scene = parseKinematicsSceneText(text, source);
        std::vector<std::string> columns = kinematicsColumns(scene.linkage);
        std::vector<double> data, row;
        long rows = 0;
        KinematicSummary sum;
        try {
          py::gil_scoped_release release;
          const PythonSignalCheck ctrlC;
          sum = analyzeKinematics(scene.linkage, scene.settings, [&](const KinematicState& st) {
            kinematicsRow(scene.linkage, st, row);
            data.insert(data.end(), row.begin(), row.end());
            ++rows;
          });
        } catch (const RunInterrupted&) {
          PythonSignalCheck::raiseIfInterrupted();
          throw;
        }
        RunOutput r;
        r.columns = std::move(columns);
        r.data = std::move(data);
        r.rows = rows;
        py::dict summary;
        summary["status"] = sum.ok ? "ok" : "failed";
        summary["message"] = sum.message;
        summary["scene"] = scene.name;
        summary["steps_completed"] = sum.stepsCompleted;
        summary["alpha_reached"] = sum.alphaReached;
        summary["assembly_iterations"] = sum.assemblyIterations;
        summary["mean_iterations"] = sum.meanIterations;
        summary["max_residual"] = sum.maxResidual;
        summary["wall_seconds"] = sum.wallSeconds;
        if (sum.singular) {
          py::dict sp;
          sp["alpha"] = sum.singular->alpha;
          sp["alpha_regular"] = sum.singular->alphaRegular;
          sp["kind"] = sum.singular->kind;
          sp["nodes"] = sum.singular->nodes;
          sp["links"] = sum.singular->links;
          summary["singular"] = sp;
        } else {
          summary["singular"] = py::none();
        }
        return py::make_tuple(r.columns, table(r), summary);
      },
      py::arg("text"), py::arg("source") = "<scene>",
      "A kinematics scene (docs/kinematics.md) analysed: (columns, table, summary dict)");
}

// ----- tensegrity structures (tensegrity/, Doc001) --------------------------------------
/// run_tensegrity_text.
void bindTensegrity(py::module_& m) {
  m.def(
      "run_tensegrity_text",
      [](const std::string& text, const std::string& source) {
        nlohmann::json j;
        try {
          j = nlohmann::json::parse(text);
        } catch (const nlohmann::json::exception& e) {
          throw InputError(source + ": not valid JSON: " + e.what());
        }
        TensegrityScene scene = jsonread::located(source, [&] { return parseTensegrityScene(j); });
        RunOutput r;
        r.columns = tensegrityColumns(*scene.structure);
        std::vector<double> row;
        std::vector<TensegrityEvent> events;
        TensegrityRunSummary sum;
        {
          py::gil_scoped_release release;
          const PythonSignalCheck ctrlC;
          const TensegrityObserver observer{[&](const TensegritySample& smp) {
                                              tensegrityRow(*scene.structure, smp, row);
                                              r.data.insert(r.data.end(), row.begin(), row.end());
                                              ++r.rows;
                                            },
                                            [&](const TensegrityEvent& e) { events.push_back(e); }};
          try {
            sum = scene.method == TensegrityScene::Method::TimeStepping
                      ? TensegrityTimeStepper(*scene.structure, scene.timeStepping).run(observer)
                      : MasslessCableIntegrator(*scene.structure, scene.massless).run(observer);
          } catch (const InputError&) {
            throw;
          } catch (const std::exception& e) {  // a non-finite value, ...: the rows so far are kept
            sum.ok = false;
            sum.message = e.what();
            sum.tReached = r.rows > 0 ? r.data[(r.rows - 1) * r.columns.size()] : 0.0;
          }
        }
        PythonSignalCheck::raiseIfInterrupted();
        py::dict summary;
        summary["status"] = sum.ok ? "ok" : "failed";
        summary["message"] = sum.message;
        summary["scene"] = scene.name;
        summary["method"] = sum.method;
        summary["t_reached"] = sum.tReached;
        summary["steps"] = sum.steps;
        summary["cpu_seconds"] = sum.cpuSeconds;
        summary["snaps"] = sum.snaps;
        summary["slack_transitions"] = sum.slackTransitions;
        summary["taut_transitions"] = sum.tautTransitions;
        summary["contacts"] = sum.contacts;
        summary["energy_start"] = sum.energyStart;
        summary["energy_end"] = sum.energyEnd;
        py::list ev;
        for (const TensegrityEvent& e : events) {
          py::dict d;
          d["t"] = e.t;
          d["step"] = e.step;
          d["type"] = toString(e.type);
          d["member"] = e.member;
          d["other"] = e.other;
          d["impulse"] = e.impulse;
          d["elongation_rate"] = e.elongationRate;
          d["energy_change"] = e.energyChange;
          d["point"] = Vec3(e.point);
          ev.append(d);
        }
        summary["events"] = ev;
        return py::make_tuple(r.columns, table(r), summary);
      },
      py::arg("text"), py::arg("source") = "<scene>",
      "A tensegrity scene (docs/tensegrity.md) run: (columns, table, summary dict with its events)");
}

/// Scene texts: parsed, read from a file, run with sensitivities or the adjoint; scene paths.
void bindSceneTexts(py::module_& m) {
  m.def(
      "parse_scene_text",
      [](const std::string& text, const std::string& source) {
        return std::make_shared<Scene>(parseSceneText(text, source));
      },
      py::arg("text"), py::arg("source") = "<scene>",
      "A scene from its JSON text (source names it in messages): a compiled Scene (flexmbd.Scene wraps it)");
  m.def(
      "read_scene_file", [](const std::string& path) { return py::bytes(jsonread::readSceneFile(path)); },
      py::arg("path"),
      "The bytes of a scene file by the command line's rules (a regular file of at most 64 MiB; InputError "
      "naming the path otherwise)");
  m.def(
      "_run_scene_text_with_sensitivities",
      [](const std::string& text, const std::string& source, const std::vector<std::string>& paths, bool errorControl,
         bool progress) {
        RunOutput r;
        {
          py::gil_scoped_release release;
          const PythonSignalCheck ctrlC;
          r = runSceneWithSensitivities(text, source, paths, errorControl, progress);
        }
        PythonSignalCheck::raiseIfInterrupted();
        return py::make_tuple(r.columns, table(r), r.summary, r.ok);
      },
      py::arg("text"), py::arg("source"), py::arg("paths"), py::arg("error_control") = true,
      py::arg("progress") = false,
      "Runs the scene text with forward sensitivities with respect to the dotted scene paths "
      "(docs/sensitivities.md): (columns, table, summary JSON, ok), the table's columns those of a plain run "
      "then d<column>/d<path>");
  m.def(
      "_run_scene_text_with_adjoint",
      [](const std::string& text, const std::string& source, const std::vector<std::string>& paths,
         const std::vector<std::string>& specs, bool progress) {
        RunOutput r;
        {
          py::gil_scoped_release release;
          const PythonSignalCheck ctrlC;
          r = runSceneWithAdjoint(text, source, paths, specs, progress);
        }
        PythonSignalCheck::raiseIfInterrupted();
        return py::make_tuple(r.columns, table(r), r.summary, r.ok);
      },
      py::arg("text"), py::arg("source"), py::arg("paths"), py::arg("outputs"), py::arg("progress") = false,
      "Runs the scene text with the gradients of the integral outputs (KIND:COLUMN) with respect to the dotted "
      "scene paths by the adjoint method (docs/sensitivities.md): (columns, table, summary JSON, ok)");
  m.def(
      "parse_scene_path",
      [](const std::string& path) {
        py::list out;
        for (const ScenePathPart& p : parseScenePath(path, "override")) {
          if (p.isIndex) {
            out.append(py::int_(p.index));
          } else {
            out.append(py::str(p.key));
          }
        }
        return out;
      },
      py::arg("path"),
      "The keys (str) and list indices (int) of a dotted scene path 'bodies[1].section.area', parsed by the "
      "engine's one parser of the syntax (scene/scene_path.hpp); InputError \"override '<path>': ...\" otherwise");
}

}  // namespace

PYBIND11_MODULE(_flexmbd, m) {
  m.doc() = "flexmbd: flexible multibody dynamics (compiled part; use the flexmbd package)";

  bindErrors(m);
  bindIndicesStatesAndProperties(m);
  bindTimeLaws(m);
  bindUserFunctions(m);
  bindFlexibleBeams(m);

  // ----- the system and the builders (builders/planar_builders.hpp) --------------------
  py::class_<System> systemClass(
      m, "System",
      "A multibody system, planar or spatial: bodies, joints, drivers and forces are added (add_*), then "
      "finalize() freezes it. Body 0 is the ground (GROUND or \"ground\"). Bodies and joints are given by "
      "name or index.");
  bindPlanarBuilders(systemClass);
  bindSystemQueries(systemClass);
  bindSpatial(m, systemClass);
  bindComponentKinds(systemClass);

  bindSolverSettings(m);
  bindScene(m);
  bindKinematics(m);
  bindTensegrity(m);
  bindSceneTexts(m);
}
