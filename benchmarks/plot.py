#!/usr/bin/python3
"""Figures from the benchmark CSV files (run with Debian's /usr/bin/python3, which has
python3-matplotlib):

  work_precision_<group>.png  error against CPU time, log-log, one line per model
                              (bench_work_precision.csv: IDA; bench_work_precision_radau5.csv:
                              Radau IIA, dashed), ends labelled with rtol
  variants_<scene>.png        time ratios to the default variant (bench_variants.csv)
  scaling.png                 time per step against the DAE size, log-log, with the
                              least-squares exponent from --fit-from elements up
                              (bench_scaling.csv)
  scaling_fixed_accuracy.png  time per simulated second at a fixed midpoint-deflection
                              accuracy against the number of elements, per integrator,
                              with least-squares exponents (bench_scaling_fixed_accuracy.csv)
  bari_crank.png              Simeon's slider crank: CPU time against significant
                              correct digits, one line per configuration, with the
                              classic codes' published figures (bench_bari_crank.csv)

usage: /usr/bin/python3 benchmarks/plot.py [--in-dir DIR] [--out-dir DIR] [--fit-from N]
Missing CSV files are skipped with a message.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    """Rows as dicts; lines starting with '#' are skipped (comments)."""
    if not os.path.exists(path):
        print(f"plot.py: {path} not found, skipped")
        return None
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def num(s):
    try:
        v = float(s)
        return v if math.isfinite(v) else None
    except (TypeError, ValueError):
        return None


def work_precision(rows, out_dir):
    groups = []
    for r in rows:
        if r["group"] not in groups:
            groups.append(r["group"])
    written = []
    for g in groups:
        fig, ax = plt.subplots(figsize=(7, 5))
        models = []
        for r in rows:
            if r["group"] == g and r["model"] not in models:
                models.append(r["model"])
        reference = ""
        for m in models:
            pts = [(num(r["seconds"]), num(r["error"]), r["rtol"]) for r in rows
                   if r["group"] == g and r["model"] == m and r.get("ok", "1") == "1"]
            pts = [p for p in pts if p[0] and p[1]]
            if not pts:
                continue
            reference = next(r["reference"] for r in rows if r["group"] == g)
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "s--" if "Radau" in m else "o-", label=m)
            for t, e, rtol in (pts if len(pts) <= 2 else [pts[0], pts[-1]]):  # loosest and tightest rtol
                ax.annotate(rtol, (t, e), textcoords="offset points", xytext=(4, 3), fontsize=7)
        ax.set_xlabel("CPU time [s] (wall time of the run)")
        ax.set_ylabel("max position error / characteristic length")
        ax.set_title(f"work-precision: {g}\nreference: {reference}", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        path = os.path.join(out_dir, f"work_precision_{g}.png")
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    return written


def scaling_fixed_accuracy(rows, out_dir):
    fig, ax = plt.subplots(figsize=(7, 5))
    kinds = []
    for r in rows:
        if r["integrator"] not in kinds:
            kinds.append(r["integrator"])
    for k in kinds:
        pts = [(num(r["elements"]), num(r["seconds_per_unit_time"])) for r in rows if r["integrator"] == k]
        pts = [p for p in pts if p[0] and p[1]]
        if not pts:
            continue
        label = k
        if len(pts) >= 2:
            xs = [math.log(p[0]) for p in pts]
            ys = [math.log(p[1]) for p in pts]
            mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
            b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
            label += f" (exponent {b:.2f})"
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=label)
    ax.set_xlabel("rod elements")
    ax.set_ylabel("CPU seconds per simulated second")
    ax.set_title("elastic slider crank, midpoint deflection within 1e-4 (relative)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    path = os.path.join(out_dir, "scaling_fixed_accuracy.png")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]


def variants(rows, out_dir):
    written = []
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    for s in scenes:
        sub = [r for r in rows if r["scene"] == s]
        fig, ax = plt.subplots(figsize=(7, 0.45 * len(sub) + 1.5))
        names = [r["variant"] for r in sub]
        ratios = [num(r["time_ratio"]) or 0.0 for r in sub]
        ax.barh(range(len(sub)), ratios, color=["C0" if i == 0 else "C1" for i in range(len(sub))])
        ax.set_yticks(range(len(sub)))
        ax.set_yticklabels(names, fontsize=8)
        ax.invert_yaxis()
        ax.axvline(1.0, color="k", lw=0.8)
        for i, v in enumerate(ratios):
            ax.text(v, i, f" {v:.2f}", va="center", fontsize=8)
        ax.set_xlabel("median time ratio to the default (round-robin repeats)")
        ax.set_title(f"variants: {s} (rtol {sub[0]['rtol']})", fontsize=10)
        path = os.path.join(out_dir, f"variants_{s}.png")
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    return written


def scaling(rows, out_dir, fit_from):
    pts = [(int(r["elements"]), num(r["dae_size"]), num(r["seconds_per_step"])) for r in rows]
    pts = [p for p in pts if p[1] and p[2]]
    if not pts:
        return []
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.loglog([p[1] for p in pts], [1e6 * p[2] for p in pts], "o-", label="time per step")
    for n, size, t in pts:
        ax.annotate(f"{n} el.", (size, 1e6 * t), textcoords="offset points", xytext=(4, -10), fontsize=7)
    fit = [p for p in pts if p[0] >= fit_from]
    title = "elastic slider-crank, nodal rod, rtol 1e-6, KLU"
    if len(fit) >= 2:
        xs = [math.log(p[1]) for p in fit]
        ys = [math.log(p[2]) for p in fit]
        n = len(xs)
        mx, my = sum(xs) / n, sum(ys) / n
        b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        a = my - b * mx
        x0, x1 = min(p[1] for p in fit), max(p[1] for p in fit)
        ax.loglog([x0, x1], [1e6 * math.exp(a + b * math.log(x0)), 1e6 * math.exp(a + b * math.log(x1))], "--",
                  label=f"least squares from {fit_from} elements: ~ size^{b:.2f}")
        title += f"\nexponent {b:.2f} (target <= 1.15)"
    ax.set_xlabel("unknowns (DAE size)")
    ax.set_ylabel("time per step [µs]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    path = os.path.join(out_dir, "scaling.png")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]


# CPU ms of the classic codes to reach scd 3, 5, 7 on this machine kind
# (shared/benchmarks/simeon-slider-crank.md): drawn as markers for comparison.
CLASSIC = {"MEBDFI": (4.5, 16.9, 28.4), "RADAU5 (Fortran)": (11.2, 53.8, 112),
           "DASSL": (12.3, 44.1, 117)}


def bari_crank(rows, out_dir):
    fig, ax = plt.subplots(figsize=(7, 5))
    configs = []
    for r in rows:
        if r["config"] not in configs:
            configs.append(r["config"])
    for c in configs:
        pts = [(num(r["scd"]), num(r["cpu_ms"])) for r in rows if r["config"] == c and r.get("ok", "1") == "1"]
        pts = [p for p in pts if p[0] is not None and p[1]]
        if pts:
            ax.semilogy([p[0] for p in pts], [p[1] for p in pts], "o-", label=c, markersize=4)
    for name, ms in CLASSIC.items():
        ax.semilogy([3, 5, 7], ms, "x--", label=name + " (published run)", alpha=0.6)
    ax.set_xlabel("significant correct digits (positions at t = 0.1)")
    ax.set_ylabel("CPU time [ms]")
    ax.set_title("Simeon's flexible slider crank: work-precision")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    path = os.path.join(out_dir, "bari_crank.png")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--in-dir", default=".", help="directory of the CSV files (default: .)")
    p.add_argument("--out-dir", default=os.path.join(here, "figures"), help="PNG directory (default: benchmarks/figures)")
    p.add_argument("--fit-from", type=int, default=16, help="smallest mesh of the scaling fit (default 16)")
    a = p.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    written = []
    rows = read_csv(os.path.join(a.in_dir, "bench_work_precision.csv")) or []
    radau = read_csv(os.path.join(a.in_dir, "bench_work_precision_radau5.csv")) or []
    for r in radau:
        r["model"] += " (Radau IIA)"
    if rows or radau:
        written += work_precision(rows + radau, a.out_dir)
    rows = read_csv(os.path.join(a.in_dir, "bench_scaling_fixed_accuracy.csv"))
    if rows:
        written += scaling_fixed_accuracy(rows, a.out_dir)
    rows = read_csv(os.path.join(a.in_dir, "bench_variants.csv"))
    if rows:
        written += variants(rows, a.out_dir)
    rows = read_csv(os.path.join(a.in_dir, "bench_scaling.csv"))
    if rows:
        written += scaling(rows, a.out_dir, a.fit_from)
    rows = read_csv(os.path.join(a.in_dir, "bench_bari_crank.csv"))
    if rows:
        written += bari_crank(rows, a.out_dir)
    for w in written:
        print("wrote", w)
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
