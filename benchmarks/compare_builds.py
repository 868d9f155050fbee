#!/usr/bin/python3
"""Planar benchmark figures of two builds, runs alternating (old, new, new, old, ...).

Runs, per round and build: bench_rigid_slider_crank --repeat 3, bench_elastic_slider_crank
--repeat 1, bench_micro (residual and Jacobian benchmarks only) and bench_kinematics;
parses their tables and prints, per figure, the median over the rounds of each build,
the ratio new/old of the medians, the median of the per-round ratios, and whether the
machine-independent counters (steps, residuals, Jacobians) are the same in both builds.
The binaries report wall times; the CPU time (user + system) of the whole run of
bench_rigid_slider_crank and bench_elastic_slider_crank (fixed work) is added, less
sensitive to a loaded machine.

    /usr/bin/python3 benchmarks/compare_builds.py --old ../wt-bench-old/build --new build \
        --rounds 10 [--callgrind] [--out results/compare.md]

--callgrind adds the instructions per residual and per Jacobian (reused scratch) of four
models, counted by callgrind: deterministic, unlike the times on a shared machine.

The builds need the targets bench_rigid_slider_crank, bench_elastic_slider_crank,
bench_micro and bench_kinematics; their source files must be the same in both trees
(the comparison is of the library they link). Run from the repository root (the
benchmarks find their scenes by the source path compiled in).
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile


CPU = {}  # binary name -> CPU seconds (user + system) of its last run


def run(cmd, cwd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(["nice"] + cmd, cwd=cwd, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        sys.stderr.write(out.stdout + out.stderr)
        raise SystemExit(f"{' '.join(cmd)} failed ({out.returncode})")
    CPU[os.path.basename(cmd[0])] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return out.stdout


def rigid(build, tmp):
    """Figures of bench_rigid_slider_crank: run time per variant [ms], residual/Jacobian [us]."""
    text = run([os.path.join(build, "benchmarks", "bench_rigid_slider_crank"), "--repeat", "3", "--out-dir", tmp], tmp)
    times, counters = {}, {}
    for line in text.splitlines():
        m = re.match(r"^(\S+/\S+/\S+)\s+(\S+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\S+)\s", line)
        if m:
            key = f"rigid crank {m.group(1)} rtol {m.group(2)}: run [ms]"
            times[key] = float(m.group(7))
            counters[key] = (m.group(3), m.group(4), m.group(5))
    m = re.search(r"dense ([\d.]+) ms \((\d+) steps\), KLU ([\d.]+) ms \((\d+) steps\)", text)
    if m:
        times["pendulum 100 s dense: run [ms]"] = float(m.group(1))
        times["pendulum 100 s KLU: run [ms]"] = float(m.group(3))
        counters["pendulum 100 s dense: run [ms]"] = (m.group(2),)
        counters["pendulum 100 s KLU: run [ms]"] = (m.group(4),)
    for label, pat in [("rigid crank residual, scratch per call [us]", r"one residual evaluation:\s+([\d.]+)"),
                       ("rigid crank Jacobian sparse, scratch per call [us]", r"Jacobian evaluation \(sparse\):\s+([\d.]+)"),
                       ("rigid crank Jacobian dense, scratch per call [us]", r"Jacobian evaluation \(dense\):\s+([\d.]+)")]:
        m = re.search(pat, text)
        if m:
            times[label] = float(m.group(1))
    return times, counters


def elastic(build, tmp):
    text = run([os.path.join(build, "benchmarks", "bench_elastic_slider_crank"), "--repeat", "1", "--out-dir", tmp], tmp)
    times, counters = {}, {}
    for line in text.splitlines():
        m = re.match(r"^(\d+)\s+(nodal|\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+([\d.]+)\s", line)
        if m:
            model = "nodal" if m.group(2) == "nodal" else m.group(2) + " modes"
            key = f"elastic crank {m.group(1)} el. {model}, 1 rev: run [s]"
            times[key] = float(m.group(7))
            counters[key] = (m.group(4), m.group(5), m.group(6))
    return times, counters


def micro(build, tmp):
    """Google Benchmark's console lines: the CPU column (less sensitive to load than real time)."""
    text = run([os.path.join(build, "benchmarks", "bench_micro"), "--out-dir", tmp,
                "--benchmark_filter=^(residual|jacobian)/", "--benchmark_min_time=0.3"], tmp)
    times, sizes = {}, {}
    for line in text.splitlines():
        m = re.match(r"^(residual|jacobian)/(\S+)\s+([\d.]+) us\s+([\d.]+) us\s+\d+\s+(\S+)", line)
        if m:
            kind = "residual" if m.group(1) == "residual" else "Jacobian"
            times[f"micro {m.group(2)} (size {m.group(5)}): {kind}, CPU [us]"] = float(m.group(4))
    return times, {}


