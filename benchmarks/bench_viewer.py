#!/usr/bin/python3
"""The browser viewer: page size, the time `flexmbd view` takes to
write it, and the time headless Chromium takes to show its first frame, for the demo's
3-revolution nodal run (examples/slider_crank_elastic_demo_nodal.json, 541 frames).

    /usr/bin/python3 benchmarks/bench_viewer.py [--cli build/app/flexmbd] [--rounds 3]

Writing: the fastest of --rounds (a shared machine's load only adds time). First frame:
the page's own `ready_ms` (from the start of loading to the first frame drawn, in its
flexmbd-status element; software rendering), the median of --rounds openings.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile
import time

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHROMIUM = "/usr/bin/chromium"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cli", default=os.path.join(SOURCE, "build", "app", "flexmbd"))
    p.add_argument("--rounds", type=int, default=3)
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        run = os.path.join(tmp, "nodal")
        subprocess.run([a.cli, "run", os.path.join(SOURCE, "examples", "slider_crank_elastic_demo_nodal.json"),
                        "--out", run, "--quiet"], check=True, capture_output=True)
        page = os.path.join(run, "view.html")
        writes = []
        for _ in range(a.rounds):
            start = time.perf_counter()
            subprocess.run([a.cli, "view", run], check=True, capture_output=True)
            writes.append(time.perf_counter() - start)
        frames = len(open(os.path.join(run, "results.csv")).readlines()) - 1
        print(f"page: {os.path.getsize(page) / 1e6:.2f} MB, {frames} frames; "
              f"flexmbd view writes it in {min(writes):.3f} s (fastest of {a.rounds})")
        if not os.path.exists(CHROMIUM):
            print(f"first frame: not measured (no {CHROMIUM})")
            return
        ready = []
        for _ in range(a.rounds):
            dom = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                                  "--window-size=1280,860", "--virtual-time-budget=3000", "--dump-dom",
                                  "file://" + page], capture_output=True, text=True).stdout
            m = re.search(r'<pre id="flexmbd-status" hidden="">([^<]*)</pre>', dom)
            status = json.loads(m.group(1)) if m else {}
            if not status.get("ok"):
                raise SystemExit(f"the page did not report ok: {status}")
            ready.append(status["ready_ms"])
        print(f"first frame in headless Chromium: {statistics.median(ready):.0f} ms after loading starts "
              f"(median of {a.rounds}: {ready})")


if __name__ == "__main__":
    main()
