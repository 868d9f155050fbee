#!/usr/bin/python3
"""Figures of source document 000 from `flexmbd kinematics` results (kinematics.csv).

  /usr/bin/python3 scripts/plot_kinematics.py --slider DIR1 --four-bar DIR2 --out FIGDIR
      [--slider-node O3] [--four-bar-node O3] [--l1 1 --l2 2]

writes FIGDIR/slider_crank.png (Fig. 5: the slider's x position, velocity and
acceleration against the crank angle; with --l1/--l2 the exact eqs. 30-32 are drawn
over the computed points), FIGDIR/four_bar_velocity.png (Fig. 7) and
FIGDIR/four_bar_acceleration.png (Fig. 8): the velocity and acceleration vectors of the
node at every step, drawn from its position on its path. Either input may be omitted.
Needs matplotlib: Debian's python3-matplotlib, installed by scripts/setup.sh for
/usr/bin/python3. Started by another python3 without matplotlib, the script runs
itself again with /usr/bin/python3 (or says what is missing).
"""
import argparse
import csv
import math
import os
import sys

# The set-up (scripts/setup.sh) installs matplotlib for Debian's /usr/bin/python3; the
# python3 first on a user's PATH (a virtualenv, conda, pyenv) may lack it. Then the
# script runs itself again through /usr/bin/python3, or says clearly what is missing.
SYSTEM_PYTHON = "/usr/bin/python3"
try:
    import matplotlib
except ImportError:
    here = os.path.realpath(sys.executable or "")
    if (os.path.exists(SYSTEM_PYTHON) and here != os.path.realpath(SYSTEM_PYTHON)
            and not os.environ.get("FLEXMBD_PLOT_REEXEC")):
        os.environ["FLEXMBD_PLOT_REEXEC"] = "1"
        print(f"plot_kinematics: {sys.executable} has no matplotlib; running with {SYSTEM_PYTHON}",
              file=sys.stderr)
        os.execv(SYSTEM_PYTHON, [SYSTEM_PYTHON, os.path.abspath(__file__)] + sys.argv[1:])
    sys.exit(f"plot_kinematics: the Python interpreter {sys.executable} has no matplotlib. "
             f"Run the script with {SYSTEM_PYTHON} after scripts/setup.sh (which installs "
             f"Debian's python3-matplotlib), or install matplotlib for this interpreter.")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from slider_crank_reference import slider_x, slider_dx_da, slider_d2x_da2  # noqa: E402


def read(directory):
    path = os.path.join(directory, "kinematics.csv")
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"plot_kinematics: cannot read {path}: {e.strerror}")
    if not rows:
        sys.exit(f"plot_kinematics: {path} has no rows")
    return rows


def column(rows, name):
    if name not in rows[0]:
        sys.exit(f"plot_kinematics: no column '{name}' (is the node name right?)")
    return [float(r[name]) for r in rows]


