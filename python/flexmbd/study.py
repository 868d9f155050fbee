"""Parameter studies: one scene run over parameter axes on Dask distributed.

A study file (JSON, docs/python.md "Parameter studies") names a scene, the parameter
axes (a grid, a zipped list, or random samples with a seed) as scene keys to override,
and the values to collect from each run. Points run as Dask tasks (a LocalCluster here,
or any scheduler by address); each returns a small record; records land in
DIR/study.csv as points finish, so an interrupted study keeps what it finished and a
rerun skips those points. Failures are recorded per point, never fatal.

    flexmbd-study examples/study_resonance.json --out out/resonance --workers 2
"""

import argparse
import csv
import importlib
import itertools
import json
import logging
import math
import os
import random
import sys
import time

import numpy as np

from . import InputError, parse_json, read_scene_file, scene_from_dict

FIXED_COLUMNS = ["point", "status", "message", "t_reached", "wall_seconds"]
STUDY_KEYS = {"name", "scene", "overrides", "axes", "combine", "samples", "outputs", "plot", "sensitivities",
              "sensitivity_error_control"}
# the outputs that have a derivative: a value of one row of a results column (the summary's
# keys and user functions have none)
DIFFERENTIABLE_OUTPUTS = ("max_abs", "max", "min", "final")
AXIS_KEYS = {"name", "key", "values", "range", "count", "spacing"}
OUTPUT_KEYS = {"summary", "max_abs", "max", "min", "final", "at", "after", "functions", "integrals"}
# the kinds of an adjoint integral output "KIND:COLUMN" (docs/sensitivities.md)
INTEGRAL_KINDS = ("integral", "integral_square", "ks", "final")
PLOT_KEYS = {"x", "y", "group", "file", "title", "log_x", "log_y"}
PLOT_FILE_TYPES = (".png", ".svg", ".pdf")
MAX_TITLE_LENGTH = 300  # a title is one line over the figure; matplotlib fails on 100 kB ("raster overflow")

# The engine's one rule for names (checkName, scene/json_reader.hpp): axis and output names
# become column names of study.csv and the plot's file name a file in --out.
NAME_RULE = "names are 1 to 64 characters, each an ASCII letter, a digit, '_' or '-'"


def _name_problem(name):
    """"" if name follows NAME_RULE, else what breaks it (as the engine says it)."""
    if not isinstance(name, str):
        return f"is not a string ({json.dumps(name)[:60]})"
    if not name:
        return "is empty"
    for k, c in enumerate(name):
        if not (c.isascii() and (c.isalnum() or c in "_-")):
            return f"has the character {c!r} at position {k + 1}"
    if len(name) > 64:
        return f"is {len(name)} characters long"
    return ""


def _check_name(name, key, where):
    problem = _name_problem(name)
    if problem:
        _fail(where, f"key {key!r}: the name {json.dumps(name)[:60]} {problem} ({NAME_RULE})")


