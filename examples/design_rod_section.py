#!/usr/bin/env python3
"""The lightest rod section of the elastic slider crank whose midpoint deflection stays
below a bound: gradient-based (SciPy's SLSQP on the engine's forward sensitivities)
against a grid study (flexmbd.study), docs/sensitivities.md "Design example".

The rod of examples/slider_crank_elastic.json (steel, 0.30 m, pinned-pinned FFR beam,
crank 0.15 m at 150 rad/s, one revolution from an undeformed rod):

    minimise   m(w, h) = rho L w h                        (the rod's mass)
    subject to D(w, h) = max_k |mid.uy(t_k)| <= BOUND     (over one revolution's outputs)
               w, h within WIDTH_BOUNDS, HEIGHT_BOUNDS

with the section's width w (out of the plane) and height h (in the plane of bending) as
the scene paths bodies[1].section.width and .height. The constraint's gradient is
summary["sensitivities"]["max_abs"]["mid.uy"]["gradient"] of one run with sensitivities
(or, with --aggregate ks, a Kreisselmeier-Steinhauser aggregate of the deflection column
made from its derivative columns); the objective's is analytic.

    PYTHONPATH=build/python /usr/bin/python3 examples/design_rod_section.py [--mode both|optimise|grid]
        [--workers N] [--out DIR] [--aggregate max_abs|ks] [--constraint linear|log]
"""

import argparse
import json
import math
import os
import sys
import tempfile
import time

import numpy as np
from scipy.optimize import minimize

import flexmbd
import flexmbd.study

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "slider_crank_elastic.json")
WIDTH = "bodies[1].section.width"
HEIGHT = "bodies[1].section.height"
PARAMETERS = [WIDTH, HEIGHT]
DEFLECTION = "mid.uy"

# The bound on the peak midpoint deflection over one revolution (m): the peak of the
# scene's own 8 mm x 8 mm rod, rounded down (see docs/sensitivities.md): a lighter rod
# deflects more, so the lightest admissible rod sits on the bound (the constraint is
# active) and the scene's section is just not admissible.
BOUND = 1.5e-3
WIDTH_BOUNDS = (0.004, 0.012)   # m
HEIGHT_BOUNDS = (0.004, 0.012)  # m
START = (0.008, 0.008)          # the scene's section

# Overrides for every run, optimiser and grid alike (the same model, so the same optimum):
# outputs 8 times as dense as the scene's (576 per revolution). The peak is taken over the
# outputs; at the scene's 72 per revolution the sampled peak of the rod's vibration jumps
# as the section changes (which output lands nearest the crest; up to 1.4 % below the
# dense peak), a
# non-smooth constraint that made SLSQP wander; at 576 it varies smoothly with h (measured
# over h = 8.5-9.5 mm in steps of 0.05 mm at w = 4 mm, docs/sensitivities.md).
SETTINGS = {"solver.output_step": 0.00058177641733144 / 8}

MM = 1.0e-3  # the optimiser's variables are millimetres (values of order 1-10)


def rod_mass(scene_dict, width, height):
    """The rod's mass rho L w h (kg) of the scene dict's rod with this section."""
    rod = scene_dict["bodies"][1]
    return rod["section"]["density"] * rod["beam"]["length"] * width * height


def ks_aggregate(values, derivatives, rho):
    """The Kreisselmeier-Steinhauser aggregate of max_k |values_k| over +values and -values,
    (1/rho) log sum_k (exp(rho u_k) + exp(-rho u_k)), and its gradient from the
    derivative columns (derivatives: one array per parameter). A smooth upper bound of
    the largest |u_k|, above it by at most log(2 n) / rho for n outputs."""
    u = np.asarray(values, dtype=float)
    top = float(np.max(np.abs(u)))
    ep, em = np.exp(rho * (u - top)), np.exp(rho * (-u - top))
    total = float(np.sum(ep + em))
    value = top + math.log(total) / rho
    weights = (ep - em) / total
    return value, [float(np.dot(weights, d)) for d in derivatives]


