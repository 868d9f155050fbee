"""flexmbd: flexible multibody dynamics from Python.

Scenes (the scene format of docs/scene-format.md, with any key overridden from a
dict), models built with the C++ API's objects and names, runs whose results are NumPy
arrays with column names. docs/python.md.

    import flexmbd
    scene = flexmbd.load_scene("examples/slider_crank_elastic.json",
                               overrides={"solver": {"t_end": 0.05}})
    res = scene.run()
    res["slider.x"], res.summary["steps"]
"""

import copy
import json
import math
import numbers
import os

try:  # the module's arrays (it imports NumPy when it loads): named here when it is missing
    import numpy  # noqa: F401
except ImportError as e:
    raise ImportError("flexmbd needs NumPy in this Python (Debian: python3-numpy, and a venv made with "
                      "--system-site-packages sees it; elsewhere: pip install numpy)") from e

from ._flexmbd import (  # noqa: F401  (the C++ API, re-exported)
    GROUND,
    BeamMesh2d,
    BeamMesh3d,
    BeamSection,
    BeamSection3d,
    BeamTheory,
    BodyIndex,
    ConstraintIndex,
    FeBodyData,
    FeBodyModel,
    FfrBeamModel,
    FfrBeamModel3d,
    FfrBeamOptions,
    FfrBeamOptions3d,
    FfrInvariants3d,
    FfrPoint3d,
    ForceIndex,
    FrameState2d,
    FrameState3d,
    InputError,
    JointFrame,
    ModalReduction,
    ModelError,
    Reference,
    Reference3d,
    RigidBody3dProperties,
    RigidBodyProperties,
    CompositeInertia,
    ShapePart,
    SolidShape,
    SolverSettings,
    SpatialJointType,
    SpringLaw,
    System,
    TimeLaw,
    circular_section_3d,
    composite_inertia,
    constant_law,
    constant_speed_law,
    harmonic_law,
    polynomial_law,
    rectangular_section,
    read_abaqus_fe,
    read_ansys_fe,
    read_sid,
    rectangular_section_3d,
    rotation_from_axis_angle,
    rotation_from_quaternion,
    shape_inertia,
    shape_properties,
    shape_volume,
    spin_up_law,
    spring_law,
    write_sid,
    tabulated_law,
    user_law,
    world_joint_frame,
)
from . import _flexmbd

__all__ = [
    "Scene", "Results", "SolverFailure", "InputError", "ModelError", "load_scene", "scene_from_dict",
    "apply_overrides", "read_scene_file", "run_kinematics", "run_tensegrity",
]


class SolverFailure(RuntimeError):
    """A run that stopped before t_end: the message says when and why.

    Attributes: ``time`` (the time reached), ``results`` (the Results up to then)."""

    def __init__(self, message, time, results):
        super().__init__(message)
        self.time = time
        self.results = results


class Results:
    """The results table of a run (the columns of results.csv) and its summary.

    ``data``: a NumPy array (rows x columns); ``columns``: the column names;
    ``res["slider.x"]``: one column; ``summary``: the keys of summary.json as a dict;
    ``ok``, ``message``, ``t``: status, message and the output times."""

    def __init__(self, columns, data, summary):
        self.columns = list(columns)
        self.data = data
        self.summary = summary
        self._index = {c: k for k, c in enumerate(self.columns)}

    @property
    def ok(self):
        """True if the run reached t_end (summary status "ok")."""
        return self.summary["status"] == "ok"

    @property
    def message(self):
        """The summary's message: "" or why the run stopped."""
        return self.summary["message"]

    @property
    def t(self):
        """The output times (the first column, "t"), a NumPy array."""
        return self.data[:, 0]

    def __getitem__(self, column):
        try:
            return self.data[:, self._index[column]]
        except KeyError:
            raise KeyError(f"no column {column!r} (columns: {', '.join(self.columns)})") from None

    def __contains__(self, column):
        return column in self._index

    def derivative(self, column, parameter):
        """d column / d parameter over the rows, a NumPy array: the sensitivity column
        "d<column>/d<parameter>" of a run with ``sensitivities`` (KeyError without it)."""
        return self[f"d{column}/d{parameter}"]

    def gradient(self, output):
        """{parameter: dG/dp} of the integral output ``output`` ("KIND:COLUMN") of a run
        with ``adjoint`` (KeyError without it)."""
        integrals = self.summary.get("sensitivities", {}).get("integrals", {})
        if output not in integrals:
            raise KeyError(f"no adjoint output {output!r} (outputs: {', '.join(integrals)})")
        return dict(integrals[output]["gradient"])

    def __len__(self):
        return self.data.shape[0]

    def to_pandas(self):
        """A pandas DataFrame of the table (pandas is optional: ImportError without it)."""
        import pandas  # noqa: PLC0415  (optional dependency)
        return pandas.DataFrame(self.data, columns=self.columns)

    def __repr__(self):
        return f"Results({len(self)} rows x {len(self.columns)} columns, status {self.summary['status']!r})"