def _shown(value, limit=60, quoted=True):
    """A value as a message shows it: JSON, cut to limit characters (a 100 kB string keeps
    the message one readable line, as the engine's messages)."""
    text = json.dumps(value) if quoted else str(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _check_outputs(outputs, where):
    """The outputs spec's types, before any point runs (a wrong type was a traceback after
    the study ran)."""
    _allow_only(outputs, OUTPUT_KEYS, where)
    for kind in ("summary", "max_abs", "max", "min", "final", "functions"):
        columns = outputs.get(kind, [])
        if not isinstance(columns, list) or not all(isinstance(c, str) for c in columns):
            _fail(where, f"key {kind!r} must be a list of column names, got {_shown(columns)}")
    for c in outputs.get("functions", []):
        if ":" not in c:
            _fail(where, f'key "functions": {_shown(c)} is not "module:function"')
    integrals = outputs.get("integrals", [])
    if not isinstance(integrals, list) or not all(isinstance(c, str) for c in integrals):
        _fail(where, f'key "integrals" must be a list of "KIND:COLUMN", got {_shown(integrals)}')
    for c in integrals:
        if c.partition(":")[0] not in INTEGRAL_KINDS or not c.partition(":")[2]:
            _fail(where, f'key "integrals": {_shown(c)} is not "KIND:COLUMN" with KIND one of {", ".join(INTEGRAL_KINDS)}')
    after = outputs.get("after", 0.0)
    if not isinstance(after, (int, float)) or isinstance(after, bool):
        _fail(where, f'key "after" must be a number (a time), got {_shown(after)}')
    at = outputs.get("at", [])
    if not isinstance(at, list):
        _fail(where, f'key "at" must be a list of {{"column", "t", "name"}}, got {_shown(at)}')
    for i, a in enumerate(at):
        w = f"{where}.at[{i}]"
        _allow_only(a, {"column", "t", "name"}, w)
        if not isinstance(a.get("column"), str):
            _fail(w, f'key "column" must be a column name, got {_shown(a.get("column"))}')
        if not isinstance(a.get("t"), (int, float)) or isinstance(a.get("t"), bool):
            _fail(w, f'key "t" must be a number (a time), got {_shown(a.get("t"))}')
        if "name" in a:
            _check_name(a["name"], "name", w)


def _fail(where, message):
    raise InputError(f"{where}: {message}")


def _allow_only(obj, allowed, where):
    if not isinstance(obj, dict):
        _fail(where, f"must be an object (keys: {', '.join(sorted(allowed))}), got {_shown(obj)}")
    unknown = sorted(set(obj) - allowed)
    if unknown:
        _fail(where, f"unknown key {_shown(unknown[0])} (allowed keys: {', '.join(sorted(allowed))})")


class Study:
    """A parsed study file. ``points``: the parameter values of every point, in order."""

    def __init__(self, spec, path="<study>"):
        where = path
        _allow_only(spec, STUDY_KEYS, where)
        if "scene" not in spec:
            _fail(where, 'key "scene" is required (the scene file, relative to the study file)')
        base = os.path.dirname(os.path.abspath(path)) if path != "<study>" else os.getcwd()
        self.path = path
        self.name = spec.get("name", os.path.splitext(os.path.basename(path))[0])
        if not isinstance(spec["scene"], str) or not spec["scene"]:
            _fail(where, 'key "scene" must be the path of a scene file')
        self.scene_path = os.path.join(base, spec["scene"])
        try:  # the command line's rules: a regular file of at most 64 MiB, strict JSON
            self.scene = parse_json(read_scene_file(self.scene_path), self.scene_path)
        except InputError as e:
            _fail(where, f'key "scene": {e}')
        self.overrides = spec.get("overrides", {})
        if not isinstance(self.overrides, dict):
            _fail(where, 'key "overrides" must be an object of scene keys')
        self.axes = self._parse_axes(spec, where)
        self.points = self._make_points(spec, where)
        self.outputs = spec.get("outputs", {"summary": ["steps", "cpu_seconds"]})
        _check_outputs(self.outputs, where + ": outputs")
        self.sensitivities = spec.get("sensitivities", [])
        if (not isinstance(self.sensitivities, list) or
                not all(isinstance(p, str) and p for p in self.sensitivities)):
            _fail(where, f'key "sensitivities" must be a list of scene paths (strings), got {_shown(self.sensitivities)}')
        if len(set(self.sensitivities)) != len(self.sensitivities):
            _fail(where, 'key "sensitivities": a scene path is given twice')
        self.sensitivity_error_control = spec.get("sensitivity_error_control", True)
        if not isinstance(self.sensitivity_error_control, bool):
            _fail(where, f'key "sensitivity_error_control" must be true or false, got '
                         f'{_shown(self.sensitivity_error_control)}')
        if self.outputs.get("integrals") and not self.sensitivities:
            _fail(where, 'outputs "integrals" need the parameters of their gradients: key "sensitivities" (the '
                         'adjoint run that gives them)')
        self.output_names = output_names(self.outputs) + gradient_names(self.outputs, self.sensitivities)
        self.plot = spec.get("plot")
        if self.plot is not None:
            self._check_plot(where + ": plot")

    def _check_plot(self, where):
        """The plot spec checked against the study's columns before any point runs."""
        spec = self.plot
        _allow_only(spec, PLOT_KEYS, where)
        for k in ("x", "y"):
            if k not in spec:
                _fail(where, f"key {k!r} is required")
        ys = spec["y"] if isinstance(spec["y"], list) else [spec["y"]]
        if not ys:
            _fail(where, 'key "y" must be a column name or a non-empty list of column names, got []')
        text_axes = {a["name"] for a in self.axes if not _numeric(a)}
        columns = self.columns
        for key, c in [("x", spec["x"])] + [("y", y) for y in ys] + ([("group", spec["group"])] if "group" in spec else []):
            if not isinstance(c, str) or c not in columns:
                listed = ", ".join(_shown(x, quoted=False) for x in columns[:20]) + (", ..." if len(columns) > 20 else "")
                _fail(where, f"key {key!r}: no column {_shown(c)} in the study (columns: {listed})")
            if key != "group" and c in text_axes:
                _fail(where, f"key {key!r}: the axis {c!r} has values that are not numbers (expected a numeric "
                             f"column; an axis of strings can be the plot's \"group\")")
        if "title" in spec:
            title = spec["title"]
            if not isinstance(title, str):
                _fail(where, f'key "title" must be a string, got {json.dumps(title)[:60]}')
            if len(title) > MAX_TITLE_LENGTH or "\n" in title:
                _fail(where, f'key "title" must be one line of at most {MAX_TITLE_LENGTH} characters, got '
                             f'{len(title)} characters')
        for k in ("log_x", "log_y"):
            if k in spec and not isinstance(spec[k], bool):
                _fail(where, f"key {k!r} must be true or false, got {json.dumps(spec[k])[:60]}")
        if "file" in spec:
            f = spec["file"]
            stem, ext = os.path.splitext(f) if isinstance(f, str) else (f, "")
            if ext not in PLOT_FILE_TYPES:
                _fail(where, f'key "file" must be a file name ending in {", ".join(PLOT_FILE_TYPES)}, got '
                             f'{json.dumps(f)[:60]}')
            _check_name(stem, "file", where)

    @staticmethod
    def _parse_axes(spec, where):
        axes = spec.get("axes")
        if not isinstance(axes, list) or not axes:
            _fail(where, 'key "axes" must be a non-empty list of axes {"name", "key", "values" | "range"}')
        out = []
        names = set()
        for i, a in enumerate(axes):
            w = f"{where}: axes[{i}]"
            _allow_only(a, AXIS_KEYS, w)
            if "key" not in a:
                _fail(w, 'key "key" is required (the scene key to override, e.g. "drivers[0].law.speed")')
            if not isinstance(a["key"], str):
                _fail(w, f'key "key" must be a scene key path such as "drivers[0].law.speed", got {json.dumps(a["key"])[:60]}')
            # default: the key's last name ("speed" of "drivers[0].law.speed")
            name = a.get("name", a["key"].split("[")[0] if "." not in a["key"] else a["key"].rsplit(".", 1)[1])
            _check_name(name, "name" if "name" in a else "key", w)
            if name in names:
                _fail(w, f"duplicate axis name {name!r} (give each axis its own \"name\")")
            names.add(name)
            if "values" in a:
                values = a["values"]
                if not isinstance(values, list) or not values:
                    _fail(w, 'key "values" must be a non-empty list')
            elif "range" in a:
                r = a["range"]
                if not (isinstance(r, list) and len(r) == 2 and all(isinstance(x, (int, float)) for x in r)):
                    _fail(w, 'key "range" must be [low, high]')
                spacing = a.get("spacing", "linear")
                if spacing not in ("linear", "log"):
                    _fail(w, f'key "spacing" must be "linear" or "log", got {_shown(spacing)}')
                if spacing == "log" and not (r[0] > 0 and r[1] > 0):
                    _fail(w, "a log range needs positive bounds")
                count = a.get("count")
                values = None
                if count is not None:
                    if not isinstance(count, int) or count < 1:
                        _fail(w, 'key "count" must be an integer >= 1')
                    grid = np.geomspace(r[0], r[1], count) if spacing == "log" else np.linspace(r[0], r[1], count)
                    values = [float(x) for x in grid]
            else:
                _fail(w, 'give "values" or "range"')
            out.append({"name": name, "key": a["key"], "values": values, "range": a.get("range"),
                        "spacing": a.get("spacing", "linear")})
        return out

    def _make_points(self, spec, where):
        combine = spec.get("combine", "random" if "samples" in spec else "grid")
        if combine == "random":
            samples = spec.get("samples")
            if not isinstance(samples, dict) or not isinstance(samples.get("count"), int) or samples["count"] < 1:
                _fail(where, 'random studies need "samples": {"count": N, "seed": S}')
            if not isinstance(samples.get("seed", 0), int) or isinstance(samples.get("seed"), bool):
                _fail(where, f'key "samples": "seed" must be an integer, got {_shown(samples["seed"])}')
            rng = random.Random(samples.get("seed", 0))
            points = []
            for _ in range(samples["count"]):
                p = {}
                for a in self.axes:
                    if a["range"] is None:
                        p[a["name"]] = rng.choice(a["values"])
                    elif a["spacing"] == "log":
                        lo, hi = math.log(a["range"][0]), math.log(a["range"][1])
                        p[a["name"]] = math.exp(rng.uniform(lo, hi))
                    else:
                        p[a["name"]] = rng.uniform(*a["range"])
                points.append(p)
            return points
        for a in self.axes:
            if a["values"] is None:
                _fail(where, f'axis {a["name"]!r}: a range needs "count" in a {_shown(combine)} study')
        if combine == "grid":
            return [dict(zip([a["name"] for a in self.axes], combo))
                    for combo in itertools.product(*[a["values"] for a in self.axes])]
        if combine == "zip":
            lengths = {len(a["values"]) for a in self.axes}
            if len(lengths) != 1:
                _fail(where, '"combine": "zip" needs axes of equal length')
            return [dict(zip([a["name"] for a in self.axes], combo)) for combo in zip(*[a["values"] for a in self.axes])]
        _fail(where, f'key "combine" must be "grid", "zip" or "random", got {_shown(combine)}')
        return []

    def overrides_of(self, point):
        """The scene overrides of one point (a dict of axis name to value): the study's
        fixed overrides with each axis's key set to the point's value."""
        o = dict(self.overrides)
        for a in self.axes:
            o[a["key"]] = point[a["name"]]
        return o

    @property
    def columns(self):
        """The columns of study.csv: point, the axes, status and message, the outputs."""
        return ["point"] + [a["name"] for a in self.axes] + FIXED_COLUMNS[1:] + self.output_names


def _numeric(axis):
    """True if every value of the axis is a number (a range always is)."""
    values = axis["values"] if axis["values"] is not None else axis["range"]
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _number(text):
    """A study.csv cell as a float (NaN where it is empty or not a number)."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def load_study(path):
    """The study file at path (read by the scene files' rules: a regular file of at most
    64 MiB, strict JSON), parsed and checked: InputError naming the key otherwise."""
    return Study(parse_json(read_scene_file(path), path), path)


def output_names(outputs):
    """The study.csv column names of a study's "outputs" object, in order: summary.KEY,
    max_abs(COLUMN), max(...), min(...), final(...), the "at" names, the functions."""
    names = [f"summary.{k}" for k in outputs.get("summary", [])]
    for kind in ("max_abs", "max", "min", "final"):
        names += [f"{kind}({c})" for c in outputs.get(kind, [])]
    for i, a in enumerate(outputs.get("at", [])):
        names.append(a.get("name", f"{a['column']}@{a['t']}"))
    for f in outputs.get("functions", []):
        names.append(f)
    names += list(outputs.get("integrals", []))
    return names


def gradient_names(outputs, paths):
    """The study.csv columns of the outputs' derivatives: d<NAME>/d<PATH> for every output
    of a differentiable kind (max_abs, max, min, final, at; in output_names' order) and
    every scene path of "sensitivities", in its order."""
    names = [f"{kind}({c})" for kind in DIFFERENTIABLE_OUTPUTS for c in outputs.get(kind, [])]
    names += [a.get("name", f"{a['column']}@{a['t']}") for a in outputs.get("at", [])]
    names += list(outputs.get("integrals", []))
    return [f"d{n}/d{p}" for n in names for p in paths]


def collect_gradients(results, outputs, paths):
    """The values named by gradient_names(outputs, paths) from a run with sensitivities:
    each output's derivative at the row it was taken from (the first row of the largest
    value; max_abs times the sign of its value), an "at" output's interpolated as the
    output is; NaN where a run ended before a requested time."""
    t = results.t if len(results) else np.array([])
    mask = t >= outputs.get("after", -math.inf) if len(t) else np.array([], dtype=bool)
    values = []
    pick = {"max_abs": lambda x: int(np.argmax(np.abs(x))), "max": lambda x: int(np.argmax(x)),
            "min": lambda x: int(np.argmin(x)), "final": lambda x: len(x) - 1}
    for kind in DIFFERENTIABLE_OUTPUTS:
        for c in outputs.get(kind, []):
            x = results[c][mask] if len(t) else np.array([])
            if not len(x):
                values += [math.nan] * len(paths)
                continue
            k = pick[kind](x)
            sign = float(np.sign(x[k])) if kind == "max_abs" else 1.0
            values += [sign * float(results.derivative(c, p)[mask][k]) for p in paths]
    for a in outputs.get("at", []):
        inside = len(t) and t[0] <= a["t"] <= t[-1]
        values += [float(np.interp(a["t"], t, results.derivative(a["column"], p))) if inside else math.nan
                   for p in paths]
    return values


def collect(results, outputs):
    """The values named by output_names(outputs) from a run's Results (NaN where a run
    ended before a requested time)."""
    values = [results.summary.get(k) for k in outputs.get("summary", [])]
    t = results.t if len(results) else np.array([])
    mask = t >= outputs.get("after", -math.inf) if len(t) else np.array([], dtype=bool)

    def column(c):
        return results[c][mask] if len(t) else np.array([])

    for kind, fn in (("max_abs", lambda x: np.max(np.abs(x))), ("max", np.max), ("min", np.min),
                     ("final", lambda x: x[-1])):
        for c in outputs.get(kind, []):
            x = column(c)
            values.append(float(fn(x)) if len(x) else math.nan)
    for a in outputs.get("at", []):
        if len(t) and t[0] <= a["t"] <= t[-1]:
            values.append(float(np.interp(a["t"], t, results[a["column"]])))
        else:
            values.append(math.nan)
    for spec in outputs.get("functions", []):
        module, _, name = spec.partition(":")
        values.append(float(getattr(importlib.import_module(module), name)(results)))
    return values


def _needs_forward(outputs):
    """Whether a study's outputs have gradients only forward sensitivities give."""
    return any(outputs.get(kind) for kind in DIFFERENTIABLE_OUTPUTS + ("at",))


