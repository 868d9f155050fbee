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