class Scene:
    """A model ready to run: a system, solver settings and requested outputs.

    Made from a scene file (load_scene), a scene dict (scene_from_dict) or built in Python::

        scene = flexmbd.Scene("pendulum")
        sys = scene.system
        bar = sys.add_rigid_body("bar", flexmbd.RigidBodyProperties(mass=1, inertia=1/12, com=(0.5, 0)))
        sys.add_revolute_joint("pin", "ground", (0, 0), bar, (0, 0))
        scene.solver.t_end = 2.0
        res = scene.run()
    """

    def __init__(self, name="", _native=None, _text=None, _source=None):
        self._native = _native if _native is not None else _flexmbd.Scene(name)
        self._text = _text  # the scene JSON it was read from (sensitivities rebuild it)
        self._source = _source

    @property
    def name(self):
        """The scene's name (the scene file's "name")."""
        return self._native.name

    @property
    def system(self):
        """The System: add bodies, joints, drivers and forces to it before run()."""
        return self._native.system

    @property
    def solver(self):
        """The SolverSettings (t_end, output_step, rtol, ...), changed in place."""
        return self._native.solver

    def add_output(self, output, spatial=None):
        """An output of the scene format ({"type": "point", "name": ..., "body": ..., "point": [...]},
        "deflection" or "energy"): extra result columns. ``spatial``: the keys of a spatial
        scene (3-component points); None: spatial if the system has a spatial body."""
        if spatial is None:
            spatial = self.system.is_spatial
        self._native.add_output_json(json.dumps(output), bool(spatial))

    def modes(self, count=10, steady=False, at=None):
        """The model's lowest modes (docs/modes.md), linearised about

        - ``at=None`` (the default): its consistent initial state, the static equilibrium
          if it starts at rest (planar and spatial models);
        - ``at=T`` (a number > ``solver.t_start``): the state a run of the scene reaches at
          time T, as ``flexmbd modes --at T`` (a failed run raises RuntimeError);
        - ``steady=True`` (not with ``at``): the steady motion at its initial velocities.

        Returns a list of dicts with ``eigenvalue``, ``omega`` (rad/s), ``frequency_hz``,
        ``damping_ratio`` and ``shape`` (complex, one entry per ``velocity_names``)."""
        return self._native.modes(count, steady, None if at is None else float(at))

    @property
    def velocity_names(self):
        """The names of the system's velocities ("crank.theta_dot", ...), the order of a
        mode shape's entries; finalizes the system."""
        return self._native.velocity_names

    def run(self, progress=False, raise_on_failure=True, sensitivities=None, sensitivity_error_control=None,
            adjoint=None):
        """Runs the model (the GIL is released: runs in threads go on in parallel).

        Returns Results. A solver failure raises SolverFailure (its ``results`` hold the
        rows up to the failure) unless raise_on_failure is False; input and model errors
        raise InputError / ModelError (ValueError) with the engine's message.

        ``sensitivities``, ``adjoint``, ``sensitivity_error_control``: None takes the
        scene's "sensitivity" object (its "parameters", "adjoint", "error_control";
        docs/scene-format.md), ``[]`` none.

        ``sensitivities``: dotted scene paths ("bodies[1].mass", ...) of parameters whose
        forward sensitivities IDAS integrates with the run (docs/sensitivities.md): the
        table then also has a column "d<column>/d<path>" per column and parameter
        (``Results.derivative``) and the summary the gradients of the final and largest
        values (``summary["sensitivities"]``). Needs a scene read from a file or a dict
        (load_scene, scene_from_dict): each parameter's scene is read again a step away.

        ``adjoint``: outputs "KIND:COLUMN" (KIND "integral", "integral_square", "final" or
        "ks" as "ks:COLUMN:RHO", of a coordinate, velocity or scene output column,
        docs/sensitivities.md) whose gradients with respect to the
        ``sensitivities`` parameters the adjoint method gives instead of the derivative
        columns: one backward integration per output, whatever the number of parameters
        (``summary["sensitivities"]["integrals"][OUTPUT]`` holds "value" and "gradient";
        ``Results.gradient(OUTPUT)`` as a dict)."""
        request = json.loads(self._text).get("sensitivity", {}) if self._text is not None else {}
        if sensitivities is None:
            sensitivities = request.get("parameters", [])
        if adjoint is None:
            adjoint = request.get("adjoint", [])
        if sensitivity_error_control is None:
            sensitivity_error_control = request.get("error_control", True)
        if adjoint:
            if not sensitivities:
                raise InputError("adjoint outputs need the parameters of their gradients: sensitivities=[PATH, ...]")
            if not sensitivity_error_control:
                raise InputError("sensitivity_error_control is for the forward sensitivities, not with adjoint")
            if isinstance(adjoint, str):
                adjoint = [adjoint]
        if sensitivities:
            if self._text is None:
                raise InputError("sensitivities need a scene read from a file or a dict (load_scene, "
                                 "scene_from_dict): each parameter's scene is read again a step away")
            if isinstance(sensitivities, str):
                sensitivities = [sensitivities]
            if adjoint:
                columns, data, summary_text, ok = _flexmbd._run_scene_text_with_adjoint(
                    self._text, self._source, list(sensitivities), list(adjoint), progress)
            else:
                columns, data, summary_text, ok = _flexmbd._run_scene_text_with_sensitivities(
                    self._text, self._source, list(sensitivities), bool(sensitivity_error_control), progress)
        else:
            columns, data, summary_text, ok = self._native._run(progress)
        results = Results(columns, data, json.loads(summary_text))
        if not ok and raise_on_failure:
            s = results.summary
            time = s["t_reached"] if s["t_reached"] is not None else float("nan")
            raise SolverFailure(f"solver failure: {s['message']} (results up to t = {time:g} kept in .results)",
                                time, results)
        return results


