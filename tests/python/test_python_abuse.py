"""The Python API under abuse: every builder given wrong types and
absurd values raises TypeError or flexmbd.InputError and never takes the interpreter down;
the same scenes run in 8 threads at once give the numbers of one run, and the interpreter
stays usable; a study on a Dask LocalCluster whose points fail on input, in the solver or
would run far too long (bounded by the solver's step limit) records every point's status
and ends.

Run by CTest as part of python_bindings (tests/CMakeLists.txt).
"""
import csv
import json
import math
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import flexmbd
from flexmbd import study as st

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def example(name):
    return os.path.join(SOURCE, "examples", name)


# ----- wrong types and absurd values to every builder ------------------------------------

# Values no builder should take for any argument, or only some: wrong types (None, strings,
# containers of the wrong shape or kind, objects, modules, classes, functions, complex) and
# absurd numbers (NaN, infinities, 1e308, negative, zero, integers beyond 64 bits). Sizes
# that are merely large (10**6 elements) are left out: what sizes run is tested in C++ (test_numeric_limits).
HOSTILE = [None, "x", "", "a,b", "x\ny", "ground", b"bytes", 1j, True, 0, -1, 3.5, 2 ** 31, 2 ** 70, -2 ** 70,
           1e308, -1e308, math.nan, math.inf, -math.inf, 5e-324, [], [1, 2], [[1, 2], [3]], (0, 0, 0),
           {"a": 1}, object(), np.array([np.nan] * 3), np.zeros((3, 3)), np.zeros((2, 2, 2)),
           np.array(["a", "b", "c"]), np.float32(1.0), np.int64(7), int, flexmbd, lambda: 0]


def _section3d():
    return flexmbd.rectangular_section_3d(0.02, 0.01, youngs_modulus=7e10, poisson_ratio=0.33, density=2700.0)


def _model3d():
    return flexmbd.FfrBeamModel3d(flexmbd.BeamMesh3d.straight(0.5, 4, _section3d()),
                                  flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.CLAMPED, modes=2))


def _model2d():
    section = flexmbd.rectangular_section(0.008, 0.008, 2e11, 7870.0)
    return flexmbd.FfrBeamModel(flexmbd.BeamMesh2d.straight(0.3, 4, section), flexmbd.FfrBeamOptions(modes=2))


def _planar():
    """A planar system with two rigid bodies and a revolute joint (names "a", "b", "h")."""
    sys_ = flexmbd.Scene("abuse").system
    a = sys_.add_rigid_body("a", flexmbd.RigidBodyProperties(1.0, 0.1))
    b = sys_.add_rigid_body("b", flexmbd.RigidBodyProperties(1.0, 0.1), flexmbd.FrameState2d(position=(1.0, 0)))
    sys_.add_revolute_joint("h", a, (1, 0), b, (0, 0))
    return sys_


def _spatial():
    """A spatial system of two rigid bodies "a", "b", the revolute joint "h" between them and
    the prismatic joint "p" of "a" on the ground."""
    sys_ = flexmbd.Scene("abuse").system
    props = flexmbd.RigidBody3dProperties(mass=1.0, inertia=(0.1, 0.1, 0.1))
    sys_.add_rigid_body_3d("a", props)
    sys_.add_rigid_body_3d("b", props, flexmbd.FrameState3d(position=(1, 0, 0)))
    sys_.add_spatial_joint_at_world("h", "revolute", "a", "b", (0.5, 0, 0), axis=(0, 0, 1))
    sys_.add_spatial_joint_at_world("p", "prismatic", "ground", "a", (0, 0, 0), axis=(1, 0, 0))
    return sys_


def _finalized(sys_):
    sys_.finalize()
    return sys_


def _law():
    return flexmbd.constant_speed_law(1.0)