def run_point(index, scene, overrides, outputs, names, sensitivities=(), sensitivity_error_control=True):
    """One point (a Dask task): a small record, whatever happens in the run. With
    ``sensitivities`` (scene paths) the run integrates the derivatives too and the record
    holds the outputs' gradients after the outputs (gradient_names); the "integrals"
    outputs and their gradients come from a run with the adjoint (the only run of the
    point when no other output has a gradient)."""
    start = time.perf_counter()
    record = {"point": index, "status": "ok", "message": "", "t_reached": math.nan}
    results = adjoint = None
    integrals = list(outputs.get("integrals", []))
    try:
        point = scene_from_dict(scene, overrides, source=f"point {index}")
        if integrals:
            adjoint = point.run(raise_on_failure=False, sensitivities=list(sensitivities), adjoint=integrals)
        if sensitivities and (_needs_forward(outputs) or not integrals):
            results = point.run(raise_on_failure=False, sensitivities=list(sensitivities),
                                sensitivity_error_control=sensitivity_error_control, adjoint=[])
        elif adjoint is not None:
            results = adjoint  # the table of a plain run, and the integrals
        else:
            # the study's own sensitivities only, not the scene's "sensitivity" key
            results = point.run(raise_on_failure=False, sensitivities=[], adjoint=[])
        if adjoint is not None and not adjoint.ok:
            results = adjoint
        record["status"] = "ok" if results.ok else "failed"
        record["message"] = "" if results.ok else results.message
        tr = results.summary.get("t_reached")
        record["t_reached"] = tr if tr is not None else math.nan
    except InputError as e:
        record["status"] = "input_error"
        record["message"] = str(e)
    except Exception as e:  # noqa: BLE001  (a point's failure is recorded, never fatal)
        record["status"] = "error"
        record["message"] = f"{type(e).__name__}: {e}"
    values = [math.nan] * len(names)
    if results is not None and record["status"] == "ok":
        try:
            values = collect(results, outputs)
            values += [adjoint.summary["sensitivities"]["integrals"][c]["value"] for c in integrals]
            if sensitivities:
                values += collect_gradients(results, outputs, sensitivities)
                values += [adjoint.gradient(c)[p] for c in integrals for p in sensitivities]
        except Exception as e:  # noqa: BLE001
            record["status"] = "error"
            record["message"] = f"outputs: {type(e).__name__}: {e}"
    record["wall_seconds"] = time.perf_counter() - start
    record["values"] = values
    return record


