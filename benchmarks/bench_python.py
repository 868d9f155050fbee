#!/usr/bin/python3
"""Python module and parameter studies: what they cost.

1. The flagship (examples/slider_crank_elastic_demo_nodal.json and ..._modal.json) run
   from Python (flexmbd.load_scene(...).run()) and by the command line (flexmbd run,
   results written to a temporary directory), interleaved, median of --rounds.
2. The resonance study (examples/study_resonance.json, or its first --points points)
   serially in-process (--workers 0) and on a LocalCluster with 1 and 2 workers: points
   per second, and the overhead per task = (wall time x workers - sum of the tasks' own
   run times) / points.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/bench_python.py [--rounds 5] [--points 108]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def flagship(cli, rounds):
    import flexmbd

    print("flagship: python run() vs command line (wall seconds, median of %d interleaved rounds)" % rounds)
    print("| scene | python [s] | CLI [s] | python / CLI |")
    print("|---|---|---|---|")
    for name in ("slider_crank_elastic_demo_nodal.json", "slider_crank_elastic_demo_modal.json"):
        path = os.path.join(ROOT, "examples", name)
        py, cl = [], []
        for _ in range(rounds):
            t = time.perf_counter()
            res = flexmbd.load_scene(path).run()
            py.append(time.perf_counter() - t)
            assert res.ok
            with tempfile.TemporaryDirectory() as d:
                t = time.perf_counter()
                subprocess.run([cli, "run", path, "--out", d, "--quiet"], check=True, capture_output=True)
                cl.append(time.perf_counter() - t)
        p, c = statistics.median(py), statistics.median(cl)
        print(f"| {name} | {p:.3f} | {c:.3f} | {p / c:.2f} |")


def study(points):
    from flexmbd import study as st

    spec = json.load(open(os.path.join(ROOT, "examples", "study_resonance.json")))
    spec["scene"] = os.path.join(ROOT, "examples", spec["scene"])
    spec.pop("plot", None)
    tmp = tempfile.mkdtemp()
    path = os.path.join(tmp, "study.json")
    json.dump(spec, open(path, "w"))
    s = st.load_study(path)
    s.points = s.points[:points]
    print(f"\nstudy: {len(s.points)} points of examples/study_resonance.json")
    import logging
    from dask.distributed import Client, LocalCluster

    startup = {0: 0.0}
    for workers in (1, 2):  # the LocalCluster's own start and stop, measured apart
        t = time.perf_counter()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                          silence_logs=logging.ERROR) as cluster, Client(cluster):
            pass
        startup[workers] = time.perf_counter() - t
    print("| workers | wall [s] | cluster start+stop [s] | points/s | points/s without start | mean task run time [s] | overhead per task [s] |")
    print("|---|---|---|---|---|---|---|")
    for workers in (0, 1, 2):
        out = os.path.join(tmp, f"w{workers}")
        t = time.perf_counter()
        st.run_study(s, out, workers=workers, progress=False)
        wall = time.perf_counter() - t
        with open(os.path.join(out, "study.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        busy = sum(float(r["wall_seconds"]) for r in rows)
        slots = max(workers, 1)
        run = wall - startup[workers]
        print(f"| {workers if workers else '0 (serial, in-process)'} | {wall:.2f} | {startup[workers]:.2f} | "
              f"{len(rows) / wall:.1f} | {len(rows) / run:.1f} | {busy / len(rows):.4f} | "
              f"{(run * slots - busy) / len(rows):.4f} |")
    print("(overhead per task: (wall - cluster start) x workers - the tasks' own run times, per point)")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--points", type=int, default=108)
    p.add_argument("--cli", default=os.path.join(ROOT, "build", "app", "flexmbd"))
    a = p.parse_args()
    flagship(a.cli, a.rounds)
    study(a.points)


if __name__ == "__main__":
    sys.exit(main())