# name -> (a function returning (callable, valid positional arguments)): each argument in
# turn is replaced by each HOSTILE value. The valid call itself must succeed.
BUILDERS = {
    "FrameState2d": lambda: (flexmbd.FrameState2d, [(0, 0), 0.0, (0, 0), 0.0]),
    "FrameState3d": lambda: (flexmbd.FrameState3d, [(0, 0, 0), ((0, 0, 1), 0.5), (0, 0, 0), (0, 0, 1)]),
    "RigidBodyProperties": lambda: (flexmbd.RigidBodyProperties, [1.0, 0.1, (0, 0)]),
    "RigidBody3dProperties": lambda: (flexmbd.RigidBody3dProperties, [1.0, (0.1, 0.2, 0.3)]),
    "SolidShape.box": lambda: (flexmbd.SolidShape.box, [(0.1, 0.2, 0.3)]),
    "SolidShape.cylinder": lambda: (flexmbd.SolidShape.cylinder, [0.1, 1.0, "z"]),
    "SolidShape.tube": lambda: (flexmbd.SolidShape.tube, [0.1, 0.05, 1.0, "x"]),
    "SolidShape.sphere": lambda: (flexmbd.SolidShape.sphere, [0.1]),
    "SolidShape.placed": lambda: (flexmbd.SolidShape.sphere(0.1).placed, [(0.1, 0, 0), ((0, 0, 1), 0.3)]),
    "ShapePart": lambda: (flexmbd.ShapePart, [flexmbd.SolidShape.sphere(0.1), 1.0]),
    "shape_properties": lambda: (flexmbd.shape_properties, [flexmbd.SolidShape.box((1, 1, 1)), None, 1000.0]),
    "composite_inertia": lambda: (flexmbd.composite_inertia,
                                  [[flexmbd.ShapePart(flexmbd.SolidShape.sphere(0.1), mass=1.0)]]),
    "shape_volume": lambda: (flexmbd.shape_volume, [flexmbd.SolidShape.sphere(0.1)]),
    "shape_inertia": lambda: (flexmbd.shape_inertia, [flexmbd.SolidShape.sphere(0.1), 1.0]),
    "rotation_from_axis_angle": lambda: (flexmbd.rotation_from_axis_angle, [(0, 0, 1), 0.5]),
    "rotation_from_quaternion": lambda: (flexmbd.rotation_from_quaternion, [(1, 0, 0, 0)]),
    "BeamSection": lambda: (flexmbd.BeamSection, [6.4e-5, 3.4e-10, 2e11, 7870.0, 0.0]),
    "BeamSection3d": lambda: (flexmbd.BeamSection3d, [1e-3, 2e-8, 8e-8, 4e-12, 2.1e11, 8.1e10, None, 7800.0]),
    "rectangular_section": lambda: (flexmbd.rectangular_section, [0.008, 0.008, 2e11, 7870.0]),
    "rectangular_section_3d": lambda: (flexmbd.rectangular_section_3d, [0.02, 0.01, 7e10, None, 0.33, 2700.0]),
    "circular_section_3d": lambda: (flexmbd.circular_section_3d, [0.01, 2e11, 8e10, None, 7800.0]),
    "BeamMesh2d.straight": lambda: (flexmbd.BeamMesh2d.straight,
                                    [0.3, 4, flexmbd.rectangular_section(0.008, 0.008, 2e11, 7870.0)]),
    "BeamMesh3d.straight": lambda: (flexmbd.BeamMesh3d.straight, [0.5, 4, _section3d()]),
    "BeamMesh3d": lambda: (flexmbd.BeamMesh3d, [[(0, 0, 0), (0.5, 0, 0)], [(0, 1)], _section3d(), (0, 1, 0)]),
    "FfrBeamOptions": lambda: (flexmbd.FfrBeamOptions, [flexmbd.Reference.PINNED_PINNED, 0, -1, 2]),
    "FfrBeamOptions3d": lambda: (flexmbd.FfrBeamOptions3d, [flexmbd.Reference3d.CLAMPED, 0, -1, 2, [], True,
                                                            flexmbd.ModalReduction.CRAIG_BAMPTON, [0, 4], True]),
    "FfrBeamModel": lambda: (flexmbd.FfrBeamModel, [flexmbd.BeamMesh2d.straight(
        0.3, 4, flexmbd.rectangular_section(0.008, 0.008, 2e11, 7870.0)), flexmbd.FfrBeamOptions(modes=2)]),
    "FfrBeamModel3d": lambda: (flexmbd.FfrBeamModel3d, [flexmbd.BeamMesh3d.straight(0.5, 4, _section3d()),
                                                        flexmbd.FfrBeamOptions3d(modes=2)]),
    "FfrPoint3d": lambda: (flexmbd.FfrPoint3d, [(0, 0, 0), np.zeros((3, 2)), np.zeros((3, 2))]),
    "JointFrame": lambda: (flexmbd.JointFrame, [(0, 0, 0), (0, 0, 1)]),
    "world_joint_frame": lambda: (flexmbd.world_joint_frame, [(0, 0, 0), (0, 0, 1), (1, 0, 0)]),
    "constant_law": lambda: (flexmbd.constant_law, [1.0]),
    "constant_speed_law": lambda: (flexmbd.constant_speed_law, [1.0]),
    "harmonic_law": lambda: (flexmbd.harmonic_law, [1.0, 2.0]),
    "polynomial_law": lambda: (flexmbd.polynomial_law, [[0.0, 1.0, 0.5]]),
    "spin_up_law": lambda: (flexmbd.spin_up_law, [10.0, 0.5]),
    "tabulated_law": lambda: (flexmbd.tabulated_law, [[0.0, 1.0, 2.0], [0.0, 1.0, 0.0]]),
    # planar builders on a system with bodies "a", "b" and joint "h"
    "add_rigid_body": lambda: (_planar().add_rigid_body, ["c", flexmbd.RigidBodyProperties(1.0, 0.1),
                                                          flexmbd.FrameState2d()]),
    "add_flexible_body": lambda: (_planar().add_flexible_body, ["c", _model2d(), flexmbd.FrameState2d()]),
    "add_revolute_joint": lambda: (_planar().add_revolute_joint, ["j", "a", (0, 0), "ground", (0, 0)]),
    "add_fixed_joint": lambda: (_planar().add_fixed_joint, ["j", "a", (0, 0), "ground", (0, 0)]),
    "add_prismatic_joint": lambda: (_planar().add_prismatic_joint, ["j", "ground", (0, 0), "b", (0, 0), (1, 0)]),
    "add_body_coordinate_driver": lambda: (_planar().add_body_coordinate_driver, ["m", "a", "theta", _law()]),
    "add_joint_driver": lambda: (_planar().add_joint_driver, ["m", "h", _law()]),
    "add_spring_damper": lambda: (_planar().add_spring_damper, ["s", "a", (0, 0), "b", (0, 0), 10.0, 0.1, 0.5]),
    "add_rotational_spring_damper": lambda: (_planar().add_rotational_spring_damper, ["s", "h", 10.0, 0.1, 0.0]),
    "add_applied_load": lambda: (_planar().add_applied_load, ["f", "a", (0, 0), _law(), None, None]),
    # spatial builders on a system with bodies "a", "b" and joints "h", "p"
    "add_rigid_body_3d": lambda: (_spatial().add_rigid_body_3d,
                                  ["c", flexmbd.RigidBody3dProperties(1.0, (1, 1, 1)), flexmbd.FrameState3d()]),
    "add_flexible_body_3d": lambda: (_spatial().add_flexible_body_3d, ["c", _model3d(), flexmbd.FrameState3d()]),
    "add_spatial_joint": lambda: (_spatial().add_spatial_joint, ["j", "spherical", "ground", flexmbd.JointFrame(),
                                                                 "a", flexmbd.JointFrame()]),
    "add_spatial_joint_at_world": lambda: (_spatial().add_spatial_joint_at_world,
                                           ["j", "revolute", "ground", "a", (0, 0, 0), (0, 0, 1), None, None]),
    "add_joint_angle_driver": lambda: (_spatial().add_joint_angle_driver, ["m", "h", _law()]),
    "add_joint_displacement_driver": lambda: (_spatial().add_joint_displacement_driver, ["m", "p", _law()]),
    "add_spatial_spring_damper": lambda: (_spatial().add_spatial_spring_damper,
                                          ["s", "a", (0, 0, 0), "b", (0, 0, 0), 10.0, 0.1, 0.5]),
    "add_spatial_rotational_spring_damper": lambda: (_spatial().add_spatial_rotational_spring_damper,
                                                     ["s", "h", 10.0, 0.1, 0.0]),
    "add_spatial_bushing": lambda: (_spatial().add_spatial_bushing, ["k", "a", flexmbd.JointFrame(), "b",
                                                                     flexmbd.JointFrame(), [1.0] * 6, [0.1] * 6]),
    "add_spatial_bushing_at_world": lambda: (_spatial().add_spatial_bushing_at_world,
                                             ["k", "a", "b", flexmbd.world_joint_frame((0.5, 0, 0), (0, 0, 1)),
                                              [1.0] * 6, None]),
    "add_spatial_applied_load": lambda: (_spatial().add_spatial_applied_load,
                                         ["f", "a", (0, 0, 0), _law(), None, None, None, None, _law()]),
    "set_gravity": lambda: (_spatial().set_gravity, [(0, 0, -9.81)]),
    "coordinate_offset": lambda: (_finalized(_spatial()).coordinate_offset, ["a"]),
    "initial_joint_angle": lambda: (_spatial().initial_joint_angle, ["h"]),
    "find_body": lambda: (_spatial().find_body, ["a"]),
}


