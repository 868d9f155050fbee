"""flexmbd.study: a small study on a Dask LocalCluster, failures recorded per point,
resume, and the same numbers serially and distributed."""
import csv
import json
import os

import pytest

from flexmbd import InputError
from flexmbd import study as st

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def write_study(tmp_path, axes, overrides=None):
    spec = {
        "scene": os.path.join(SOURCE, "examples", "slider_crank_elastic_demo_modal.json"),
        "overrides": overrides or {"solver": {"t_end": 0.01}},
        "axes": axes,
        "outputs": {"summary": ["steps"], "max_abs": ["mid.uy", "motor.effort"], "at": [{"column": "slider.x", "t": 0.005}]},
    }
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    return st.load_study(str(path))


def table(out):
    with open(os.path.join(out, "study.csv"), newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    drop = header.index("wall_seconds")
    return header, sorted([r[:drop] + r[drop + 1:] for r in rows[1:]], key=lambda r: int(r[0]))


AXES = [{"name": "speed", "key": "drivers[0].law.speed", "values": [100.0, 250.0]},
        {"name": "modulus", "key": "bodies[1].section.youngs_modulus", "values": [5e10, 2e11]}]


def test_a_study_on_a_local_cluster_equals_the_serial_study(tmp_path):
    study = write_study(tmp_path, AXES)
    assert len(study.points) == 4
    ran, failed = st.run_study(study, str(tmp_path / "dask"), workers=2, progress=False)
    assert (ran, failed) == (4, 0)
    st.run_study(study, str(tmp_path / "serial"), workers=0, progress=False)
    h1, rows_dask = table(tmp_path / "dask")
    h2, rows_serial = table(tmp_path / "serial")
    assert h1 == h2 == study.columns
    # every number written with repr (17 digits): the same runs give the same text
    assert rows_dask == rows_serial
    # physics in the record: a stiffer rod deflects less at the same speed
    col = {c: k for k, c in enumerate(h1[:h1.index("wall_seconds")] + h1[h1.index("wall_seconds") + 1:])}
    by = {(float(r[col["speed"]]), float(r[col["modulus"]])): float(r[col["max_abs(mid.uy)"]]) for r in rows_serial}
    assert by[(250.0, 2e11)] < by[(250.0, 5e10)]


def test_failed_points_are_recorded_and_do_not_stop_the_study(tmp_path):
    axes = [{"name": "modulus", "key": "bodies[1].section.youngs_modulus", "values": [2e11, -1.0]},
            {"name": "max_steps", "key": "solver.max_steps", "values": [1000000, 3]}]
    study = write_study(tmp_path, axes)
    ran, failed = st.run_study(study, str(tmp_path / "out"), workers=0, progress=False)
    assert (ran, failed) == (4, 3)
    header, rows = table(tmp_path / "out")
    status = {(r[1], r[2]): (r[3], r[4]) for r in rows}
    assert status[("200000000000.0", "1000000")][0] == "ok"
    s, msg = status[("-1.0", "1000000")]
    assert s == "input_error" and 'key "youngs_modulus" must be > 0, got -1' in msg
    s, msg = status[("200000000000.0", "3")]
    assert s == "failed" and msg  # the solver's reason, with the time reached in its column


def test_a_rerun_resumes_and_skips_finished_points(tmp_path):
    study = write_study(tmp_path, AXES)
    out = tmp_path / "out"
    st.run_study(study, str(out), workers=0, progress=False)
    full = table(out)
    path = out / "study.csv"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:2]))  # interrupted after one point
    ran, _ = st.run_study(study, str(out), workers=0, progress=False)
    assert ran == 3
    assert table(out) == full
    ran, _ = st.run_study(study, str(out), workers=0, progress=False)
    assert ran == 0


def test_study_input_errors_name_the_key(tmp_path):
    with pytest.raises(InputError, match='axes\\[0\\]: unknown key "valus"|unknown key \'valus\''):
        write_study(tmp_path, [{"key": "solver.rtol", "valus": [1e-6]}])
    with pytest.raises(InputError, match="range"):
        write_study(tmp_path, [{"key": "solver.rtol", "range": [1e-6]}])
    study = write_study(tmp_path, AXES)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "study.csv").write_text("a,b\n")
    with pytest.raises(InputError, match="another study"):
        st.run_study(study, str(tmp_path / "other"), workers=0, progress=False)


