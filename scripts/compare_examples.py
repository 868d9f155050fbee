#!/usr/bin/env python3
"""Runs every example scene and compares two such sets of results: the check of a change
that must not alter behaviour (a refactoring) against the build before it.

  scripts/compare_examples.py run FLEXMBD OUT        every examples/*.json into OUT/<name>/
  scripts/compare_examples.py compare BEFORE AFTER   every results file, column by column

A scene runs through the subcommand it is for: `kinematics` for a linkage (nodes, no bodies),
`run` for the rest (tensegrity scenes included), and the examples made for `modes` also
through `flexmbd modes`; a study file (a "scene" and "axes") is
left out: its points are runs of a scene that is compared on its own. `compare` reads
every *.csv of each pair of folders and prints, per file, the largest difference of a
column relative to that column's largest magnitude; it fails (exit 1) where a file or
column is missing or a difference exceeds --tolerance (default 1e-9: round-off of a
result that went through a different order of the same operations).
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(os.path.dirname(HERE), "examples")


# the examples made for `flexmbd modes`, with the options their docs give
MODES = {"modes_blade": ["--count", "3", "--steady", "--sweep", "motor:0:60:4"],
         "spinning_blade": [], "rayleigh_rotor": []}


def subcommand(scene):
    if "axes" in scene and "scene" in scene:
        return None
    if scene.get("model") == "tensegrity":
        return "run"
    if "nodes" in scene and "bodies" not in scene:  # a linkage of document 000
        return "kinematics"
    return "run"


def run_all(flexmbd, out):
    os.makedirs(out, exist_ok=True)
    status = 0
    for name in sorted(os.listdir(EXAMPLES)):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(EXAMPLES, name)) as f:
            scene = json.load(f)
        command = subcommand(scene)
        stem = name[:-5]
        if command is None:
            print(f"{stem}: a study, left out (its scene is compared on its own)")
            continue
        target = os.path.join(out, stem)
        t0 = time.monotonic()
        done = subprocess.run([flexmbd, command, os.path.join(EXAMPLES, name), "--out", target, "--quiet"],
                              capture_output=True, text=True)
        print(f"{stem}: flexmbd {command}, exit {done.returncode}, {time.monotonic() - t0:.1f} s")
        with open(os.path.join(out, stem + ".exit"), "w") as f:
            f.write(f"{done.returncode}\n{done.stderr}")
        if stem in MODES:
            done = subprocess.run([flexmbd, "modes", os.path.join(EXAMPLES, name), "--out", target + "_modes",
                                   "--quiet"] + MODES[stem], capture_output=True, text=True)
            print(f"{stem}: flexmbd modes, exit {done.returncode}")
            with open(os.path.join(out, stem + "_modes.exit"), "w") as f:
                f.write(f"{done.returncode}\n{done.stderr}")
    return status


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns = {}
    for j, name in enumerate(header):
        values = []
        for row in body:
            try:
                values.append(float(row[j]))
            except (ValueError, IndexError):
                values.append(row[j] if j < len(row) else None)
        columns[name] = values
    return columns


def column_difference(a, b):
    """Largest |a - b| relative to max |a| (1 where a and b differ in length or text)."""
    if len(a) != len(b):
        return math.inf
    scale, diff = 0.0, 0.0
    for x, y in zip(a, b):
        if isinstance(x, float) and isinstance(y, float):
            if math.isnan(x) or math.isnan(y):
                if not (math.isnan(x) and math.isnan(y)):
                    return math.inf
                continue
            scale = max(scale, abs(x))
            diff = max(diff, abs(x - y))
        elif x != y:
            return math.inf
    return diff / scale if scale > 0 else diff


def compare(before, after, tolerance):
    failures = 0
    for stem in sorted(os.listdir(before)):
        if stem.endswith(".exit"):
            with open(os.path.join(before, stem)) as f:
                a = f.readline().strip()
            other = os.path.join(after, stem)
            b = open(other).readline().strip() if os.path.exists(other) else "missing"
            if a != b:
                print(f"{stem[:-5]}: exit {a} before, {b} after")
                failures += 1
            continue
        folder = os.path.join(before, stem)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            if not name.endswith(".csv"):
                continue
            other = os.path.join(after, stem, name)
            if not os.path.exists(other):
                print(f"{stem}/{name}: missing after")
                failures += 1
                continue
            ca, cb = read_columns(os.path.join(folder, name)), read_columns(other)
            worst, worst_column = 0.0, ""
            for column, values in ca.items():
                d = column_difference(values, cb[column]) if column in cb else math.inf
                if d > worst:
                    worst, worst_column = d, column
            if set(cb) - set(ca):
                worst, worst_column = math.inf, "new columns " + ",".join(sorted(set(cb) - set(ca)))
            rows = len(next(iter(ca.values()))) if ca else 0
            verdict = "ok" if worst <= tolerance else "DIFFERS"
            print(f"{stem}/{name}: {rows} rows, {len(ca)} columns, largest relative difference "
                  f"{worst:.3g}{' (' + worst_column + ')' if worst_column else ''}: {verdict}")
            failures += worst > tolerance
    print(f"{failures} differences above {tolerance:g}" if failures else "every result agrees")
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run")
    r.add_argument("flexmbd")
    r.add_argument("out")
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--tolerance", type=float, default=1e-9)
    a = parser.parse_args()
    if a.what == "run":
        return run_all(a.flexmbd, a.out)
    return compare(a.before, a.after, a.tolerance)


if __name__ == "__main__":
    sys.exit(main())
