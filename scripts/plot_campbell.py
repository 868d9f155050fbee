#!/usr/bin/python3
"""Draws the Campbell diagram of `flexmbd modes --sweep` (PNG).

  /usr/bin/python3 scripts/plot_campbell.py DIR/campbell.csv --out DIR/campbell.png [--title TEXT]

campbell.csv (written by flexmbd modes, docs/modes.md): column `speed` (rad/s), then
`f<k>_hz` and `zeta<k>` for the modes k = 1..N at each speed. Upper panel: the
frequencies (Hz) against the speed with the excitation line 1x (speed / 2 pi); lower
panel: the damping ratios (a negative one is an instability). Exit status: 0 written;
2 a missing or malformed file; 1 matplotlib missing or the PNG not written.
Needs matplotlib (Debian's python3-matplotlib, installed by scripts/setup.sh).
"""
import argparse
import csv
import math
import os
import sys

PROG = "plot_campbell"


def fail(message, status=2):
    prefix = "flexmbd: error: modes" if os.environ.get("FLEXMBD_PLOT_FROM_CLI") else f"{PROG}: error"
    print(f"{prefix}: {' '.join(str(message).split())}", file=sys.stderr)
    sys.exit(status)


def read(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    if len(rows) < 2 or not rows[0] or rows[0][0] != "speed":
        fail(f"{path} is not a campbell.csv (header 'speed,f1_hz,...' and at least one row)")
    header = rows[0]
    data = {name: [] for name in header}
    for r in rows[1:]:
        for name, value in zip(header, r):
            try:
                data[name].append(float(value))
            except ValueError:
                data[name].append(math.nan)
    return header, data


def main():
    ap = argparse.ArgumentParser(prog=PROG, description="Campbell diagram of flexmbd modes --sweep")
    ap.add_argument("csv")
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="Campbell diagram")
    a = ap.parse_args()
    header, data = read(a.csv)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("matplotlib is missing (Debian: apt-get install python3-matplotlib)", 1)
    speed = data["speed"]
    freqs = [h for h in header if h.startswith("f") and h.endswith("_hz")]
    zetas = [h for h in header if h.startswith("zeta")]
    fig, (ax, az) = plt.subplots(2, 1, figsize=(8, 7), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    for h in freqs:
        ax.plot(speed, data[h], "o-", ms=3, label=h[:-3])
    ax.plot(speed, [abs(s) / (2 * math.pi) for s in speed], "k--", lw=1, label="1x speed")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(a.title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    for h in zetas:
        az.plot(speed, data[h], "o-", ms=3)
    az.axhline(0.0, color="k", lw=0.8)
    # at least +-0.05: the rounding noise (~1e-13) of undamped models reads as zero
    lo, hi = az.get_ylim()
    az.set_ylim(min(lo, -0.05), max(hi, 0.05))
    az.set_ylabel("damping ratio")
    az.set_xlabel("speed (rad/s)")
    az.grid(True, alpha=0.3)
    fig.tight_layout()
    try:
        fig.savefig(a.out, dpi=120)
    except OSError as e:
        fail(f"cannot write {a.out}: {e.strerror}", 1)
    print(a.out)


if __name__ == "__main__":
    main()