def kinematics(build, tmp):
    text = run([os.path.join(build, "benchmarks", "bench_kinematics")], tmp)
    times, counters = {}, {}
    for line in text.splitlines():
        m = re.match(r"^(\S+)\s+(newton|modified_newton)\s+(\d+)\s+([\d.]+)\s+\S+\s+\S+\s+([\d.]+)", line)
        if m:
            key = f"kinematics {m.group(1)} {m.group(2)}: per step [us]"
            times[key] = float(m.group(5))
            counters[key] = (m.group(3), m.group(4))
    return times, counters


def instructions(build, model, kind, n):
    """Instructions (callgrind) of bench_micro --loop MODEL:KIND:N."""
    out = subprocess.run(["nice", "valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                          os.path.join(build, "benchmarks", "bench_micro"), "--loop", f"{model}:{kind}:{n}"],
                         capture_output=True, text=True)
    m = re.search(r"Collected : (\d+)", out.stderr)
    if out.returncode != 0 or not m:
        sys.stderr.write(out.stderr)
        raise SystemExit("valgrind --tool=callgrind failed")
    return int(m.group(1))


def callgrind_table(builds, n=1000):
    """Instructions per evaluation (reused scratch), deterministic: (Ir(N) - Ir(0)) / N."""
    lines = ["", f"Instructions per evaluation (callgrind, bench_micro --loop MODEL:KIND:{n} minus :0)", "",
             "| model | evaluation | old [Ir] | new [Ir] | new/old |", "|---|---|---|---|---|"]
    for model in ("rigid_crank", "bari_ggl", "bari_index1", "crank8"):
        for kind in ("residual", "jacobian"):
            per = {}
            for which in ("old", "new"):
                per[which] = (instructions(builds[which], model, kind, n) - instructions(builds[which], model, kind, 0)) / n
            lines.append(f"| {model} | {kind} | {per['old']:.0f} | {per['new']:.0f} | {per['new'] / per['old']:.3f} |")
            print(f"callgrind {model} {kind} done", file=sys.stderr, flush=True)
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", required=True, help="build directory of the old tree")
    ap.add_argument("--new", required=True, help="build directory of the new tree")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--out", help="also write the table (markdown) to this file")
    ap.add_argument("--skip", default="", help="comma-separated: rigid,elastic,micro,kinematics")
    ap.add_argument("--callgrind", action="store_true",
                    help="also count instructions per residual and Jacobian (valgrind; bench_micro --loop)")
    args = ap.parse_args()
    skip = set(filter(None, args.skip.split(",")))
    benches = [(n, f) for n, f in [("rigid", rigid), ("elastic", elastic), ("micro", micro),
                                   ("kinematics", kinematics)] if n not in skip]
    builds = {"old": os.path.abspath(args.old), "new": os.path.abspath(args.new)}
    samples = {"old": {}, "new": {}}
    counters = {"old": {}, "new": {}}
    order = []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            # each binary runs for both builds back to back, the order alternating from
            # round to round (old, new / new, old): a change of the machine's load between
            # two binaries' runs biases neither build
            for name, fn in benches:
                for which in (("old", "new") if r % 2 == 0 else ("new", "old")):
                    t, c = fn(builds[which], tmp)
                    if name in ("rigid", "elastic"):  # whole-binary CPU time (fixed work)
                        binary = "bench_rigid_slider_crank" if name == "rigid" else "bench_elastic_slider_crank"
                        t[f"{binary}: CPU of the whole binary [s]"] = CPU[binary]
                    for k, v in t.items():
                        samples[which].setdefault(k, []).append(v)
                        if k not in order:
                            order.append(k)
                    counters[which].update(c)
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    lines = [f"{args.rounds} rounds; in each, every binary runs for both builds back to back "
             f"(order old/new, then new/old in the next round); medians over the rounds",
             "",
             "| figure | old | new | new/old (medians) | new/old (median of per-round ratios) | counters equal |",
             "|---|---|---|---|---|---|"]
    for k in order:
        o, n = samples["old"].get(k, []), samples["new"].get(k, [])
        if not o or not n:
            continue
        mo, mn = statistics.median(o), statistics.median(n)
        per = statistics.median([b / a for a, b in zip(o, n)])
        ceq = ""
        if k in counters["old"] and k in counters["new"]:
            ceq = "yes" if counters["old"][k] == counters["new"][k] else f"no: {counters['old'][k]} / {counters['new'][k]}"
        lines.append(f"| {k} | {mo:.4g} | {mn:.4g} | {mn / mo:.3f} | {per:.3f} | {ceq} |")
    if args.callgrind:
        lines += callgrind_table(builds)
    text = "\n".join(lines)
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