class RodDesign:
    """The design problem: the scene with SETTINGS, the bound, and a counter of the engine
    runs. ``evaluate(w, h)`` runs the scene once with sensitivities to both section
    dimensions (cached: SciPy asks for the constraint and its Jacobian at the same point)."""

    def __init__(self, scene_path=SCENE, settings=None, bound=BOUND, aggregate="max_abs", ks_rho=None,
                 width=None):
        self.scene = flexmbd.parse_json(flexmbd.read_scene_file(scene_path), scene_path)
        self.scene = flexmbd.apply_overrides(self.scene, SETTINGS if settings is None else settings)
        # width=None: both dimensions are design variables; a number: the width held there
        # and the height alone designed (one sensitivity per run)
        self.fixed_width = width
        self.parameters = PARAMETERS if width is None else [HEIGHT]
        self.bound = bound
        self.aggregate = aggregate
        # KS: rho such that its overshoot log(2 n) / rho is 1 % of the bound for n outputs
        self.ks_rho = ks_rho
        self.runs = 0
        self.run_seconds = 0.0
        self.history = []
        self._cache = {}

    def mass(self, width, height):
        """The rod's mass (kg)."""
        return rod_mass(self.scene, width, height)

    def evaluate(self, width, height):
        """(peak deflection D in m, {path: dD/dp in m/m}) at the section (w, h) in m: one
        engine run with sensitivities to the design's parameters, unless this point was run
        already."""
        key = (float(width), float(height))
        if key in self._cache:
            return self._cache[key]
        scene = flexmbd.scene_from_dict(self.scene, {WIDTH: key[0], HEIGHT: key[1]}, source="design point")
        start = time.perf_counter()
        res = scene.run(sensitivities=self.parameters, sensitivity_error_control=False)
        self.run_seconds += time.perf_counter() - start
        self.runs += 1
        if self.aggregate == "ks":
            u = res[DEFLECTION]
            rho = self.ks_rho or math.log(2 * len(u)) / (0.01 * self.bound)
            value, derivatives = ks_aggregate(u, [res.derivative(DEFLECTION, p) for p in self.parameters], rho)
            gradient = dict(zip(self.parameters, derivatives))
        else:
            peak = res.summary["sensitivities"]["max_abs"][DEFLECTION]
            value, gradient = peak["value"], {p: peak["gradient"][p] for p in self.parameters}
        self.history.append((key[0], key[1], value))
        self._cache = {key: (value, gradient)}
        return value, gradient


# SLSQP's ftol on the mass in grams: the peak deflection of a run at the scene's rtol 1e-6
# is known to about 1e-6 of itself, which moves the height on the bound by about 1/4 of
# that (D falls roughly as h^-4) and the mass by ~2e-5 g; a ftol below it has the line
# search chase the integration's noise (measured: 1e-6 g took 18 runs of the one-variable
# problem where 1e-4 g takes 8, to the same height within 1e-9 m).
FTOL_GRAMS = 1e-4