def _try(what, f):
    """Prints what before calling f (a crash names it), and what with the exception if f
    raises anything but TypeError or flexmbd.InputError (AttributeError too for setters:
    read-only attributes)."""
    print(f"CALL {what}", flush=True)
    try:
        f()
    except (TypeError, flexmbd.InputError):
        pass
    except Exception as e:  # noqa: BLE001  (what the test reports)
        print(f"UNEXPECTED {what}: {type(e).__name__}: {e}"[:400], flush=True)


def sweep_builders():
    """Every builder with each argument in turn replaced by each HOSTILE value."""
    for name in sorted(BUILDERS):
        for position in range(len(BUILDERS[name]()[1])):
            for value in HOSTILE:
                f, args = BUILDERS[name]()
                args[position] = value
                _try(f"{name} argument {position} = {value!r:.80}", lambda: f(*args))
    print("DONE", flush=True)


def sweep_attributes():
    """Every writable attribute of the API's value objects set to each HOSTILE value, one
    object through all of them (what one value leaves, the next meets), then the objects
    used: validated, added to a system, run."""
    inv = _model3d().invariants
    objects = {"SolverSettings": flexmbd.SolverSettings(), "FfrInvariants3d": inv,
               "FfrBeamOptions3d": flexmbd.FfrBeamOptions3d(), "FfrBeamOptions": flexmbd.FfrBeamOptions(),
               "FrameState2d": flexmbd.FrameState2d(), "FrameState3d": flexmbd.FrameState3d(),
               "JointFrame": flexmbd.JointFrame(), "FfrPoint3d": inv.points[0],
               "RigidBodyProperties": flexmbd.RigidBodyProperties(1.0, 0.1),
               "RigidBody3dProperties": flexmbd.RigidBody3dProperties(1.0, (1, 1, 1)), "BeamSection3d": _section3d(),
               "SolidShape": flexmbd.SolidShape.box((1, 1, 1)), "Scene.solver": flexmbd.Scene("s").solver}
    for name, obj in objects.items():
        for attr in [a for a in dir(obj) if not a.startswith("_") and not callable(getattr(obj, a))]:
            for value in HOSTILE:
                def set_it():
                    try:
                        setattr(obj, attr, value)
                    except AttributeError:  # read-only
                        pass
                _try(f"{name}.{attr} = {value!r:.80}", set_it)
    _try("FfrInvariants3d.validate()", inv.validate)
    _try("add_flexible_body_3d(abused invariants)", lambda: flexmbd.Scene("s").system.add_flexible_body_3d("b", inv))
    _try("add_rigid_body_3d(abused objects)", lambda: _spatial().add_rigid_body_3d(
        "c", objects["RigidBody3dProperties"], objects["FrameState3d"]))
    print("DONE", flush=True)


