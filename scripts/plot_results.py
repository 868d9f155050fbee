#!/usr/bin/python3
"""Plots columns of flexmbd results against time or against another column (PNG).

  /usr/bin/python3 scripts/plot_results.py DIR [DIR ...] [--columns A,B] [--x COLUMN]
      [--out FILE.png] [--labels L1,L2] [--title TEXT] [--deg]

(also run by `flexmbd plot`, which checks the column names first). DIR is the output
directory of `flexmbd run` (DIR/results.csv) or `flexmbd kinematics` (DIR/kinematics.csv).
Every column named in --columns is drawn against --x (default: t, or alpha for
kinematics results); several DIRs draw the same columns of several runs on the same axes
(legend: --labels, else the directory names). Columns with the same unit share a panel;
the units follow from the column names (docs/results.md): m, rad, m/s, rad/s, N, N m,
J, ...; lengths below 1 cm are drawn in mm (below 10 um in um); --deg draws angles in
degrees. Default columns: the position coordinates of the rigid bodies (x, y, theta).
Default output: DIR/plot.png of the first DIR. Prints the path of the PNG written.
Exit status: 0 written; 2 bad arguments, a missing or empty results file, an unknown
column (one line naming close matches); 1 matplotlib missing or the PNG not written.

Needs matplotlib: Debian's python3-matplotlib, installed by scripts/setup.sh for
/usr/bin/python3. Started by another python3 without matplotlib, the script runs
itself again with /usr/bin/python3 (or says what is missing).
"""
import argparse
import csv
import json
import difflib
import math
import os
import re
import sys

PROG = "plot_results"
# Text drawn on the figure (--title, each of --labels): one line; matplotlib fails on a
# 10,000-character title ("raster overflow").
MAX_TEXT_LENGTH = 300
# Largest magnitude drawn: matplotlib's autoscaling overflows near 1e308 (an IndexError in
# its ticker for a column of 1e308); 1e307 and below draw.
MAX_DRAWABLE = 1e300


def fail(message, status=2):
    """One line on stderr, then exit (2: bad input, 1: cannot plot)."""
    prefix = "flexmbd: error: plot" if os.environ.get("FLEXMBD_PLOT_FROM_CLI") else f"{PROG}: error"
    print(f"{prefix}: {' '.join(str(message).split())}", file=sys.stderr)
    sys.exit(status)


# ----- reading -------------------------------------------------------------------------

def results_file(directory):
    for name in ("results.csv", "kinematics.csv"):
        path = os.path.join(directory, name)
        if os.path.isfile(path):
            return path
    if not os.path.isdir(directory):
        fail(f"'{directory}' is not a directory (give the --out DIR of flexmbd run or kinematics)")
    fail(f"{directory} holds neither results.csv nor kinematics.csv")


def read_table(path):
    try:
        with open(path, newline="") as f:
            reader = csv.reader(f)
            header = next(reader, None)
            rows = [r for r in reader if r]
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        fail(f"cannot read {path}: {getattr(e, 'strerror', None) or e}")
    if not header:
        fail(f"{path} is empty (no header)")
    if not rows:
        fail(f"{path} has no rows")
    return header, rows


def close_matches(name, header):
    found = difflib.get_close_matches(name, header, n=5, cutoff=0.8)
    found += [h for h in header if name and (name in h or h in name) and h not in found and len(h) > 1]
    return found[:5]


def check_column(name, header, path):
    if name in header:
        return
    near = close_matches(name, header)
    hint = f"close matches: {', '.join(near)}" if near else \
        f"it has {len(header)} columns: {', '.join(header[:8])}{', ...' if len(header) > 8 else ''}"
    fail(f"{path} has no column '{name}' ({hint})")


def check_text(option, text):
    if len(text) > MAX_TEXT_LENGTH or "\n" in text:
        fail(f"{option} must be one line of at most {MAX_TEXT_LENGTH} characters, got {len(text)} characters")


def check_drawable(name, path, data):
    """Exit 2 naming the column if its values are beyond what matplotlib can draw."""
    largest = max((abs(v) for v in data if math.isfinite(v)), default=0.0)
    if largest > MAX_DRAWABLE:
        fail(f"column '{name}' of {path} has values up to {largest:g} in magnitude: matplotlib cannot draw values "
             f"beyond {MAX_DRAWABLE:g} (leave the column out of --columns / --x)")


def values(header, rows, name):
    k = header.index(name)
    out = []
    for r in rows:
        try:
            out.append(float(r[k]) if k < len(r) else math.nan)
        except ValueError:
            out.append(math.nan)
    return out


# ----- units from the column names (docs/scene-format.md, "Results files") ---------------