def apply_overrides(scene_dict, overrides):
    """A copy of scene_dict with overrides applied.

    ``overrides`` maps keys to values: nested dicts merge into objects
    ({"solver": {"rtol": 1e-6}}), and a dotted path with list indices addresses any key
    ({"bodies[1].section.youngs_modulus": 1e11, "solver.t_end": 0.1}). A key that is not
    such a path, a path through a key or index that does not exist, or a value that is not
    JSON (NaN, infinities, objects other than numbers, strings, booleans, None, lists and
    dicts) raises InputError naming the key."""
    if overrides is None:
        overrides = {}
    if not isinstance(overrides, dict):
        raise InputError(f"overrides must be a dict of scene keys and values, got {type(overrides).__name__}")
    result = copy.deepcopy(scene_dict)
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise InputError(f"override {key!r}: the key must be a string (a scene key such as 'solver.t_end')")
        _set_path(result, key, _json_value(key, value, key))
    return result


def _json_value(path, value, where):
    """value as plain JSON data (tuples and NumPy arrays as lists, NumPy numbers as int and
    float), or InputError "override <path>: ..." naming where in the value it fails."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        x = float(value)
        if not math.isfinite(x):
            raise InputError(f"override {path!r}: {where} is {x!r}, not a number a scene accepts (NaN and "
                             f"infinities are not JSON numbers; expected a finite number)")
        return x
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise InputError(f"override {path!r}: {where} has the key {k!r} (expected string keys)")
            out[k] = _json_value(path, v, f"{where}.{k}")
        return out
    if hasattr(value, "tolist") and not isinstance(value, (list, tuple)):  # NumPy arrays
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_json_value(path, v, f"{where}[{k}]") for k, v in enumerate(value)]
    raise InputError(f"override {path!r}: {where} is a {type(value).__name__}, not a scene value (expected a "
                     f"number, a string, a boolean, None, a list or a dict)")


def _merge(target, value):
    if isinstance(target, dict) and isinstance(value, dict):
        for k, v in value.items():
            if k in target and isinstance(target[k], dict) and isinstance(v, dict):
                _merge(target[k], v)
            else:
                target[k] = copy.deepcopy(v)
        return target
    return copy.deepcopy(value)


def _path_parts(path):
    """The names and indices of a dotted path "bodies[1].section.area", or InputError
    (parsed by the engine, scene/scene_path.hpp: the one parser of the syntax, which
    sensitivity parameters use too)."""
    return _flexmbd.parse_scene_path(path)


def _set_path(root, path, value):
    parts = _path_parts(path)
    node = root
    for depth, part in enumerate(parts[:-1]):
        where = path if depth == len(parts) - 2 else ".".join(str(p) for p in parts[: depth + 1])
        if isinstance(part, int):
            if not isinstance(node, list) or not -len(node) <= part < len(node):
                raise InputError(f"override {path!r}: no element [{part}] at {where!r}")
            node = node[part]
        else:
            if not isinstance(node, dict):
                raise InputError(f"override {path!r}: {where!r} is not an object")
            node = node.setdefault(part, {})
    last = parts[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or not -len(node) <= last < len(node):
            raise InputError(f"override {path!r}: no element [{last}]")
        node[last] = copy.deepcopy(value)
    else:
        if not isinstance(node, dict):
            raise InputError(f"override {path!r}: the parent of {last!r} is not an object")
        node[last] = _merge(node[last], value) if last in node else copy.deepcopy(value)


def scene_from_dict(scene_dict, overrides=None, source="<scene>"):
    """A Scene from a scene-format dict (with overrides applied)."""
    text = json.dumps(apply_overrides(scene_dict, overrides))
    return Scene(_native=_flexmbd.parse_scene_text(text, source), _text=text, _source=source)


def read_scene_file(path):
    """The text of a scene file by the command line's rules (a regular file of at most
    64 MiB, UTF-8): InputError naming the path otherwise."""
    path = os.fspath(path)
    data = _flexmbd.read_scene_file(path)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"{path}: not UTF-8 text (byte {e.start + 1}); scene files are UTF-8 JSON") from None


def load_scene(path, overrides=None):
    """A Scene from a scene file, with any key overridden (apply_overrides). Errors are
    InputError with the engine's message, starting with the path."""
    text, source = _scene_text(path, overrides)
    return Scene(_native=_flexmbd.parse_scene_text(text, source), _text=text, _source=source)