def _in_child(function):
    """Runs this module's function in a child interpreter; returns its printed lines after
    checking that it ended normally (a crash names the last call) and met nothing but
    TypeError and flexmbd.InputError."""
    here = os.path.dirname(os.path.abspath(__file__))
    code = f"import sys; sys.path.insert(0, {here!r}); import test_python_abuse as t; t.{function}()"
    r = subprocess.run([sys.executable, "-X", "faulthandler", "-c", code], capture_output=True, text=True, timeout=600)
    lines = r.stdout.splitlines()
    assert r.returncode == 0, f"the interpreter ended with {r.returncode} at: {lines[-1:]}\n{r.stderr[-2000:]}"
    assert lines and lines[-1] == "DONE"
    unexpected = [x for x in lines if x.startswith("UNEXPECTED")]
    assert not unexpected, "\n".join(unexpected[:40])
    return [x for x in lines if x.startswith("CALL")]


@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_the_valid_call_of_each_builder_template_succeeds(name):
    f, args = BUILDERS[name]()
    f(*args)


def test_wrong_types_and_absurd_values_to_every_builder_raise_type_or_input_errors():
    assert len(_in_child("sweep_builders")) > 5000  # every argument of every builder, every value


def test_wrong_types_set_on_every_object_raise_type_or_input_errors():
    assert len(_in_child("sweep_attributes")) > 2000


def test_a_point_taken_from_invariants_outlives_setting_the_points_again():
    inv = _model3d().invariants
    point = inv.points[0]
    inv.points = []  # freed the point's storage when points handed out references into it
    point.shape = np.ones((3, inv.num_elastic))
    assert point.shape.sum() == 3 * inv.num_elastic and inv.points == []
    with pytest.raises(TypeError, match="FfrPoint3d: shape must be a 3 x nf matrix"):
        flexmbd.FfrPoint3d((0, 0, 0), np.zeros((2, 2)), np.zeros((3, 2)))
    with pytest.raises(flexmbd.InputError, match="position_shape: expected 3 matrices"):
        inv.position_shape = [np.zeros((5, 2))] * 3