COORD_UNITS = {"x": "m", "y": "m", "z": "m", "theta": "rad", "vx": "m/s", "vy": "m/s", "vz": "m/s",
               "ux": "m", "uy": "m", "N": "N", "M": "N m", "fx": "N", "fy": "N", "m": "N m",
               "effort": "N or N m", "force": "N", "tension": "N", "length": "m", "impulse": "N s",
               "slack": "-",
               # spatial joint outputs (docs/scene-format.md, "Results files", item 7)
               "angle": "rad", "angle1": "rad", "angle2": "rad", "displacement": "m", "dx": "m", "dy": "m",
               "rx": "rad", "ry": "rad", "rz": "rad", "omega_x": "rad/s", "omega_y": "rad/s", "omega_z": "rad/s",
               # spatial bodies, reactions, beam section forces and FE stresses
               "uz": "m", "Qy": "N", "Qz": "N", "Mx": "N m", "My": "N m", "Mz": "N m", "fz": "N",
               "mx": "N m", "my": "N m", "mz": "N m", "wx": "rad/s", "wy": "rad/s", "wz": "rad/s",
               "e0": "-", "e1": "-", "e2": "-", "e3": "-",
               "sxx": "Pa", "syy": "Pa", "szz": "Pa", "sxy": "Pa", "syz": "Pa", "szx": "Pa", "von_mises": "Pa"}
DESCRIPTIONS = {"ux": "elastic displacement x", "uy": "elastic displacement y", "N": "axial force",
                "M": "bending moment", "fx": "reaction x", "fy": "reaction y", "m": "reaction moment",
                "effort": "driver effort", "theta": "angle", "theta_dot": "angular velocity",
                "theta_ddot": "angular acceleration", "kinetic": "kinetic energy",
                "potential": "potential energy", "total": "total energy",
                "angle": "joint angle", "displacement": "joint displacement",
                "uz": "elastic displacement z", "Qy": "shear force y", "Qz": "shear force z",
                "Mx": "torsional moment", "My": "bending moment y", "Mz": "bending moment z",
                "fz": "reaction z", "mx": "reaction moment x", "my": "reaction moment y", "mz": "reaction moment z",
                "wx": "angular velocity x (body axes)", "wy": "angular velocity y (body axes)",
                "wz": "angular velocity z (body axes)", "e0": "Euler parameter e0", "e1": "Euler parameter e1",
                "e2": "Euler parameter e2", "e3": "Euler parameter e3", "von_mises": "von Mises stress"}


# Units the run's summary.json gives for columns whose name cannot tell them (a driver's
# effort: "N m" or "N"), filled by read_model_units.
MODEL_UNITS = {}


def read_model_units(directory):
    """The "units" of DIR/summary.json (runs of earlier versions have none)."""
    try:
        with open(os.path.join(directory, "summary.json")) as f:
            units = json.load(f).get("units", {})
    except (OSError, ValueError, AttributeError):
        return
    if isinstance(units, dict):
        MODEL_UNITS.update({k: v for k, v in units.items() if isinstance(v, str)})


def unit_of(name, kinematics):
    """Unit of a results column, or None when it cannot be told from the name."""
    if name == "t":
        return "s"
    if name in MODEL_UNITS:
        return MODEL_UNITS[name]
    if kinematics:
        if name == "alpha":
            return None  # the input parameter, in the unit of the scene's input
        base = name.rpartition(".")[2]
        return {"x": "L", "y": "L", "vx": "L/s", "vy": "L/s", "ax": "L/s²", "ay": "L/s²",
                "angle": "rad", "omega": "rad/s", "omega_dot": "rad/s²"}.get(base)
    prefix, _, coord = name.rpartition(".")
    if prefix == "energy":
        return "J"
    per = ""
    if coord.endswith("_ddot"):
        coord, per = coord[:-5], "/s²"
    elif coord.endswith("_dot"):
        coord, per = coord[:-4], "/s"
    if re.fullmatch(r"q\d+", coord):
        return None  # an elastic coordinate: a displacement, a slope or a modal amplitude
    unit = COORD_UNITS.get(coord)
    if unit == "rad/s" and per == "/s":  # wx_dot: an angular acceleration
        return "rad/s²"
    if unit is None or (per and unit not in ("m", "rad")):
        return None
    return unit + per


# Columns of one unit share a panel while their largest values lie within this factor.
PANEL_MAGNITUDES = 30.0


def same_magnitude(a, others):
    """True when a column of size a (its largest |value|) can share a panel with columns of
    these sizes: within PANEL_MAGNITUDES of each (zero goes with anything)."""
    return all(a == 0.0 or b == 0.0 or max(a, b) <= PANEL_MAGNITUDES * min(a, b) for b in others)