class TableWriter:
    """DIR/study.csv: the header, then one row per finished point, flushed as written;
    a rerun reads the points already there (resume)."""

    def __init__(self, path, columns):
        self.path, self.columns = path, columns
        self.done = {}
        if os.path.exists(path):
            with open(path, newline="", encoding="utf-8") as f:
                rows = list(csv.reader(f))
            if rows and rows[0] != columns:
                raise InputError(f"{path} holds another study (its columns differ); use another --out or delete it")
            for r in rows[1:]:
                if len(r) == len(columns):
                    self.done[int(r[0])] = r
            self.file = open(path, "a", newline="", encoding="utf-8")
        else:
            self.file = open(path, "w", newline="", encoding="utf-8")
            csv.writer(self.file).writerow(columns)
            self.file.flush()
        self.writer = csv.writer(self.file)

    def write(self, row):
        """Appends one point's row (floats written exactly, repr) and flushes."""
        self.writer.writerow([repr(x) if isinstance(x, float) else x for x in row])
        self.file.flush()

    def close(self):
        """Closes study.csv."""
        self.file.close()


class Progress:
    """Points done, failed, rate and time left on stderr: one updated line on a
    terminal, else a line every tenth of the study."""

    def __init__(self, total, done, stream=sys.stderr):
        self.total, self.done, self.failed, self.stream = total, done, 0, stream
        self.start, self.ran = time.perf_counter(), 0
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self.every = max(1, total // 10)

    def update(self, status):
        """Counts one finished point of the given status ("ok" or a failure) and shows the line."""
        self.done += 1
        self.ran += 1
        self.failed += status != "ok"
        elapsed = time.perf_counter() - self.start
        rate = self.ran / elapsed if elapsed > 0 else math.inf
        left = (self.total - self.done) / rate if rate > 0 else math.inf
        line = (f"study: {self.done}/{self.total} points, {self.failed} failed, "
                f"{rate:.2f} points/s, ~{left:.0f} s left")
        if self.tty:
            self.stream.write("\r" + line + "   ")
        elif self.ran % self.every == 0 or self.done == self.total:
            self.stream.write(line + "\n")
        self.stream.flush()

    def finish(self):
        """Ends the progress line (a newline on a terminal)."""
        if self.tty:
            self.stream.write("\n")
        self.stream.flush()


def run_study(study, out_dir, scheduler=None, workers=None, progress=True):
    """Runs the points not yet in out_dir/study.csv. ``workers == 0``: serially in this
    process; else on Dask: the scheduler at ``scheduler`` (an address) or a LocalCluster
    of ``workers`` processes (default: the machine's cores). Returns (ran, failed)."""
    os.makedirs(out_dir, exist_ok=True)
    table = TableWriter(os.path.join(out_dir, "study.csv"), study.columns)
    todo = [i for i in range(len(study.points)) if i not in table.done]
    prog = Progress(len(study.points), len(study.points) - len(todo), sys.stderr if progress else open(os.devnull, "w"))
    failed = 0
    input_errors = []  # the messages of the points that failed on input

    def write(record):
        nonlocal failed
        p = study.points[record["point"]]
        row = [record["point"]] + [p[a["name"]] for a in study.axes]
        row += [record["status"], record["message"], record["t_reached"], record["wall_seconds"]] + record["values"]
        table.write(row)
        failed += record["status"] != "ok"
        if record["status"] == "input_error":
            input_errors.append(record["message"])
        prog.update(record["status"])

    args = lambda i: (i, study.scene, study.overrides_of(study.points[i]), study.outputs, study.output_names,  # noqa: E731
                      study.sensitivities, study.sensitivity_error_control)
    try:
        if workers == 0 and scheduler is None:
            for i in todo:
                write(run_point(*args(i)))
        else:
            from dask.distributed import Client, LocalCluster, as_completed  # noqa: PLC0415

            cluster = None
            if scheduler is None:
                n = workers or os.cpu_count() or 1
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                       silence_logs=logging.ERROR)
            client = Client(scheduler or cluster)
            try:
                futures = [client.submit(run_point, *args(i), pure=False) for i in todo]
                index = {f.key: i for f, i in zip(futures, todo)}
                for future in as_completed(futures):
                    try:
                        record = future.result()
                    except Exception as e:  # noqa: BLE001  (a worker died: recorded)
                        record = {"point": index[future.key], "status": "error",
                                  "message": f"{type(e).__name__}: {e}", "t_reached": math.nan,
                                  "wall_seconds": math.nan, "values": [math.nan] * len(study.output_names)}
                    write(record)
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
    finally:
        prog.finish()
        table.close()
    if todo and len(input_errors) == len(todo):
        # every point refused its input: the study itself is wrong (an axis key that names
        # nothing, a value of the wrong kind), not one point's value
        raise InputError(f"{study.path}: every point failed on input ({len(todo)} of {len(todo)}; their rows are in "
                         f"study.csv), e.g. {input_errors[0]}")
    return len(todo), failed


