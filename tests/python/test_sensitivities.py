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
    # one engine path (io/sensitivity_results.hpp runSensitivityScene) behind both: the same
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
