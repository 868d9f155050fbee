#!/usr/bin/env python3
"""Prints a compact table of a flexmbd run: python3 scripts/print_table.py DIR

Reads DIR/results.csv and DIR/summary.json (written by `flexmbd run ... --out DIR`) and
prints every 5th output row (and the last): t, crank angle, slider x, slider x_dot and,
for the rigid slider-crank of examples/slider_crank_rigid.json, the exact slider
position of the closed form x = l1 cos a + sqrt(l2^2 - l1^2 sin^2 a) (l1 = 1, l2 = 2,
a = crank.theta) with the relative error of the computed one; then the run statistics.
Columns that a scene does not have are left out. Standard library only.
"""
import csv
import json
import math
import os
import sys

from slider_crank_reference import slider_x  # scripts/slider_crank_reference.py

L1, L2 = 1.0, 2.0  # crank and rod lengths of the example (source document 000)
EVERY = 5

WANTED = [("t", "t"), ("crank.theta", "crank angle"), ("slider.x", "slider x"),
          ("slider.x_dot", "slider x_dot")]

SUMMARY_KEYS = ["status", "message", "t_reached", "steps", "residual_evals", "jacobian_evals",
                "nonlinear_iterations", "error_test_failures", "linear_setups", "cpu_seconds",
                "max_position_violation", "max_velocity_violation", "energy_start", "energy_end",
                "formulation", "linear_solver", "rtol", "atol"]


def exact_slider_x(a):
    return slider_x(L1, L2, a)


def to_float(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def print_results(path):
    if not os.path.exists(path):
        print(f"(no {path})")
        return
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        rows = [r for r in reader if r]
    if not header:
        print(f"({path} is empty)")
        return
    index = {name: k for k, name in enumerate(header)}
    cols = [(name, label) for name, label in WANTED if name in index]
    with_exact = "crank.theta" in index and "slider.x" in index
    labels = [label for _, label in cols] + (["exact x", "rel. error"] if with_exact else [])
    if not cols:
        print(f"{path}: none of the columns {', '.join(n for n, _ in WANTED)} "
              f"(it has: {', '.join(header[:12])}{', ...' if len(header) > 12 else ''})")
        return
    width = 18
    print("".join(f"{label:>{width}}" for label in labels))
    print("-" * (width * len(labels)))
    picked = [k for k in range(len(rows)) if k % EVERY == 0 or k == len(rows) - 1]
    max_err = 0.0
    for k, row in enumerate(rows):
        if with_exact:
            x = to_float(row[index["slider.x"]]) if index["slider.x"] < len(row) else math.nan
            exact = exact_slider_x(to_float(row[index["crank.theta"]]))
            err = abs(x - exact) / abs(exact) if exact != 0 else abs(x - exact)
            if not math.isnan(err):
                max_err = max(max_err, err)
        if k not in picked:
            continue
        cells = [f"{to_float(row[index[name]]) if index[name] < len(row) else math.nan:>{width}.11g}"
                 for name, _ in cols]
        if with_exact:
            cells += [f"{exact:>{width}.11g}", f"{err:>{width}.3e}"]
        print("".join(cells))
    print(f"{len(rows)} output rows ({len(picked)} shown)", end="")
    if with_exact:
        print(f"; max relative error of slider x over all rows: {max_err:.3e}")
    else:
        print()


def print_summary(path):
    if not os.path.exists(path):
        print(f"(no {path})")
        return
    try:
        with open(path) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        print(f"({path}: cannot read: {e})")
        return
    print()
    print("summary:")
    keys = [k for k in SUMMARY_KEYS if k in summary] + \
           [k for k in summary if k not in SUMMARY_KEYS]
    for key in keys:
        value = summary[key]
        if value is None:
            text = "-"
        elif isinstance(value, float):
            text = f"{value:.6g}"
        else:
            text = str(value)
        print(f"  {key:<28} {text}")


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip().splitlines()[0], file=sys.stderr)
        return 2
    out_dir = argv[1]
    print_results(os.path.join(out_dir, "results.csv"))
    print_summary(os.path.join(out_dir, "summary.json"))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        sys.exit(0)