def optimise(design, start=START, tolerance=FTOL_GRAMS, max_iterations=30, constraint="linear"):
    """SLSQP on the section in millimetres: the mass (grams) with its analytic gradient,
    the constraint 1 - D / bound >= 0 with the engine's gradient, or with
    ``constraint="log"`` log(bound / D) >= 0 (D falls roughly as a power of h, so its
    logarithm is nearly linear in h: SLSQP's linearisation holds further; on the
    two-variable problem it took 37 runs instead of 19, creeping along w = 4 mm). Variables (w, h), or h
    alone when the design holds the width fixed. Returns a dict of the optimum (width,
    height in m, mass in kg, peak deflection), SciPy's status, iterations and the engine
    runs and wall time it took."""
    runs0, t0 = design.runs, time.perf_counter()
    both = design.fixed_width is None

    def section(x):
        return (x[0] * MM, x[1] * MM) if both else (design.fixed_width, x[0] * MM)

    def grams(x):
        return 1e3 * design.mass(*section(x))

    def grams_gradient(x):
        w, h = section(x)
        g = 1e3 * design.mass(1.0, 1.0) * MM  # d(grams)/d(x in mm) = rho L (the other dimension) 1e3 mm
        return np.array([g * h, g * w]) if both else np.array([g * w])

    def margin(x):
        value, _ = design.evaluate(*section(x))
        return np.array([math.log(design.bound / value) if constraint == "log" else 1.0 - value / design.bound])

    def margin_gradient(x):
        value, gradient = design.evaluate(*section(x))
        scale = value if constraint == "log" else design.bound
        return np.array([[-gradient[p] * MM / scale for p in design.parameters]])

    bounds = [WIDTH_BOUNDS, HEIGHT_BOUNDS] if both else [HEIGHT_BOUNDS]
    x0 = np.array(start if both else start[1:]) / MM
    result = minimize(grams, x0, jac=grams_gradient, method="SLSQP",
                      bounds=[(b[0] / MM, b[1] / MM) for b in bounds],
                      constraints=[{"type": "ineq", "fun": margin, "jac": margin_gradient}],
                      options={"ftol": tolerance, "maxiter": max_iterations})
    width, height = section(result.x)
    peak, _ = design.evaluate(width, height)
    return {"width": float(width), "height": float(height), "mass": design.mass(width, height),
            "peak": float(peak), "success": bool(result.success), "message": result.message,
            "iterations": int(result.nit), "runs": design.runs - runs0, "wall": time.perf_counter() - t0}


def grid_study(design, widths, heights, out_dir, workers=0):
    """The same problem on the grid widths x heights by flexmbd.study (a study of the
    scene with the design's settings, plain runs, output max_abs(mid.uy)): the lightest
    point whose peak deflection is within the bound. Returns a dict of that point (None
    values if no point is feasible), the table (width, height, peak, mass) and the runs
    and wall time."""
    t0 = time.perf_counter()
    scene_file = os.path.join(out_dir, "scene.json")
    with open(scene_file, "w", encoding="utf-8") as f:
        json.dump(design.scene, f)
    spec = {"name": "rod-section-grid", "scene": "scene.json",
            "axes": [{"name": "width", "key": WIDTH, "values": [float(w) for w in widths]},
                     {"name": "height", "key": HEIGHT, "values": [float(h) for h in heights]}],
            "outputs": {"max_abs": [DEFLECTION]}}
    study = flexmbd.study.Study(spec, os.path.join(out_dir, "study.json"))
    ran, failed = flexmbd.study.run_study(study, out_dir, workers=workers, progress=False)
    columns, rows = flexmbd.study.read_table(os.path.join(out_dir, "study.csv"))
    c = {name: k for k, name in enumerate(columns)}
    table = []
    for r in rows:
        w, h = float(r[c["width"]]), float(r[c["height"]])
        peak = float(r[c[f"max_abs({DEFLECTION})"]]) if r[c["status"]] == "ok" else math.nan
        table.append({"width": w, "height": h, "peak": peak, "mass": design.mass(w, h), "status": r[c["status"]]})
    table.sort(key=lambda p: (p["width"], p["height"]))
    feasible = [p for p in table if p["peak"] <= design.bound]
    best = min(feasible, key=lambda p: p["mass"]) if feasible else {"width": None, "height": None, "mass": None,
                                                                     "peak": None}
    return {**best, "table": table, "runs": ran, "failed": failed, "wall": time.perf_counter() - t0}


def linear_grid(bounds, count):
    """count values from bounds[0] to bounds[1], evenly spaced."""
    return list(np.linspace(bounds[0], bounds[1], count))