def _scene_text(scene, overrides):
    """(text, source) of a scene given as a path or a dict, with overrides applied."""
    if isinstance(scene, dict):
        return json.dumps(apply_overrides(scene, overrides)), "<scene>"
    path = os.fspath(scene)
    text = read_scene_file(path)
    if overrides:
        text = json.dumps(apply_overrides(parse_json(text, path), overrides))
    return text, path


def parse_json(text, source):
    """JSON text parsed as strictly as the engine parses it (no NaN or Infinity, no key
    twice in an object): InputError "<source>: not valid JSON: ..." otherwise."""
    def constant(name):
        raise InputError(f"{source}: not valid JSON: {name} is not a JSON number")

    def pairs(items):
        out = {}
        for k, v in items:
            if k in out:
                shown = repr(k) if len(k) <= 60 else repr(k[:57] + "...")
                raise InputError(f"{source}: not valid JSON: the key {shown} appears twice in an object")
            out[k] = v
        return out

    def number(text):  # 1e999 is inf to Python's reader; the engine refuses it
        x = float(text)
        if not math.isfinite(x):
            raise InputError(f"{source}: not valid JSON: the number {text[:60]} is beyond the range of a double")
        return x

    try:
        return json.loads(text, parse_constant=constant, parse_float=number, object_pairs_hook=pairs)
    except json.JSONDecodeError as e:
        raise InputError(f"{source}: not valid JSON: {e}") from None
    except RecursionError:  # 100,000 nested arrays: Python's reader gives up
        raise InputError(f"{source}: not valid JSON: arrays or objects nested too deep") from None


def run_tensegrity(scene, overrides=None):
    """A tensegrity run (a "model": "tensegrity" scene file or dict, docs/tensegrity.md):
    Results with the columns of its results.csv (node positions and velocities, strut
    forces, cable tensions, slack flags, impulses, energies) and a summary with the run's
    statistics and ``events`` (snaps, slack and taut transitions, contacts: dicts with
    the columns of events.csv). A run that stops early has status "failed", its rows kept."""
    text, source = _scene_text(scene, overrides)
    columns, data, summary = _flexmbd.run_tensegrity_text(text, source)
    return Results(columns, data, summary)


def run_kinematics(scene, overrides=None):
    """The kinematic analysis of a linkage (a kinematics scene file or dict,
    docs/kinematics.md, with overrides as for load_scene): Results whose columns are those
    of kinematics.csv (step, alpha, node positions, transfer functions, velocities, ...)
    and whose summary holds status, message, steps_completed, alpha_reached, singular
    (the singular position met, or None). A singular position ends the analysis there:
    status "failed", the rows up to it kept (no exception)."""
    text, source = _scene_text(scene, overrides)
    columns, data, summary = _flexmbd.run_kinematics_text(text, source)
    return Results(columns, data, summary)
