"""The Python module against the engine: closed forms, the command line's results,
models built in Python against scene files, every error type, runs in threads.

Run by CTest (tests/CMakeLists.txt: PYTHONPATH=build/python, FLEXMBD_CLI, FLEXMBD_SOURCE_DIR).
"""
import csv
import json
import math
import os
import subprocess
import threading

import numpy as np
import pytest

import flexmbd

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("FLEXMBD_CLI", os.path.join(SOURCE, "build", "app", "flexmbd"))


def example(name):
    return os.path.join(SOURCE, "examples", name)


def rigid_crank_in_python(slider_joint=None):
    """examples/slider_crank_rigid.json built with the C++ API's objects and names;
    slider_joint(system) adds the slider's joint in place of the prismatic one."""
    scene = flexmbd.Scene("rigid slider-crank, l1 = 1, l2 = 2 (source document 000)")
    sys = scene.system
    crank = sys.add_rigid_body("crank", flexmbd.RigidBodyProperties(mass=1.0, inertia=0.1, com=(0.5, 0.0)),
                               flexmbd.FrameState2d(position=(0.0, 0.0), angle=0.0))
    rod = sys.add_rigid_body("rod", flexmbd.RigidBodyProperties(mass=1.0, inertia=0.4, com=(1.0, 0.0)),
                             flexmbd.FrameState2d(position=(1.0, 0.0)))
    slider = sys.add_rigid_body("slider", flexmbd.RigidBodyProperties(mass=0.5, inertia=0.01),
                                flexmbd.FrameState2d(position=(3.0, 0.0)))
    sys.add_revolute_joint("O1", flexmbd.GROUND, (0, 0), crank, (0, 0))
    sys.add_revolute_joint("O2", crank, (1, 0), rod, (0, 0))
    sys.add_revolute_joint("O3", rod, (2, 0), slider, (0, 0))
    if slider_joint:
        slider_joint(sys)
    else:
        sys.add_prismatic_joint("P", "ground", (0, 0), "slider", (0, 0), axis=(1, 0))
    sys.add_body_coordinate_driver("motor", crank, "theta", flexmbd.constant_speed_law(1.0))
    s = scene.solver
    s.formulation = "ggl"
    s.rtol, s.atol = 1e-8, 1e-10
    s.t_end, s.output_step = 2 * math.pi, math.pi / 30
    return scene


def test_rigid_slider_crank_from_python_follows_the_closed_form():
    # x = cos t + sqrt(4 - sin^2 t) (crank l1 = 1 at 1 rad/s, rod l2 = 2). At rtol 1e-8 the
    # engine's tests reach ~1e-9 m; bound 1e-7 m.
    res = rigid_crank_in_python().run()
    assert res.ok, res.message
    t = res.t
    exact = np.cos(t) + np.sqrt(4.0 - np.sin(t) ** 2)
    assert np.max(np.abs(res["slider.x"] - exact)) < 1e-7
    assert res.data.shape == (61, len(res.columns))
    assert res.summary["steps"] > 0 and res.summary["formulation"] == "ggl"


def test_a_model_built_in_python_equals_the_same_scene_file():
    # The same objects through the scene reader and through the bindings: the same
    # System, the same arithmetic, so the same numbers to the last bit.
    a = flexmbd.load_scene(example("slider_crank_rigid.json"), overrides={"solver.output_step": math.pi / 30}).run()
    b = rigid_crank_in_python().run()
    assert a.columns == b.columns
    assert np.array_equal(a.data, b.data)


