#!/usr/bin/env python3
"""scd of a `flexmbd run examples/bari_slider_crank.json` at t = 0.1: -log10 of the largest
relative error of the positions phi2, x3, q1..q4 against the Bari test set's reference
(problems/bari_crank.hpp, kReferencePositions; the test set's measure).

usage: scripts/bari_scd.py OUT_DIR [OUT_DIR ...]   (reads OUT_DIR/results.csv)
"""
import csv
import math
import sys

REFERENCE = {  # t = 0.1: phi2, x3, q1..q4 (problems/bari_crank.hpp)
    "rod.theta": -0.3311734988256260,
    "slider.x": 0.1697373328427860,
    "rod.q1": 1.893192899613509e-4,
    "rod.q2": 2.375751249879174e-5,
    "rod.q3": -5.323896770569702e-6,
    "rod.q4": -8.363313279112129e-6,
}
END_TIME = 0.1


def scd(out_dir):
    with open(f"{out_dir}/results.csv") as f:
        rows = list(csv.DictReader(f))
    last = rows[-1]
    if abs(float(last["t"]) - END_TIME) > 1e-12:
        return float("nan"), float(last["t"])
    err = max(abs(float(last[k]) - v) / abs(v) for k, v in REFERENCE.items())
    return -math.log10(err), END_TIME


if __name__ == "__main__":
    for d in sys.argv[1:]:
        s, t = scd(d)
        print(f"{d}: scd {s:.2f}" if t == END_TIME else f"{d}: stopped at t = {t}")
