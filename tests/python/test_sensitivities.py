"""Forward sensitivities from Python (Scene.run(sensitivities=[...]), docs/sensitivities.md):
the slider's position against the closed form of its derivative, the table and gradients
against the command line's, and the errors.

Run by CTest (tests/CMakeLists.txt: PYTHONPATH=build/python, FLEXMBD_CLI, FLEXMBD_SOURCE_DIR).
"""
import csv
import json
import os
import subprocess

import numpy as np
import pytest

import flexmbd

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("FLEXMBD_CLI", os.path.join(SOURCE, "build", "app", "flexmbd"))
CRANK = os.path.join(SOURCE, "examples", "slider_crank_rigid.json")
ROD_LENGTH = "joints[2].points[0][0]"  # the rod's end O3, at (l2, 0) on the rod: l2 = 2
SLIDER_MASS = "bodies[2].mass"


def test_slider_position_derivative_by_rod_length_is_the_closed_form():
    # x = l1 cos(theta) + sqrt(l2^2 - l1^2 sin(theta)^2) with l1 = 1, so
    # dx/dl2 = l2 / sqrt(l2^2 - sin(theta)^2). The engine's error: IDAS at the scene's
    # rtol 1e-8 and the central difference of dF/dp (~1e-10); 1e-6 leaves a margin.
    res = flexmbd.load_scene(CRANK).run(sensitivities=[ROD_LENGTH])
    assert res.ok
    theta = res["crank.theta"]
    closed = 2.0 / np.sqrt(4.0 - np.sin(theta) ** 2)
    assert np.max(np.abs(res.derivative("slider.x", ROD_LENGTH) - closed)) < 1e-6
    final = res.summary["sensitivities"]["final"]["slider.x"]
    assert final["gradient"][ROD_LENGTH] == pytest.approx(res.derivative("slider.x", ROD_LENGTH)[-1], rel=1e-15)