def test_a_study_whose_every_point_fails_on_input_is_an_input_error(tmp_path, capsys):
    # an axis key with a typo: every point refuses its override; the study says so (exit 2
    # from the command, naming the key) instead of reporting a finished study
    axes = [{"name": "modulus", "key": "bodies[1].section.youngs_modulus", "values": [5e10, 2e11]},
            {"name": "speed", "key": "drivers[0].law.sped", "values": [100.0]}]
    study = write_study(tmp_path, axes)
    with pytest.raises(InputError, match="every point failed on input \\(2 of 2.*sped"):
        st.run_study(study, str(tmp_path / "out"), workers=0, progress=False)
    assert len(table(tmp_path / "out")[1]) == 2  # the rows are kept
    spec = write_spec(tmp_path, axes, name="typo.json")
    assert st.main([spec, "--out", str(tmp_path / "cli"), "--workers", "0", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("flexmbd-study: error:") and "sped" in err


def write_spec(tmp_path, axes, plot=None, name="study.json"):
    spec = {
        "scene": os.path.join(SOURCE, "examples", "slider_crank_elastic_demo_modal.json"),
        "overrides": {"solver": {"t_end": 0.005}},
        "axes": axes,
        "outputs": {"summary": ["steps"], "max_abs": ["mid.uy"]},
    }
    if plot is not None:
        spec["plot"] = plot
    path = tmp_path / name
    path.write_text(json.dumps(spec))
    return str(path)


@pytest.mark.parametrize("plot,words", [
    ({"x": "speed", "y": []}, 'plot: key "y" must be a column name or a non-empty list'),
    ({"x": "speed", "y": "max_abs(mid.uy)", "title": "T" * 100000}, 'plot: key "title" must be one line of at most 300'),
    ({"x": "sped", "y": "max_abs(mid.uy)"}, "plot: key 'x': no column \"sped\" in the study"),
    ({"x": "speed", "y": "max_abs(mid.uy)", "group": "nope"}, "plot: key 'group': no column \"nope\""),
    ({"x": "integ", "y": "max_abs(mid.uy)"}, "plot: key 'x': the axis 'integ' has values that are not numbers"),
    ({"x": "speed", "y": "max_abs(mid.uy)", "file": "../up.png"}, "plot: key 'file': the name \"../up\" has the character '.'"),
    ({"x": "speed", "y": "max_abs(mid.uy)", "file": "plot.exe"}, 'plot: key "file" must be a file name ending in .png'),
])
def test_the_plot_spec_is_checked_before_the_study_runs(tmp_path, capsys, plot, words):
    # D17: before, a traceback after every point had run
    axes = [{"name": "integ", "key": "solver.integrator", "values": ["ida", "radau5"]},
            {"key": "drivers[0].law.speed", "values": [100.0, 150.0]}]
    path = write_spec(tmp_path, axes, plot)
    assert st.main([path, "--out", str(tmp_path / "out"), "--workers", "0", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "out" / "study.csv").exists()  # refused before any point ran


def test_a_group_axis_of_strings_groups_the_plot_by_category(tmp_path, capsys):
    # D17, R11: an axis of integrator names as the plot's group
    axes = [{"name": "integ", "key": "solver.integrator", "values": ["ida", "radau5"]},
            {"key": "drivers[0].law.speed", "values": [100.0, 150.0]}]  # named "speed" by default
    path = write_spec(tmp_path, axes, {"x": "speed", "y": ["max_abs(mid.uy)"], "group": "integ", "file": "by_integrator.png"})
    assert st.main([path, "--out", str(tmp_path / "out"), "--workers", "0", "--quiet"]) == 0
    png = (tmp_path / "out" / "by_integrator.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    header, rows = table(tmp_path / "out")
    assert header[:3] == ["point", "integ", "speed"]
    assert {r[1] for r in rows} == {"ida", "radau5"} and {r[3] for r in rows} == {"ok"}


@pytest.mark.parametrize("axis,words", [
    ({"name": "a,b", "key": "solver.rtol", "values": [1e-6]}, "axes[0]: key 'name': the name \"a,b\" has the character ','"),
    ({"name": "x" * 65, "key": "solver.rtol", "values": [1e-6]}, "is 65 characters long"),
    ({"key": "solver.rtol[0]", "values": [1e-6]}, "axes[0]: key 'key': the name \"rtol[0]\" has the character '['"),
])
def test_axis_names_follow_the_one_name_rule(tmp_path, axis, words):
    with pytest.raises(InputError, match="names are 1 to 64 characters") as e:
        st.load_study(write_spec(tmp_path, [axis]))
    assert words in str(e.value)


def test_study_and_scene_files_follow_the_scene_file_rules(tmp_path):
    with pytest.raises(InputError, match="a character device"):
        st.load_study("/dev/zero")
    spec = json.loads(open(write_spec(tmp_path, AXES)).read())
    spec["scene"] = "/dev/zero"
    (tmp_path / "s.json").write_text(json.dumps(spec))
    with pytest.raises(InputError, match='key "scene": cannot read scene file \'/dev/zero\': it is a character device'):
        st.load_study(str(tmp_path / "s.json"))
    (tmp_path / "nan.json").write_text('{"scene": "x.json", "axes": [{"key": "solver.rtol", "values": [NaN]}]}')
    with pytest.raises(InputError, match="NaN is not a JSON number"):
        st.load_study(str(tmp_path / "nan.json"))


AXIS = [{"key": "drivers[0].law.speed", "values": [100.0]}]


@pytest.mark.parametrize("text,words", [
    # found by the fuzz test: each was a Python traceback, exit 1
    ("[" * 100000 + "]" * 100000, "not valid JSON: arrays or objects nested too deep"),
    ('{"scene": "x.json", "axes": [], "outputs": {"after": -1e400}}', "the number -1e400 is beyond the range of a double"),
    (json.dumps({"axes": AXIS, "outputs": {"summary": "steps"}}), "outputs: key 'summary' must be a list of column names"),
    (json.dumps({"axes": AXIS, "outputs": {"at": [{"column": "slider.x"}]}}), 'outputs.at[0]: key "t" must be a number'),
    (json.dumps({"axes": AXIS, "outputs": {"at": "x"}}), 'outputs: key "at" must be a list'),
    (json.dumps({"axes": AXIS, "combine": "random", "samples": {"count": 2, "seed": [1]}}),
     'key "samples": "seed" must be an integer'),
    (json.dumps({"axes": ["b" * 100000]}), 'axes[0]: must be an object (keys: count, key, name, range, spacing, '
                                           'values), got "bbbbbbbb'),
    (json.dumps({"axes": AXIS, "outputs": None}), "outputs: must be an object (keys: after, at, "),
    (json.dumps({"axes": [{"key": "solver.rtol", "range": [1e-6, 1e-4], "spacing": "l" * 100000}]}),
     'key "spacing" must be "linear" or "log", got "llll'),
    (json.dumps({"axes": AXIS, "k" * 100000: 1}), 'unknown key "kkkk'),
])
def test_damaged_study_files_are_input_errors_on_one_short_line(tmp_path, capsys, text, words):
    if text.startswith("{") and '"scene"' not in text:
        spec = json.loads(text)
        spec["scene"] = os.path.join(SOURCE, "examples", "slider_crank_rigid.json")
        text = json.dumps(spec)
    path = tmp_path / "study.json"
    path.write_text(text)
    assert st.main([str(path), "--out", str(tmp_path / "out"), "--workers", "0", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err
    assert err.count("\n") == 1 and len(err) < 400 and "Traceback" not in err


def test_study_gradients_equal_the_runs_and_the_closed_form(tmp_path):
    # The rigid slider crank (l1 = 1) over two rod lengths l2, with sensitivities to l2 (the
    # rod's end O3 on the rod) and the slider's mass. final(slider.x) by l2 is the closed
    # form l2 / sqrt(l2^2 - sin^2 theta) at t_end (the engine's error ~1e-8 at rtol 1e-8:
    # 1e-6); every gradient column equals the same point's Scene.run with sensitivities, at
    # the row the output was taken from (the same engine path: 1e-15).
    import numpy as np

    import flexmbd

    rod, mass = "joints[2].points[0][0]", "bodies[2].mass"
    spec = {
        "scene": os.path.join(SOURCE, "examples", "slider_crank_rigid.json"),
        "overrides": {"solver": {"t_end": 2.0}},
        "axes": [{"name": "l2", "key": rod, "values": [2.0, 2.5]}],
        "outputs": {"final": ["slider.x"], "max_abs": ["motor.effort"], "summary": ["steps"],
                    "at": [{"column": "slider.x", "t": 1.0, "name": "x_at_1"}]},
        "sensitivities": [rod, mass],
    }
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    study = st.load_study(str(path))
    assert study.output_names[-6:] == [f"dmax_abs(motor.effort)/d{rod}", f"dmax_abs(motor.effort)/d{mass}",
                                       f"dfinal(slider.x)/d{rod}", f"dfinal(slider.x)/d{mass}",
                                       f"dx_at_1/d{rod}", f"dx_at_1/d{mass}"]
    ran, failed = st.run_study(study, str(tmp_path / "out"), workers=0, progress=False)
    assert (ran, failed) == (2, 0)
    header, rows = table(str(tmp_path / "out"))
    col = {name: header.index(name) - (header.index(name) > header.index("wall_seconds")) for name in header}
    for row in rows:
        l2 = float(row[col["l2"]])
        res = flexmbd.load_scene(spec["scene"], {"solver": {"t_end": 2.0}, rod: l2}).run(sensitivities=[rod, mass])
        theta = res["crank.theta"][-1]
        closed = l2 / np.sqrt(l2 ** 2 - np.sin(theta) ** 2)
        assert float(row[col[f"dfinal(slider.x)/d{rod}"]]) == pytest.approx(closed, abs=1e-6)
        effort = res["motor.effort"]
        k = int(np.argmax(np.abs(effort)))
        for p in (rod, mass):
            expected = np.sign(effort[k]) * res.derivative("motor.effort", p)[k]
            assert float(row[col[f"dmax_abs(motor.effort)/d{p}"]]) == pytest.approx(expected, rel=1e-15)
            at = np.interp(1.0, res.t, res.derivative("slider.x", p))
            assert float(row[col[f"dx_at_1/d{p}"]]) == pytest.approx(at, rel=1e-15)
        # the slider's mass moves no position of a driven mechanism: its derivative is zero
        assert float(row[col[f"dfinal(slider.x)/d{mass}"]]) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("value,words", [
    ("bodies[1].mass", 'key "sensitivities" must be a list'),
    ([1], 'key "sensitivities" must be a list'),
    (["bodies[1].mass", "bodies[1].mass"], "given twice"),
])
def test_study_sensitivities_are_checked_before_the_study_runs(tmp_path, value, words):
    spec = {"scene": os.path.join(SOURCE, "examples", "slider_crank_rigid.json"),
            "axes": [{"name": "m", "key": "bodies[2].mass", "values": [1.0]}], "sensitivities": value}
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    with pytest.raises(InputError, match=words):
        st.load_study(str(path))


def test_study_integrals_and_their_adjoint_gradients(tmp_path):
    # The slider crank without its driver (the crank started at 1 rad/s: one degree of
    # freedom) over two rod lengths, with the integral int slider.x^2 dt and its adjoint
    # gradient by the rod length and the slider's mass, next to a forward gradient
    # (final(slider.x)): each point's columns equal its own Scene.run(adjoint=...) and
    # Scene.run(sensitivities=...) (the same engine paths: 1e-15).
    import flexmbd

    rod, mass, out = "joints[2].points[0][0]", "bodies[2].mass", "integral_square:slider.x"
    with open(os.path.join(SOURCE, "examples", "slider_crank_rigid.json")) as f:
        scene = json.load(f)
    del scene["drivers"]
    scene["bodies"][0]["angular_velocity"] = 1.0
    scene["solver"]["t_end"] = 1.0
    (tmp_path / "crank.json").write_text(json.dumps(scene))
    spec = {"scene": "crank.json", "axes": [{"name": "l2", "key": rod, "values": [2.0, 2.5]}],
            "outputs": {"integrals": [out], "final": ["slider.x"]}, "sensitivities": [rod, mass]}
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    study = st.load_study(str(path))
    assert study.output_names == ["final(slider.x)", out, f"dfinal(slider.x)/d{rod}", f"dfinal(slider.x)/d{mass}",
                                  f"d{out}/d{rod}", f"d{out}/d{mass}"]
    assert st.run_study(study, str(tmp_path / "out"), workers=0, progress=False) == (2, 0)
    header, rows = table(str(tmp_path / "out"))
    col = {name: header.index(name) - (header.index(name) > header.index("wall_seconds")) for name in header}
    for row in rows:
        point = dict(scene)
        point["joints"] = json.loads(json.dumps(scene["joints"]))
        point["joints"][2]["points"][0][0] = float(row[col["l2"]])
        adjoint = flexmbd.scene_from_dict(point).run(sensitivities=[rod, mass], adjoint=out)
        forward = flexmbd.scene_from_dict(point).run(sensitivities=[rod, mass])
        integral = adjoint.summary["sensitivities"]["integrals"][out]
        assert float(row[col[out]]) == pytest.approx(integral["value"], rel=1e-15)
        for p in (rod, mass):
            assert float(row[col[f"d{out}/d{p}"]]) == pytest.approx(integral["gradient"][p], rel=1e-15)
            assert float(row[col[f"dfinal(slider.x)/d{p}"]]) == pytest.approx(
                forward.derivative("slider.x", p)[-1], rel=1e-15)


def test_study_integrals_need_sensitivities(tmp_path):
    spec = {"scene": os.path.join(SOURCE, "examples", "slider_crank_rigid.json"),
            "axes": [{"name": "m", "key": "bodies[2].mass", "values": [1.0]}],
            "outputs": {"integrals": ["integral_square:slider.x"]}}
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    with pytest.raises(InputError, match="need the parameters of their gradients"):
        st.load_study(str(path))
    spec["outputs"] = {"integrals": ["maximum:slider.x"]}
    spec["sensitivities"] = ["bodies[2].mass"]
    path.write_text(json.dumps(spec))
    with pytest.raises(InputError, match="is not \"KIND:COLUMN\""):
        st.load_study(str(path))