def slider_figure(rows, node, l1, l2, out):
    alpha = column(rows, "alpha")
    deg = [math.degrees(a) for a in alpha]
    quantities = [(f"{node}.x", "x [length]", "(a) x coordinate"),
                  (f"{node}.vx", "velocity [length/s]", "(b) velocity in x"),
                  (f"{node}.ax", "acceleration [length/s$^2$]", "(c) acceleration in x")]
    fig, axes = plt.subplots(3, 1, figsize=(7, 9), sharex=True)
    for ax, (name, label, title) in zip(axes, quantities):
        ax.plot(deg, column(rows, name), "o", ms=3.5, label="flexmbd kinematics")
        if l1 and l2:
            fine = [i * 2 * math.pi / 720 for i in range(721)]
            formula = {f"{node}.x": slider_x, f"{node}.vx": slider_dx_da, f"{node}.ax": slider_d2x_da2}[name]
            exact = [formula(l1, l2, a) for a in fine]  # eqs. 30-32 (scripts/slider_crank_reference.py)
            ax.plot([math.degrees(a) for a in fine], exact, "-", lw=1, label="exact, eqs. 30-32")
        ax.set_ylabel(label)
        ax.set_title(title, fontsize=10, loc="left")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("crank angle alpha [deg]  (alphadot = 1 rad/s, alphaddot = 0)")
    axes[-1].set_xticks(range(0, 361, 60))
    fig.suptitle(f"Slider-crank: node {node} (source document 000, Fig. 5)")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def vector_figure(rows, node, kind, out):
    """Left: the node's path with its vectors at every other step; right: the vector
    diagram proper, every step's vector drawn from one origin (tips joined: hodograph)."""
    x, y = column(rows, f"{node}.x"), column(rows, f"{node}.y")
    deg = [math.degrees(a) for a in column(rows, "alpha")]
    u, v = (column(rows, f"{node}.vx"), column(rows, f"{node}.vy")) if kind == "velocity" else \
        (column(rows, f"{node}.ax"), column(rows, f"{node}.ay"))
    colour = "tab:blue" if kind == "velocity" else "tab:red"
    unit = "length/s" if kind == "velocity" else "length/s$^2$"
    pivots = []
    for name in rows[0]:
        if name.endswith(".x") and name[:-2] != node and name[:-2] + ".y" in rows[0]:
            xs, ys = column(rows, name), column(rows, name[:-2] + ".y")
            if max(xs) == min(xs) and max(ys) == min(ys):
                pivots.append((xs[0], ys[0]))
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 6.5))

    mags = [math.hypot(a, b) for a, b in zip(u, v)]
    span = max(max(x) - min(x), max(y) - min(y), 1e-12)
    scale = max(mags) / (0.25 * span) if max(mags) > 0 else 1.0
    left.plot(x, y, "-", color="0.6", lw=1, label=f"path of {node}")
    idx = range(0, len(x), 2)
    left.quiver([x[i] for i in idx], [y[i] for i in idx], [u[i] for i in idx], [v[i] for i in idx],
                angles="xy", scale_units="xy", scale=scale, width=0.003, color=colour)
    left.plot(x[0], y[0], "ko", ms=4, label="alpha = 0")
    for px, py in pivots:
        left.plot(px, py, "k^", ms=9)
    xs = x + [a + b / scale for a, b in zip(x, u)] + [p[0] for p in pivots]
    ys = y + [a + b / scale for a, b in zip(y, v)] + [p[1] for p in pivots]
    pad = 0.05 * span
    left.set_xlim(min(xs) - pad, max(xs) + pad)
    left.set_ylim(min(ys) - pad, max(ys) + pad)
    left.set_aspect("equal")
    left.grid(True, alpha=0.3)
    left.set_title(f"{node} on its path, every 2nd step\n(arrow of length {0.25 * span:.3g} = {max(mags):.3g} {unit})",
                   fontsize=10)
    left.set_xlabel("x")
    left.set_ylabel("y")
    left.legend(fontsize=8, loc="best")

    right.quiver([0] * len(u), [0] * len(v), u, v, angles="xy", scale_units="xy", scale=1, width=0.003,
                 color=colour, alpha=0.8)
    right.plot(u + [u[0]], v + [v[0]], "-", color="0.3", lw=0.8)
    for i in range(0, len(u), 5):
        right.annotate(f"{deg[i]:.0f}", (u[i], v[i]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    m = 1.1 * max(mags)
    right.set_xlim(-m, m)
    right.set_ylim(-m, m)
    right.set_aspect("equal")
    right.grid(True, alpha=0.3)
    right.axhline(0, color="k", lw=0.5)
    right.axvline(0, color="k", lw=0.5)
    comp = "v" if kind == "velocity" else "a"
    right.set_xlabel(f"{comp}x [{unit}]")
    right.set_ylabel(f"{comp}y [{unit}]")
    right.set_title(f"{kind} vector diagram of {node} (labels: crank angle, deg)", fontsize=10)
    fig.suptitle(f"Four-bar: {kind} of node {node}, alphadot = 1 rad/s, alphaddot = 0 "
                 f"(source document 000, Fig. {7 if kind == 'velocity' else 8})")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--slider", help="output directory of the slider-crank run")
    p.add_argument("--four-bar", dest="four_bar", help="output directory of the four-bar run")
    p.add_argument("--out", required=True, help="directory for the PNG files")
    p.add_argument("--slider-node", default="O3")
    p.add_argument("--four-bar-node", default="O3")
    p.add_argument("--l1", type=float, help="crank length, to draw eqs. 30-32")
    p.add_argument("--l2", type=float, help="rod length, to draw eqs. 30-32")
    a = p.parse_args()
    if not a.slider and not a.four_bar:
        p.error("give --slider DIR and/or --four-bar DIR")
    os.makedirs(a.out, exist_ok=True)
    if a.slider:
        out = os.path.join(a.out, "slider_crank.png")
        slider_figure(read(a.slider), a.slider_node, a.l1, a.l2, out)
        print(out)
    if a.four_bar:
        rows = read(a.four_bar)
        for kind in ("velocity", "acceleration"):
            out = os.path.join(a.out, f"four_bar_{kind}.png")
            vector_figure(rows, a.four_bar_node, kind, out)
            print(out)


if __name__ == "__main__":
    main()