def test_table_and_gradients_equal_the_command_lines(tmp_path):
    # one engine path (results/sensitivity_results.hpp runSensitivityScene) behind both: the same
    # numbers to the 17 digits results.csv prints
    res = flexmbd.load_scene(CRANK).run(sensitivities=[SLIDER_MASS, ROD_LENGTH])
    out = tmp_path / "out"
    subprocess.run([CLI, "run", CRANK, "--out", str(out), "-q", "--sensitivity", SLIDER_MASS,
                    "--sensitivity", ROD_LENGTH], check=True)
    with open(out / "results.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == res.columns
    table = np.array(rows[1:], dtype=float)
    assert table.shape == res.data.shape
    assert np.allclose(table, res.data, rtol=1e-14, atol=0.0)
    with open(out / "summary.json") as f:
        summary = json.load(f)
    assert summary["sensitivities"] == res.summary["sensitivities"]


def test_sensitivity_errors_name_the_parameter():
    with pytest.raises(flexmbd.InputError, match=r"bodies\[7\]\.mass.*no element \[7\]"):
        flexmbd.load_scene(CRANK).run(sensitivities=["bodies[7].mass"])
    with pytest.raises(flexmbd.InputError, match="expected a number there"):
        flexmbd.load_scene(CRANK).run(sensitivities=["bodies[1].name"])
    built = flexmbd.Scene("built in Python")
    with pytest.raises(flexmbd.InputError, match="sensitivities need a scene read from a file or a dict"):
        built.run(sensitivities=[SLIDER_MASS])
    plain = flexmbd.load_scene(CRANK).run()
    with pytest.raises(KeyError, match="no column"):
        plain.derivative("slider.x", SLIDER_MASS)


def free_crank():
    """The slider crank without its driver, the crank started at 1 rad/s, over 1 s (one
    degree of freedom: the adjoint's test model, tests/test_adjoint.cpp)."""
    with open(CRANK) as f:
        scene = json.load(f)
    del scene["drivers"]
    scene["bodies"][0]["angular_velocity"] = 1.0
    scene["solver"]["t_end"] = 1.0
    scene["solver"]["rtol"] = 1e-10
    scene["solver"]["atol"] = 1e-12
    return scene


def test_adjoint_gradients_equal_the_forward_ones_and_the_command_lines(tmp_path):
    # int slider.x dt by the adjoint, against the forward sensitivities of slider.x at
    # outputs 1e-3 s apart integrated by Simpson's rule (error ~h^4: 1e-12) and against the
    # command line (one engine path, results/adjoint_results.hpp: the same numbers)
    scene = free_crank()
    res = flexmbd.scene_from_dict(scene).run(sensitivities=[SLIDER_MASS, ROD_LENGTH], adjoint="integral:slider.x")
    assert res.ok
    assert not any(c.startswith("d") and "/d" in c for c in res.columns)  # no derivative columns
    gradient = res.gradient("integral:slider.x")
    fine = dict(scene, solver=dict(scene["solver"], output_step=1e-3))
    forward = flexmbd.scene_from_dict(fine).run(sensitivities=[SLIDER_MASS, ROD_LENGTH])
    weights = np.ones(len(forward))
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    for path in (SLIDER_MASS, ROD_LENGTH):
        simpson = np.sum(weights * forward.derivative("slider.x", path)) * 1e-3 / 3.0
        # both at rtol 1e-10 over a second: 1e-6 of the gradient (the slider's mass moves
        # its position little, so the state's errors weigh more in that derivative:
        # measured 1.4e-5 of it at rtol 1e-8)
        assert gradient[path] == pytest.approx(simpson, rel=1e-6)
    path = tmp_path / "crank.json"
    path.write_text(json.dumps(scene))
    out = tmp_path / "out"
    subprocess.run([CLI, "run", str(path), "--out", str(out), "-q", "--sensitivity", SLIDER_MASS,
                    "--sensitivity", ROD_LENGTH, "--adjoint", "integral:slider.x"], check=True)
    with open(out / "summary.json") as f:
        summary = json.load(f)
    integrals = summary["sensitivities"]["integrals"]
    assert integrals == res.summary["sensitivities"]["integrals"]


def test_adjoint_errors():
    with pytest.raises(flexmbd.InputError, match="need the parameters"):
        flexmbd.load_scene(CRANK).run(adjoint="integral:slider.x")
    with pytest.raises(flexmbd.InputError, match="no results column"):
        flexmbd.load_scene(CRANK).run(sensitivities=[SLIDER_MASS], adjoint="integral:slider.w")
    plain = flexmbd.load_scene(CRANK).run()
    with pytest.raises(KeyError, match="no adjoint output"):
        plain.gradient("integral:slider.x")


def test_the_scenes_sensitivity_key_is_the_default_of_run():
    # the scene's "sensitivity" object (docs/scene-format.md): run() with no arguments takes
    # its parameters; the table and gradients equal the run naming them; [] runs without
    with open(CRANK) as f:
        scene = json.load(f)
    scene["sensitivity"] = {"parameters": [SLIDER_MASS, ROD_LENGTH]}
    keyed = flexmbd.scene_from_dict(scene).run()
    named = flexmbd.load_scene(CRANK).run(sensitivities=[SLIDER_MASS, ROD_LENGTH])
    assert keyed.columns == named.columns
    assert np.array_equal(keyed.data, named.data)
    assert keyed.summary["sensitivities"] == named.summary["sensitivities"]
    plain = flexmbd.scene_from_dict(scene).run(sensitivities=[])
    assert "sensitivities" not in plain.summary
    assert not any(c.startswith("d") and "/d" in c for c in plain.columns)
    # the adjoint outputs of the key, with its parameters
    scene["sensitivity"]["adjoint"] = ["integral_square:slider.x"]
    adjoint = flexmbd.scene_from_dict(scene).run()
    assert set(adjoint.gradient("integral_square:slider.x")) == {SLIDER_MASS, ROD_LENGTH}