def read_table(path):
    """study.csv as (columns, rows of strings)."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def plot(study, out_dir):
    """The study's "plot": y columns against x, one line per value of "group"; a PNG."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    spec = study.plot
    columns, rows = read_table(os.path.join(out_dir, "study.csv"))
    ys = spec["y"] if isinstance(spec["y"], list) else [spec["y"]]
    if columns != study.columns:  # checked with the study: only another file in its place differs
        raise InputError(f"{study.path}: plot: study.csv holds other columns than the study's")
    col = {c: k for k, c in enumerate(columns)}
    ok = [r for r in rows if r[col["status"]] == "ok"]
    if "group" in spec:  # numbers in numeric order, other values (an axis of strings) as categories
        values = {r[col[spec["group"]]] for r in ok}
        numeric = all(not math.isnan(_number(v)) for v in values)
        groups = sorted(values, key=_number if numeric else str)
    else:
        numeric, groups = True, [None]
    fig, axes = plt.subplots(len(ys), 1, figsize=(8, 3.2 * len(ys)), sharex=True, squeeze=False)
    for ax, y in zip(axes[:, 0], ys):
        for g in groups:
            sel = sorted((r for r in ok if g is None or r[col[spec["group"]]] == g), key=lambda r: _number(r[col[spec["x"]]]))
            label = None if g is None else f"{spec['group']} = {_number(g):g}" if numeric else f"{spec['group']} = {g}"
            ax.plot([_number(r[col[spec["x"]]]) for r in sel], [_number(r[col[y]]) for r in sel], marker="o", ms=3,
                    label=label)
        ax.set_ylabel(y)
        ax.grid(True, alpha=0.3)
        if spec.get("log_x"):
            ax.set_xscale("log")
        if spec.get("log_y"):
            ax.set_yscale("log")
        if groups != [None]:
            ax.legend(fontsize=8)
    axes[-1, 0].set_xlabel(spec["x"])
    title = spec.get("title", study.name)
    fig.suptitle(title if len(title) <= MAX_TITLE_LENGTH else title[:MAX_TITLE_LENGTH - 3] + "...")
    fig.tight_layout()
    out = os.path.join(out_dir, spec.get("file", "study.png"))
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def main(argv=None):
    """The flexmbd-study command: runs the study file given in argv (default sys.argv)
    into --out DIR; returns the exit status: 2 for an input error (named on stderr), else 0."""
    p = argparse.ArgumentParser(prog="flexmbd-study", description="Run a parameter study of a flexmbd scene.")
    p.add_argument("study", help="the study file (JSON)")
    p.add_argument("--out", required=True, help="output directory: study.csv (resumed if present), the plot")
    p.add_argument("--scheduler", help="a running Dask scheduler's address (tcp://host:8786); default: a LocalCluster")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: the cores); 0: serially here")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    a = p.parse_args(argv)
    try:
        if a.workers is not None and a.workers < 0:
            raise InputError(f"option --workers must be >= 0, got {a.workers}")
        study = load_study(a.study)
        ran, failed = run_study(study, a.out, a.scheduler, a.workers, progress=not a.quiet)
        print(f"flexmbd-study: {len(study.points)} points in {os.path.join(a.out, 'study.csv')} "
              f"({ran} run now, {failed} of them not ok)")
        if study.plot:
            print(f"flexmbd-study: plot in {plot(study, a.out)}")
    except InputError as e:
        print(f"flexmbd-study: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