def describe(name):
    if name == "alpha":
        return "alpha (input parameter)"
    coord = name.rpartition(".")[2]
    if re.fullmatch(r"q\d+(_dot|_ddot)?", coord):
        return f"{name} (elastic coordinate)"
    return name


# Lengths are drawn in the largest of these units below which the data stays under 10.
SCALES = {"m": [(1e-2, 1e3, "mm"), (1e-5, 1e6, "µm")], "m/s": [(1e-2, 1e3, "mm/s")],
          "m/s²": [(1e-2, 1e3, "mm/s²")]}
LINE_STYLES = ["-", "--", "-.", ":"]  # one per run: curves that coincide stay visible
DEGREES = {"rad": "deg", "rad/s": "deg/s", "rad/s²": "deg/s²"}


def display_unit(unit, data, deg):
    """(factor, unit shown) for data of the given unit."""
    if unit in DEGREES and deg:
        return 180.0 / math.pi, DEGREES[unit]
    finite = [abs(v) for v in data if math.isfinite(v)]
    peak = max(finite) if finite else 0.0
    factor, shown = 1.0, unit
    for below, f, u in SCALES.get(unit, []):
        if 0 < peak < below:
            factor, shown = f, u
    return factor, shown


def axis_label(names, unit):
    text = ", ".join(describe(n) for n in names)
    if len(names) > 3:  # the legend names them; the label says what they are
        kinds = {DESCRIPTIONS.get(n.rpartition(".")[2], n.rpartition(".")[2]) for n in names}
        text = next(iter(kinds)) if len(kinds) == 1 else f"{len(names)} columns (see the legend)"
        if kinds <= {"x", "y", "z"}:
            text = "positions"
    if len(names) == 1:
        d = DESCRIPTIONS.get(names[0].rpartition(".")[2])
        if d and names[0] != "t":
            text = f"{names[0]}: {d}"
    return f"{text} [{unit}]" if unit and unit != "-" else text


# ----- the figure ----------------------------------------------------------------------

