"""scripts/plot_results.py (flexmbd plot): the units it reads from spatial column names,
and how it parts columns of one unit into panels by their size (a spatial run's
0.2 mm deflection and 0.3 m positions on one axis drew the deflection as a flat line).

Run by CTest as part of python_bindings (tests/CMakeLists.txt).
"""
import importlib.util
import os

import pytest

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


@pytest.fixture(scope="module")
def plot():
    spec = importlib.util.spec_from_file_location("plot_results", os.path.join(SOURCE, "scripts", "plot_results.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("column, unit", [
    ("crank.z", "m"), ("crank.wx", "rad/s"), ("crank.wz_dot", "rad/s²"), ("crank.z_ddot", "m/s²"),
    ("rod_mid.uz", "m"), ("rod_mid.Qy", "N"), ("rod_mid.Mx", "N m"), ("pin.fz", "N"), ("pin.mz", "N m"),
    ("crank.e0", "-"), ("probe.von_mises", "Pa"), ("probe.szx", "Pa"), ("energy.total", "J"),
])
def test_spatial_columns_have_their_units(plot, column, unit):
    assert plot.unit_of(column, False) == unit


def test_columns_of_one_unit_share_a_panel_only_within_a_factor_of_30(plot):
    assert plot.same_magnitude(0.3, [0.15, 0.6])
    assert not plot.same_magnitude(2e-4, [0.3])  # a deflection beside positions: its own panel
    assert plot.same_magnitude(0.0, [0.3])        # zero (a planar motion's z) joins any panel
    assert plot.same_magnitude(0.3, [])


def test_a_spatial_run_is_drawn_by_default(plot, tmp_path):
    # the bodies' positions and the deflection outputs: two panels of metres
    cli = os.environ.get("FLEXMBD_CLI")
    if not cli:
        pytest.skip("FLEXMBD_CLI not set (CTest sets it)")
    out = tmp_path / "run"
    assert os.system(f"'{cli}' run '{SOURCE}/examples/spatial_slider_crank_elastic.json' --out '{out}' "
                     f"--t-end 0.02 --quiet > /dev/null 2>&1") == 0
    assert plot.main([str(out)]) in (0, None)
    assert (out / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("driver, unit", [("motor", "N m"), ("push", "N")])
def test_a_driver_effort_has_the_unit_of_what_it_drives(plot, tmp_path, driver, unit):
    # summary.json's "units": a body_theta driver's effort is a torque, a body_x driver's a
    # force (the axis once said "N or N m")
    import json
    cli = os.environ.get("FLEXMBD_CLI")
    if not cli:
        pytest.skip("FLEXMBD_CLI not set (CTest sets it)")
    scene = json.load(open(os.path.join(SOURCE, "examples", "slider_crank_rigid.json")))
    if driver == "push":  # drive the slider instead of the crank, away from the dead point
        import math
        theta = 1.0
        x = math.cos(theta) + math.sqrt(4.0 - math.sin(theta) ** 2)  # l1 = 1, l2 = 2
        scene["bodies"][0]["angle"] = theta
        scene["bodies"][1]["position"] = [math.cos(theta), math.sin(theta)]
        scene["bodies"][1]["angle"] = -math.asin(math.sin(theta) / 2.0)
        scene["bodies"][2]["position"] = [x, 0.0]
        scene["drivers"] = [{"name": "push", "type": "body_x", "body": "slider",
                             "law": {"type": "constant_speed", "speed": -0.1, "initial": x}}]
    scene["solver"]["t_end"] = 0.5
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    out = tmp_path / "run"
    assert os.system(f"'{cli}' run '{path}' --out '{out}' --quiet > /dev/null 2>&1") == 0
    assert json.load(open(out / "summary.json"))["units"] == {f"{driver}.effort": unit}
    plot.MODEL_UNITS.clear()
    assert plot.unit_of(f"{driver}.effort", False) == "N or N m"  # a run without "units" (earlier versions)
    plot.read_model_units(str(out))
    assert plot.unit_of(f"{driver}.effort", False) == unit