def main(argv=None):
    """The command line: optimise, grid or both, and a comparison printed."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mode", choices=["both", "optimise", "grid"], default="both")
    parser.add_argument("--aggregate", choices=["max_abs", "ks"], default="max_abs")
    parser.add_argument("--constraint", choices=["linear", "log"], default="linear",
                        help="SLSQP's constraint: 1 - D / bound or log(bound / D)")
    parser.add_argument("--widths", type=int, default=3, help="grid values of the width")
    parser.add_argument("--heights", type=int, default=17, help="grid values of the height")
    parser.add_argument("--workers", type=int, default=0, help="Dask workers of the grid (0: serially here)")
    parser.add_argument("--out", default=None, help="the grid study's folder (default: a temporary one)")
    args = parser.parse_args(argv)

    design = RodDesign(aggregate=args.aggregate)
    print(f"bound on max |{DEFLECTION}| over one revolution: {design.bound * 1e3:.4g} mm; "
          f"width {WIDTH_BOUNDS[0] * 1e3:g}-{WIDTH_BOUNDS[1] * 1e3:g} mm, "
          f"height {HEIGHT_BOUNDS[0] * 1e3:g}-{HEIGHT_BOUNDS[1] * 1e3:g} mm")
    opt = grid = None
    if args.mode in ("both", "optimise"):
        opt = optimise(design, constraint=args.constraint)
        for k, (w, h, value) in enumerate(design.history):
            print(f"  run {k + 1}: width {w * 1e3:.4f} mm, height {h * 1e3:.4f} mm, {args.aggregate} {value * 1e3:.5f} mm")
        print(f"SLSQP ({args.aggregate}): width {opt['width'] * 1e3:.4f} mm, height {opt['height'] * 1e3:.4f} mm, "
              f"mass {opt['mass'] * 1e3:.3f} g, peak deflection {opt['peak'] * 1e3:.5f} mm; "
              f"{opt['iterations']} iterations, {opt['runs']} runs with 2 sensitivities, {opt['wall']:.1f} s "
              f"({opt['message']})")
    if args.mode in ("both", "grid"):
        widths, heights = linear_grid(WIDTH_BOUNDS, args.widths), linear_grid(HEIGHT_BOUNDS, args.heights)
        with tempfile.TemporaryDirectory() as tmp:
            out = args.out or tmp
            os.makedirs(out, exist_ok=True)
            grid = grid_study(design, widths, heights, out, workers=args.workers)
        for p in grid["table"]:
            print(f"  grid: width {p['width'] * 1e3:6.3f} mm, height {p['height'] * 1e3:6.3f} mm, "
                  f"mass {p['mass'] * 1e3:8.3f} g, peak {p['peak'] * 1e3:.5f} mm"
                  f"{'' if p['peak'] <= design.bound else '  (above the bound)'}")
        if grid["mass"] is None:
            print(f"grid ({args.widths} x {args.heights}): no feasible point; {grid['runs']} runs, {grid['wall']:.1f} s")
        else:
            print(f"grid ({args.widths} x {args.heights}): width {grid['width'] * 1e3:.4f} mm, height "
                  f"{grid['height'] * 1e3:.4f} mm, mass {grid['mass'] * 1e3:.3f} g, peak {grid['peak'] * 1e3:.5f} mm; "
                  f"{grid['runs']} plain runs, {grid['wall']:.1f} s")
    if opt and grid and grid["mass"] is not None:
        print(f"optimum {opt['mass'] * 1e3:.3f} g in {opt['runs']} runs with sensitivities ({opt['wall']:.1f} s) "
              f"against the grid's {grid['mass'] * 1e3:.3f} g in {grid['runs']} plain runs ({grid['wall']:.1f} s): "
              f"{100 * (grid['mass'] - opt['mass']) / grid['mass']:.2f} % lighter")
    return 0


if __name__ == "__main__":
    sys.exit(main())