# ----- 8 threads at once ---------------------------------------------------------------

def _run(path, overrides):
    return flexmbd.load_scene(example(path), overrides=overrides).run()


THREAD_SCENES = [("slider_crank_elastic.json", {"solver.t_end": 0.005}),
                 ("spatial_slider_crank_elastic.json", {"solver.t_end": 0.005}),
                 ("heavy_top.json", {"solver.t_end": 0.05}),
                 ("bari_slider_crank.json", {"solver.t_end": 0.005})]


def test_eight_threads_running_at_once_give_the_numbers_of_one_run():
    alone = [_run(p, o) for p, o in THREAD_SCENES]
    results, errors = [None] * 8, []
    barrier = threading.Barrier(8)

    def work(k):
        try:
            barrier.wait()
            path, overrides = THREAD_SCENES[k % len(THREAD_SCENES)]
            results[k] = _run(path, overrides)
        except Exception as e:  # noqa: BLE001
            errors.append(f"thread {k}: {type(e).__name__}: {e}")

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(timeout=300)
    assert not any(th.is_alive() for th in threads)
    assert not errors, errors
    for k, r in enumerate(results):
        assert r.ok
        assert np.array_equal(r.data, alone[k % len(THREAD_SCENES)].data), f"thread {k}"
    # the interpreter is still usable: a run, an input error, a model from Python
    assert np.array_equal(_run(*THREAD_SCENES[0]).data, alone[0].data)
    with pytest.raises(flexmbd.InputError):
        flexmbd.load_scene(example("slider_crank_rigid.json"), overrides={"bodies[0].mass": -1.0})


def test_eight_threads_of_failing_and_bad_scenes_leave_the_interpreter_usable():
    outcomes = [None] * 8
    barrier = threading.Barrier(8)
    cases = [{"bodies[0].mass": -1.0}, {"solver.max_steps": 3}, {"solver.t_end": 0.05}, {"bodies[0].mass": math.nan}]

    def work(k):
        barrier.wait()
        try:
            r = flexmbd.load_scene(example("slider_crank_rigid.json"), overrides=cases[k % 4]).run(
                raise_on_failure=False)
            outcomes[k] = "ok" if r.ok else "failed"
        except flexmbd.InputError:
            outcomes[k] = "input_error"

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(timeout=300)
    assert outcomes == ["input_error", "failed", "ok", "input_error"] * 2
    assert _run("slider_crank_rigid.json", {"solver.t_end": 0.05}).ok


# ----- a study whose points fail --------------------------------------------------------

def test_a_study_on_dask_records_points_that_fail_or_would_run_too_long(tmp_path):
    # the rigid crank, 4 points: ok; a negative mass (input); max_steps 3 (solver); and a
    # run of t_end 1e6 s that would take hours, ended by its step limit within an output
    # interval of 1000 s (max_steps 2000)
    spec = {
        "scene": example("slider_crank_rigid.json"),
        "overrides": {"solver": {"t_end": 0.5}},
        "axes": [{"name": "case", "key": "name", "values": ["ok", "input", "solver", "long"]},
                 {"name": "mass", "key": "bodies[0].mass", "values": [1.0, -1.0, 1.0, 1.0]},
                 {"name": "max_steps", "key": "solver.max_steps", "values": [100000, 100000, 3, 2000]},
                 {"name": "t_end", "key": "solver.t_end", "values": [0.5, 0.5, 0.5, 1e6]},
                 {"name": "output_step", "key": "solver.output_step", "values": [0.1, 0.1, 0.1, 1000.0]}],
        "combine": "zip",
        "outputs": {"summary": ["steps"], "max_abs": ["slider.x"]},
    }
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    study = st.load_study(str(path))
    ran, failed = st.run_study(study, str(tmp_path / "out"), workers=2, progress=False)
    assert (ran, failed) == (4, 3)
    with open(tmp_path / "out" / "study.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    status = {r["case"]: (r["status"], r["message"]) for r in rows}
    assert status["ok"] == ("ok", "")
    assert status["input"][0] == "input_error" and 'key "mass" must be > 0' in status["input"][1]
    for case in ("solver", "long"):  # IDA's words: "mxstep steps taken before reaching tout"
        assert status[case][0] == "failed" and "IDA_TOO_MUCH_WORK" in status[case][1]
    assert math.isfinite(float(next(r for r in rows if r["case"] == "ok")["max_abs(slider.x)"]))