def main(argv):
    p = argparse.ArgumentParser(prog=PROG, usage="%(prog)s DIR [DIR ...] [--columns A,B] [--x COLUMN] "
                                                 "[--out FILE.png] [--labels L1,L2] [--title TEXT] [--deg]")
    p.add_argument("dirs", nargs="+", metavar="DIR")
    p.add_argument("--columns", help="comma-separated columns to draw")
    p.add_argument("--x", dest="x", help="column of the horizontal axis (default t, or alpha)")
    p.add_argument("--out", help="PNG file (default DIR/plot.png of the first DIR)")
    p.add_argument("--labels", help="comma-separated legend labels, one per DIR")
    p.add_argument("--title", help="title of the figure")
    p.add_argument("--deg", action="store_true", help="angles in degrees")
    a = p.parse_args(argv)

    runs = []
    for d in a.dirs:
        path = results_file(d)
        header, rows = read_table(path)
        runs.append((d, path, header, rows, path.endswith("kinematics.csv")))
        read_model_units(d)
    kinematics = runs[0][4]
    if any(r[4] != kinematics for r in runs):
        fail("cannot draw results.csv and kinematics.csv on the same axes")
    xname = a.x or ("alpha" if kinematics else "t")
    if a.columns is not None:
        columns = [c.strip() for c in a.columns.split(",") if c.strip()]
        if not columns:
            fail("--columns names no column")
    else:
        header = runs[0][2]
        columns = [h for h in header if re.fullmatch(r"[^,]+\.(x|y|theta)", h) and
                   h.rpartition(".")[0] + ".theta" in header]
        if not columns:  # a spatial run: the bodies' positions (x, y, z of those with Euler parameters)
            bodies = [h.rpartition(".")[0] for h in header if h.endswith(".e0")]
            columns = [f"{b}.{c}" for b in bodies[:3] for c in ("x", "y", "z") if f"{b}.{c}" in header]
            # and the deflection outputs' elastic displacements (their own panel: other magnitudes)
            columns += [h for h in header if re.fullmatch(r"[^,]+\.(ux|uy|uz)", h)][:3]
        if kinematics:
            columns = [h for h in header if h.endswith(".x") or h.endswith(".y")][:6]
        if not columns:
            fail(f"{runs[0][1]}: no body coordinates to draw by default; name them with --columns")
    for _, path, header, _, _ in runs:
        for c in [xname] + columns:
            check_column(c, header, path)
    labels = [os.path.basename(os.path.normpath(d)) or d for d in a.dirs]
    if a.labels is not None:
        labels = [s.strip() for s in a.labels.split(",")]
        if len(labels) != len(a.dirs):
            fail(f"--labels gives {len(labels)} labels for {len(a.dirs)} directories")
        for label in labels:
            check_text("each of --labels", label)
    if a.title is not None:
        check_text("--title", a.title)
    for _, path, header, rows, _ in runs:
        for c in [xname] + columns:
            check_drawable(c, path, values(header, rows, c))
    out = a.out or os.path.join(a.dirs[0], "plot.png")
    if not out.lower().endswith(".png"):
        fail(f"--out '{out}' must end in .png")

    # The set-up (scripts/setup.sh) installs matplotlib for Debian's /usr/bin/python3; the
    # python3 first on a user's PATH (a virtualenv, conda, pyenv) may lack it. Then the
    # script runs itself again through /usr/bin/python3, or says clearly what is missing.
    try:
        import matplotlib
    except ImportError:
        system_python = "/usr/bin/python3"
        here = os.path.realpath(sys.executable or "")
        if (os.path.exists(system_python) and here != os.path.realpath(system_python)
                and not os.environ.get("FLEXMBD_PLOT_REEXEC")):
            os.environ["FLEXMBD_PLOT_REEXEC"] = "1"
            sys.stderr.flush()
            os.execv(system_python, [system_python, os.path.abspath(__file__)] + argv)
        fail(f"the Python interpreter {sys.executable} has no matplotlib; run scripts/setup.sh (Debian's "
             f"python3-matplotlib for {system_python}) or install matplotlib for it", status=1)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # Panels: one per unit, in the order the columns first name them; within a unit, columns
    # whose sizes differ by more than PANEL_MAGNITUDES (0.2 mm of deflection and 0.3 m of
    # position) go to panels of their own, so that none is drawn as a flat line.
    size = {c: max((abs(v) for _, _, h, rows, _ in runs for v in values(h, rows, c) if math.isfinite(v)),
                   default=0.0) for c in columns}
    largest = {}
    for c in columns:
        largest[unit_of(c, kinematics)] = max(largest.get(unit_of(c, kinematics), 0.0), size[c])
    for c in columns:  # round-off of zero (a planar motion's z) is zero: it joins any panel
        if size[c] <= 1e-9 * largest[unit_of(c, kinematics)]:
            size[c] = 0.0
    panels = []
    for c in columns:
        u = unit_of(c, kinematics)
        key = u if u is not None else f"?{c}"
        for panel in panels:
            if panel[0] == key and same_magnitude(size[c], [size[n] for n in panel[1]]):
                panel[1].append(c)
                break
        else:
            panels.append((key, [c]))

    xunit = unit_of(xname, kinematics)
    xdata = [values(h, rows, xname) for _, _, h, rows, _ in runs]
    xfactor, xshown = display_unit(xunit, [v for xs in xdata for v in xs], a.deg)
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 2.2 + 2.4 * len(panels)), sharex=True, squeeze=False)
    for ax, (key, names) in zip(axes[:, 0], panels):
        unit = None if key.startswith("?") else key
        ydata = {(k, n): values(runs[k][2], runs[k][3], n) for k in range(len(runs)) for n in names}
        yfactor, yshown = display_unit(unit, [v for ys in ydata.values() for v in ys], a.deg)
        for k in range(len(runs)):
            for n in names:
                label = labels[k] if len(names) == 1 else (n if len(runs) == 1 else f"{labels[k]}: {n}")
                ax.plot([x * xfactor for x in xdata[k]], [y * yfactor for y in ydata[(k, n)]],
                        LINE_STYLES[k % len(LINE_STYLES)], lw=1.2, label=label)
        ax.set_ylabel(axis_label(names, yshown))
        ax.grid(True, alpha=0.3)
        if len(runs) > 1 or len(names) > 1:
            ax.legend(fontsize=8, loc="best")
    if xshown == "deg":  # angle ticks at multiples of 90 or 180 degrees
        span = max((abs(v) for xs in xdata for v in xs if math.isfinite(v)), default=0.0) * xfactor
        if span >= 180:
            from matplotlib.ticker import MultipleLocator
            axes[-1, 0].xaxis.set_major_locator(MultipleLocator(90 if span <= 1080 else 180))
    axes[-1, 0].set_xlabel(axis_label([xname], xshown) if xname != "t" else f"t [{xshown}]")
    title = a.title
    if title is None:
        title = ", ".join(a.dirs) if len(a.dirs) > 1 else a.dirs[0]
        if len(title) > MAX_TEXT_LENGTH:
            title = title[:MAX_TEXT_LENGTH - 3] + "..."
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    try:
        os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
        fig.savefig(out, dpi=110)
    except (OSError, ValueError) as e:
        fail(f"cannot write {out}: {getattr(e, 'strerror', None) or e}", status=1)
    plt.close(fig)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
