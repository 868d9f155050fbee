#!/usr/bin/python3
"""User functions from Python: the overhead per call of a Python callable.

A pendulum driven by a harmonic torque (50 s, outputs every 0.01 s) and a slider on a
spring-damper, each run with the built-in law and with the same law as a Python
callable (which counts its calls); the overhead per call is
(t_python - t_builtin) / calls: taking the GIL from the run's thread, calling the
callable, converting its float, releasing the GIL. The fastest of --rounds interleaved
runs each (a shared machine's load only adds time).
For comparison, the bare cost of calling the same callable from Python.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/bench_user_functions.py [--rounds 5]

The C++ callables' overhead: build/benchmarks/bench_user_functions.
"""
import argparse
import math
import time
import timeit

import flexmbd

A, W = 2.0, 5.0
T_END = 50.0  # s: tens of thousands of calls per run


def pendulum(torque):
    scene = flexmbd.Scene("pendulum")
    s = scene.system
    s.set_gravity((0.0, -9.81))
    rod = s.add_rigid_body("rod", flexmbd.RigidBodyProperties(mass=1.0, inertia=1.0 / 12.0),
                           flexmbd.FrameState2d(position=(0.5, 0.0)))
    s.add_revolute_joint("pin", "ground", (0, 0), rod, (-0.5, 0))
    s.add_applied_load("motor", rod, (0, 0), torque=torque)
    scene.solver.t_end = T_END
    return scene


def slider(**spring):
    scene = flexmbd.Scene("slider")
    s = scene.system
    b = s.add_rigid_body("slider", flexmbd.RigidBodyProperties(mass=2.0, inertia=0.1),
                         flexmbd.FrameState2d(position=(1.3, 0.0)))
    s.add_prismatic_joint("rail", "ground", (0, 0), b, (0, 0), axis=(1, 0))
    s.add_spring_damper("spring", "ground", (0, 0), b, (0, 0), **spring)
    scene.solver.t_end = T_END
    return scene


def once(make):
    scene = make()
    t = time.perf_counter()
    res = scene.run()
    elapsed = time.perf_counter() - t
    assert res.ok, res.message
    return elapsed


def timed(builtin, python, rounds):
    """The fastest of `rounds` interleaved runs of each (the minimum: what the run costs
    without the other work of a shared machine; timeit's advice)."""
    tb, tp = [], []
    for _ in range(rounds):
        tb.append(once(builtin))
        tp.append(once(python))
    return min(tb), min(tp)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    rounds = ap.parse_args().rounds
    calls = [0]

    def torque(t):
        calls[0] += 1
        return 0.0 + A * math.sin(W * t + 0.0)

    def spring(t, l, ldot):
        calls[0] += 1
        return 50.0 * (l - 1.0) + 0.8 * ldot

    print(f"fastest of {rounds} interleaved runs each, {T_END:g} s of motion, outputs every 0.01 s")
    print(f"| model | built-in law [ms] | Python law [ms] | calls per run | overhead per call [us] |")
    print("|---|---|---|---|---|")
    for name, builtin, python in (
            ("pendulum, torque law f(t)", lambda: pendulum(flexmbd.harmonic_law(A, W)), lambda: pendulum(torque)),
            ("slider, spring law f(t, l, ldot), FD derivatives",
             lambda: slider(stiffness=50.0, damping=0.8, free_length=1.0), lambda: slider(law=spring))):
        calls[0] = 0
        tb, tp = timed(builtin, python, rounds)
        n = calls[0] / rounds
        print(f"| {name} | {1e3 * tb:.2f} | {1e3 * tp:.2f} | {n:.0f} | {1e6 * (tp - tb) / n:.3f} |")
    # the call alone: f(t) evaluated from C++ with the GIL released, as in a run
    n = 200000
    plain = lambda t: 0.0 + A * math.sin(W * t + 0.0)  # noqa: E731
    builtin = min(flexmbd._flexmbd._time_law_calls(flexmbd.harmonic_law(A, W), n)[0] for _ in range(rounds))
    python = min(flexmbd._flexmbd._time_law_calls(flexmbd.user_law(plain), n)[0] for _ in range(rounds))
    bare = min(timeit.repeat(lambda: plain(0.3), number=n, repeat=rounds)) / n
    print(f"\nf(t) = A sin(W t) called {n} times from C++ without the GIL (fastest of {rounds}):")
    print("| law | us per call |\n|---|---|")
    print(f"| built-in harmonic_law | {1e6 * builtin / n:.3f} |")
    print(f"| Python callable (user_law) | {1e6 * python / n:.3f} |")
    print(f"| overhead per call (Python - built-in) | {1e6 * (python - builtin) / n:.3f} |")
    print(f"| the callable called from Python (no GIL to take, no conversion) | {1e6 * bare:.3f} |")


if __name__ == "__main__":
    main()