def test_a_declared_joint_from_python_equals_the_scene_and_checks_its_keys():
    # The slider on a point_on_line joint (System.add_point_on_line_joint, made from the
    # kind's declaration) and the same joint in the scene: the same System, bit for bit;
    # the slider still follows the closed form x = cos t + sqrt(4 - sin^2 t) (its
    # rotation is free now, and nothing turns it).
    line = {"name": "P", "type": "point_on_line", "bodies": ["ground", "slider"],
            "points": [[0.0, 0.0], [0.0, 0.0]], "direction": [1.0, 0.0]}
    a = flexmbd.load_scene(example("slider_crank_rigid.json"),
                           overrides={"solver.output_step": math.pi / 30, "joints[3]": line}).run()
    added = []
    b = rigid_crank_in_python(lambda sys: added.append(
        sys.add_point_on_line_joint(**{k: v for k, v in line.items() if k != "type"}))).run()
    assert isinstance(added[0], flexmbd.ConstraintIndex) and added[0].value == 3
    assert a.ok and b.ok, (a.message, b.message)
    assert a.columns == b.columns and np.array_equal(a.data, b.data)
    exact = np.cos(b.t) + np.sqrt(4.0 - np.sin(b.t) ** 2)
    assert np.max(np.abs(b["slider.x"] - exact)) < 1e-7  # as the prismatic crank's test above
    assert "points [m]" in flexmbd.System.add_point_on_line_joint.__doc__
    with pytest.raises(flexmbd.InputError, match=r'add_point_on_line_joint: missing key "direction"'):
        flexmbd.Scene("bad").system.add_point_on_line_joint(name="q", bodies=["ground", "ground"], points=[[0, 0], [0, 0]])


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def test_the_elastic_crank_equals_the_command_line(tmp_path):
    # The CLI writes 17 significant digits, which read back to the same doubles: equal.
    out = tmp_path / "cli"
    scene = example("slider_crank_elastic.json")
    r = subprocess.run([CLI, "run", scene, "--out", str(out), "--quiet", "--t-end", "0.004"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    columns, data = read_csv(out / "results.csv")
    res = flexmbd.load_scene(scene, overrides={"solver": {"t_end": 0.004}}).run()
    assert res.columns == columns
    assert np.array_equal(res.data, data)
    assert "mid.uy" in res and len(res) == data.shape[0]


def test_overrides_reach_any_key_and_name_missing_ones():
    base = flexmbd.load_scene(example("slider_crank_elastic.json"), overrides={"solver.t_end": 0.002})
    stiff = flexmbd.load_scene(example("slider_crank_elastic.json"),
                               overrides={"solver.t_end": 0.002, "bodies[1].section.youngs_modulus": 2e13})
    a, b = base.run(), stiff.run()
    # a 100 x stiffer rod deflects about 100 x less (bound: 20 x)
    assert np.max(np.abs(b["mid.uy"])) < np.max(np.abs(a["mid.uy"])) / 20
    with pytest.raises(flexmbd.InputError, match=r"no element \[7\]"):
        flexmbd.load_scene(example("slider_crank_elastic.json"), overrides={"bodies[7].mass": 1.0})


def test_input_errors_are_value_errors_with_the_engines_message(tmp_path):
    # The message the command line prints (after "flexmbd: error: ").
    bad = flexmbd.apply_overrides(
        __import__("json").load(open(example("slider_crank_rigid.json"))), {"bodies[0].mass": -1.0})
    path = tmp_path / "bad.json"
    path.write_text(__import__("json").dumps(bad))
    with pytest.raises(flexmbd.InputError) as e:
        flexmbd.load_scene(path)
    assert isinstance(e.value, ValueError)
    r = subprocess.run([CLI, "run", str(path), "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 2
    assert str(e.value) in r.stderr
    assert 'bodies[0] ("crank"): key "mass" must be > 0, got -1' in str(e.value)
    with pytest.raises(flexmbd.InputError, match="cannot open scene file"):
        flexmbd.load_scene(tmp_path / "missing.json")
    with pytest.raises(flexmbd.InputError, match="unknown body 'nope'"):
        flexmbd.Scene().system.add_revolute_joint("j", "ground", (0, 0), "nope", (0, 0))


def test_a_model_error_names_the_redundant_joint():
    scene = rigid_crank_in_python()
    scene.system.add_revolute_joint("again", "crank", (1, 0), "rod", (0, 0))  # O2 twice
    scene.solver.redundant_constraints = "refuse"
    with pytest.raises(flexmbd.ModelError, match="again") as e:
        scene.run()
    assert isinstance(e.value, flexmbd.InputError)


def test_a_redundant_joint_is_released_by_default_and_named():
    scene = rigid_crank_in_python()
    scene.system.add_revolute_joint("again", "crank", (1, 0), "rod", (0, 0))  # O2 twice
    assert scene.solver.redundant_constraints == "resolve"
    results = scene.run()
    assert any("joint 'again'" in r for r in results.summary["redundant_constraints"])


def test_a_solver_failure_says_when_and_keeps_the_results():
    # A lock-up: the slider crank with a rod shorter than the crank stops at the dead
    # position; crossing singular positions off, the run fails there.
    scene = flexmbd.load_scene(example("slider_crank_lockup.json"), overrides={"solver.cross_singular": False})
    with pytest.raises(flexmbd.SolverFailure) as e:
        scene.run()
    f = e.value
    assert f.time > 0 and len(f.results) > 1
    assert f.results.t[-1] <= f.time
    assert "solver failure" in str(f) and f.results.summary["status"] == "failed"
    res = scene.run(raise_on_failure=False)
    assert not res.ok and res.message == f.results.message


def test_runs_in_threads_release_the_gil_and_give_the_same_numbers():
    # While a run goes on in a thread, the main thread keeps running Python (it could not
    # if the run held the GIL); two runs in threads equal the run alone.
    alone = flexmbd.load_scene(example("slider_crank_elastic.json"), overrides={"solver.t_end": 0.01}).run()
    results = [None, None]

    def work(k):
        results[k] = flexmbd.load_scene(example("slider_crank_elastic.json"), overrides={"solver.t_end": 0.01}).run()

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    ticks = 0
    while any(th.is_alive() for th in threads):
        ticks += 1
    for th in threads:
        th.join()
    assert ticks > 1000
    for r in results:
        assert np.array_equal(r.data, alone.data)


def test_flexible_body_built_in_python():
    # A pinned-pinned beam's natural frequencies from the model, and a flexible body in a
    # system: the frame at the first node, the columns q1.. of its elastic coordinates.
    section = flexmbd.rectangular_section(0.01, 0.01, 2.1e11, 7850.0)
    model = flexmbd.FfrBeamModel(flexmbd.BeamMesh2d.straight(1.0, 8, section),
                                 flexmbd.FfrBeamOptions(reference=flexmbd.Reference.PINNED_PINNED, modes=3))
    w = model.natural_frequencies()
    # first bending frequency of a pinned-pinned beam: pi^2 sqrt(EI / (rho A L^4)); 8 cubic
    # elements: 1e-4 relative
    EI, rhoA = 2.1e11 * 0.01 ** 4 / 12, 7850.0 * 1e-4
    assert abs(w[0] / (math.pi ** 2 * math.sqrt(EI / rhoA)) - 1) < 1e-4
    scene = flexmbd.Scene("beam")
    beam = scene.system.add_flexible_body("beam", model, flexmbd.FrameState2d(angular_velocity=1.0))
    scene.system.add_revolute_joint("pin", "ground", (0, 0), beam, (0, 0))
    scene.add_output({"type": "deflection", "name": "mid", "body": "beam", "point": [0.5, 0]})
    scene.solver.t_end, scene.solver.output_step = 0.01, 0.005
    res = scene.run()
    assert res.ok and "beam.q3" in res and "mid.M" in res


def test_modes_of_a_pendulum_built_in_python():
    # A rigid bar of length L hinged at one end: small oscillations at sqrt(3 g / (2 L)),
    # the closed form, to the linearisation's round-off (1e-10).
    L, g = 0.8, 9.81
    scene = flexmbd.Scene("pendulum")
    sys = scene.system
    bar = sys.add_rigid_body("bar", flexmbd.RigidBodyProperties(mass=2.0, inertia=2.0 * L * L / 12, com=(L / 2, 0)),
                             flexmbd.FrameState2d(angle=-math.pi / 2))
    sys.add_revolute_joint("pin", "ground", (0, 0), bar, (0, 0))
    sys.set_gravity((0, -g))
    modes = scene.modes(count=1)
    assert len(modes) == 1
    assert abs(modes[0]["omega"] / math.sqrt(3 * g / (2 * L)) - 1) < 1e-10
    assert len(modes[0]["shape"]) == len(scene.velocity_names) == 3


def spatial_pendulum(angle):
    """A rigid arm (m = 3 kg, Iyy = 0.08 kg m^2 about its centre of mass, which is d = 0.35 m
    below the pivot) on a revolute joint about the world y axis, at rest, turned by `angle`
    about y from the bottom."""
    d = 0.35
    return {"name": "spatial pendulum", "dimension": 3, "gravity": [0, 0, -9.81],
            "bodies": [{"name": "arm", "type": "rigid", "mass": 3.0, "inertia": [0.05, 0.08, 0.04],
                        "position": [-d * math.sin(angle), 0, -d * math.cos(angle)],
                        "orientation": {"axis": [0, 1, 0], "angle": angle}}],
            "joints": [{"name": "pivot", "type": "revolute", "bodies": ["ground", "arm"],
                        "frames": [{"point": [0, 0, 0], "axis": [0, 1, 0]}, {"point": [0, 0, d], "axis": [0, 1, 0]}]}],
            "solver": {"t_end": 1, "rtol": 1e-10, "atol": 1e-12}}


def test_spatial_modes_at_rest_and_at_a_time_of_a_run():
    # at=None: about the static equilibrium (the arm started 1.2 rad off the bottom hangs
    # straight down), omega = sqrt(m g d / (Iyy + m d^2)); the linearisation of an
    # equilibrium is exact to round-off (1e-10). at=0.5: about the state a run reaches then;
    # started at the bottom the arm stays there (to the run's tolerances, 1e-10 relative),
    # so the same frequency.
    m, d, iyy, g = 3.0, 0.35, 0.08, 9.81
    exact = math.sqrt(m * g * d / (iyy + m * d * d))
    modes = flexmbd.scene_from_dict(spatial_pendulum(1.2)).modes(count=3)
    assert len(modes) == 1
    assert abs(modes[0]["omega"] / exact - 1) < 1e-10
    assert len(modes[0]["shape"]) == 6  # velocity space: 3 translations, 3 body-axes rotations
    at_rest = flexmbd.scene_from_dict(spatial_pendulum(0.0))
    later = at_rest.modes(count=3, at=0.5)
    assert len(later) == 1
    assert abs(later[0]["omega"] / exact - 1) < 1e-8
    with pytest.raises(flexmbd.InputError, match="after t_start"):
        at_rest.modes(at=0.0)
    with pytest.raises(flexmbd.InputError, match="at and steady"):
        at_rest.modes(at=0.5, steady=True)


def test_kinematics_from_python_equals_the_command_line(tmp_path):
    # The four-bar's kinematics table: the same columns and numbers as kinematics.csv
    # (17 significant digits read back exactly).
    scene = example("kinematics_four_bar.json")
    out = tmp_path / "kin"
    r = subprocess.run([CLI, "kinematics", scene, "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    columns, data = read_csv(out / "kinematics.csv")
    res = flexmbd.run_kinematics(scene)
    assert res.columns == columns
    assert np.array_equal(res.data, data)
    assert res.ok and res.summary["singular"] is None
    # the locking four-bar stops at its singular position, rows kept
    lock = flexmbd.run_kinematics(example("kinematics_four_bar_lock.json"))
    assert not lock.ok and lock.summary["singular"]["kind"] == "lock" and len(lock) > 1


def test_tensegrity_from_python_equals_the_command_line(tmp_path):
    # The two-mass tensegrity scene: the same columns and numbers as its results.csv, and
    # the snap of events.csv among the summary's events.
    scene = example("tensegrity_two_masses.json")
    out = tmp_path / "tens"
    r = subprocess.run([CLI, "run", scene, "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    columns, data = read_csv(out / "results.csv")
    res = flexmbd.run_tensegrity(scene)
    assert res.columns == columns
    assert np.array_equal(res.data, data)
    with open(out / "events.csv", newline="") as f:
        events = list(csv.DictReader(f))
    assert [e["type"] for e in res.summary["events"]] == [e["type"] for e in events]
    assert res.summary["snaps"] == sum(e["type"] == "snap" for e in events)


def test_craig_bampton_rod_from_python_carries_the_axial_force():
    # A pinned-pinned rod reduced by Craig-Bampton at its end nodes keeps the
    # static axial stretch a joint load causes: its constraint modes span it, so the
    # number of elastic coordinates is (constraint modes) + (fixed-interface modes).
    section = flexmbd.rectangular_section(0.008, 0.008, 2e11, 7870.0)
    mesh = flexmbd.BeamMesh2d.straight(0.3, 8, section)
    cb = flexmbd.FfrBeamModel(mesh, flexmbd.FfrBeamOptions(reference=flexmbd.Reference.PINNED_PINNED, modes=2,
                                                           reduction=flexmbd.ModalReduction.CRAIG_BAMPTON,
                                                           interface_nodes=[0, 8]))
    normal = flexmbd.FfrBeamModel(mesh, flexmbd.FfrBeamOptions(reference=flexmbd.Reference.PINNED_PINNED, modes=2))
    # pinned-pinned holds node 0's two translations and node 8's transverse one: the
    # interface keeps node 0's slope, node 8's axial displacement and slope (3 modes)
    assert cb.num_elastic == 3 + 2 and normal.num_elastic == 2


def test_tolerance_overrides_scale_every_class_as_the_command_line():
    # examples/bari_slider_crank.json sets atol 1e-6, atol_elastic 1e-9: override_tolerances
    # (the command line's --atol) keeps their ratio; unset classes (None) follow atol by
    # their defaults, which summary["tolerances"] lists with the model scales.
    scene = flexmbd.load_scene(example("bari_slider_crank.json"), overrides={"solver.t_end": 0.001})
    s = scene.solver
    assert s.atol_elastic == 1e-9 and s.atol_angle is None and s.atol_velocity is None
    s.override_tolerances(atol=1e-8)
    assert s.atol == 1e-8 and math.isclose(s.atol_elastic, 1e-11, rel_tol=1e-12) and s.rtol == 1e-6
    t = scene.run().summary["tolerances"]
    assert math.isclose(t["elastic"], 1e-11, rel_tol=1e-12)
    assert math.isclose(t["angle"], 1e-8, rel_tol=1e-12)  # atol in rad (simulation/tolerances.cpp)
    assert math.isclose(t["velocity"], 1e-8, rel_tol=1e-12)  # atol per second
    s.override_tolerances(rtol=1e-8)  # rtol alone: every absolute tolerance by the same factor
    assert s.rtol == 1e-8 and math.isclose(s.atol, 1e-10, rel_tol=1e-12)
    assert math.isclose(s.atol_elastic, 1e-13, rel_tol=1e-12)


# ----- Ctrl-C during a run, the name rule ------------------------------------------------

def test_ctrl_c_interrupts_a_run_and_leaves_the_interpreter_usable():
    """D7: a KeyboardInterrupt (here from SIGALRM's handler) reaches Python within the run,
    not after it; the interpreter then runs scenes as before."""
    import signal
    import time

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    scene = flexmbd.load_scene(os.path.join(SOURCE, "examples", "slider_crank_rigid.json"),
                               overrides={"solver.t_end": 1e4, "solver.output_step": 1e4})
    previous = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.5)
        t0 = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            scene.run()
        assert time.monotonic() - t0 < 5.0  # before: the whole run (minutes)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    short = flexmbd.load_scene(os.path.join(SOURCE, "examples", "slider_crank_rigid.json"),
                               overrides={"solver.t_end": 0.5})
    assert short.run().summary["status"] == "ok"


@pytest.mark.parametrize("name,words", [("a,b", "has the character ',' at position 2"),
                                        ("rod\nx", "has the control character 0x0A at position 4"),
                                        ("", "is empty")])
def test_names_follow_the_one_rule_in_python_scenes(name, words):
    with open(os.path.join(SOURCE, "examples", "slider_crank_rigid.json"), encoding="utf-8") as f:
        scene = json.load(f)
    scene["drivers"][0]["name"] = name
    with pytest.raises(flexmbd.InputError, match="names are 1 to 64 characters") as e:
        flexmbd.scene_from_dict(scene)
    assert words in str(e.value)


@pytest.mark.parametrize("overrides,words", [
    ({"": 1}, "override '': the key is empty (expected a scene key such as 'solver.t_end'"),
    ({"bodies[": 1}, "override 'bodies[': '[' without its ']'"),
    ({"solver..t_end": 1}, "override 'solver..t_end': an empty name between dots"),
    ({"bodies[x].mass": 1}, "override 'bodies[x].mass': [x] is not an index"),
    ({1: 1}, "override 1: the key must be a string"),
    ({"solver.t_end": float("nan")}, "override 'solver.t_end': solver.t_end is nan, not a number a scene accepts"),
    ({"solver": {"t_end": math.inf}}, "override 'solver': solver.t_end is inf, not a number a scene accepts"),
    ({"solver.t_end": object()}, "is a object, not a scene value"),
])
def test_bad_overrides_are_input_errors_naming_the_key(overrides, words):
    # D20: before, IndexError, a raw ValueError or "<scene file>: invalid JSON at byte 1103"
    with pytest.raises(flexmbd.InputError) as e:
        flexmbd.load_scene(example("slider_crank_rigid.json"), overrides=overrides)
    assert words in str(e.value)
    assert "invalid JSON" not in str(e.value)


def test_override_values_from_numpy_are_scene_values():
    scene = flexmbd.load_scene(example("slider_crank_rigid.json"),
                               overrides={"solver.t_end": np.float64(0.1), "solver.max_steps": np.int64(100000),
                                          "gravity": np.array([0.0, -9.81])})
    assert scene.run().summary["status"] == "ok"


def test_scene_files_from_python_follow_the_command_lines_file_rules(tmp_path):
    # D20 / D17: load_scene reads by readSceneFile's rules (regular file, at most 64 MiB)
    with pytest.raises(flexmbd.InputError, match="a character device"):
        flexmbd.load_scene("/dev/zero")
    with pytest.raises(flexmbd.InputError, match="it is a directory"):
        flexmbd.load_scene(tmp_path, overrides={"solver.t_end": 1.0})
    nan_file = tmp_path / "nan.json"
    nan_file.write_text('{"name": "x", "gravity": [NaN, 0]}')
    with pytest.raises(flexmbd.InputError, match="NaN is not a JSON number"):
        flexmbd.load_scene(nan_file, overrides={"solver.t_end": 1.0})


def test_system_misuse_is_an_input_error_that_says_what_to_do():
    # D20: the ground has no coordinates; a load on it does nothing; finalize once
    scene = flexmbd.Scene("x")
    with pytest.raises(flexmbd.InputError, match="coordinate_offset: the ground has no coordinates"):
        scene.system.coordinate_offset(flexmbd.GROUND)
    bar = scene.system.add_rigid_body("bar", flexmbd.RigidBodyProperties(mass=1, inertia=0.1, com=(0.5, 0)))
    with pytest.raises(flexmbd.InputError, match="call it first"):
        scene.system.coordinate_offset(bar)
    with pytest.raises(flexmbd.InputError, match="force 'push': a load on the ground does nothing"):
        scene.system.add_applied_load("push", flexmbd.GROUND, (0, 0), flexmbd.constant_law(1.0))
    with pytest.raises(flexmbd.InputError, match="force 'push3': a load on the ground does nothing"):
        scene.system.add_spatial_applied_load("push3", "ground", (0, 0, 0), force_x=flexmbd.constant_law(1.0))
    scene.system.finalize()
    assert scene.system.coordinate_offset(bar) == 0
    with pytest.raises(flexmbd.InputError, match="finalize: the system is already finalized"):
        scene.system.finalize()
