"""CTest python_pip_install: `pip install` of the source tree into a
fresh virtual environment, then the package and flexmbd-study used from there without
PYTHONPATH and outside the source tree; then this interpreter's pip into a prefix (pip
install --prefix), whose flexmbd-study must find its package by itself.

    /usr/bin/python3 tests/pip_install_venv.py SOURCE_DIR BUILD_DIR

The venv (BUILD_DIR/venv-test, made afresh each time, --system-site-packages: numpy and
Dask from Debian) is made by the interpreter running this script; pip runs offline
(--no-index, every requirement already installed) with build isolation (the backend
needs no build package) and reuses BUILD_DIR (FLEXMBD_BUILD_DIR): it builds the module
up to date there, it does not compile the engine again.
"""

import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

SOURCE, BUILD = (os.path.abspath(a) for a in sys.argv[1:3])
VENV = os.path.join(BUILD, "venv-test")
PREFIX = os.path.join(BUILD, "prefix-test")

failures = []


def check(ok, what):
    print(("ok: " if ok else "FAILED: ") + what, flush=True)
    if not ok:
        failures.append(what)


def run(cmd, cwd, env, timeout=600, fails=False):
    start = time.monotonic()
    r = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=timeout)
    print(f"$ {' '.join(cmd)}  ({time.monotonic() - start:.1f} s, exit {r.returncode})", flush=True)
    if (r.returncode != 0) != fails:
        print(r.stdout)
    return r


# an environment as a user's: no PYTHONPATH, no pip configuration, no index
# (nor make's jobserver of `make test`: the build folder is brought up to date by its own make)
env = {k: v for k, v in os.environ.items()
       if not k.startswith(("PYTHON", "PIP_", "VIRTUAL_ENV")) and k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}
env.update(PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1", PIP_CONFIG_FILE=os.devnull,
           FLEXMBD_BUILD_DIR=BUILD)
pip_flags = ["--no-index", "--no-cache-dir", "--quiet"]

SIMULATION = f"""
import flexmbd, json, numpy, sys
res = flexmbd.load_scene({os.path.join(SOURCE, "examples", "slider_crank_rigid.json")!r},
                         overrides={{"solver": {{"t_end": 0.05}}}}).run()
x = res["slider.x"]
print(json.dumps({{"file": flexmbd.__file__, "status": res.summary["status"], "rows": len(x), "t_end": float(res.t[-1]),
                  "array": isinstance(x, numpy.ndarray), "finite": bool(numpy.isfinite(x).all())}}))
"""

STUDY = {
    "scene": os.path.join(SOURCE, "examples", "slider_crank_elastic_demo_modal.json"),
    "overrides": {"solver": {"t_end": 0.01}},
    "axes": [{"name": "speed", "key": "drivers[0].law.speed", "values": [100.0, 250.0]}],
    "outputs": {"summary": ["steps"], "max_abs": ["mid.uy"]},
}


def study_rows(script, python_env, work, workers, label):
    out = os.path.join(work, f"study-{label}")
    r = run([script, os.path.join(work, "study.json"), "--out", out, "--workers", str(workers), "--quiet"],
            work, python_env, timeout=300)
    check(r.returncode == 0, f"{script} --workers {workers} exits 0")
    try:
        with open(os.path.join(out, "study.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError:
        rows = []
    check(len(rows) == 2 and all(row["status"] == "ok" for row in rows),
          f"{script} --workers {workers}: 2 points, every one ok ({[row.get('status') for row in rows]})")


with tempfile.TemporaryDirectory() as work:  # outside the source tree: no ./flexmbd to import by accident
    with open(os.path.join(work, "study.json"), "w") as f:
        json.dump(STUDY, f)

    # ----- a venv made by this interpreter ------------------------------------------------
    shutil.rmtree(VENV, ignore_errors=True)
    r = run([sys.executable, "-m", "venv", "--system-site-packages", VENV], work, env)
    check(r.returncode == 0, "python3 -m venv --system-site-packages")
    py, pip = os.path.join(VENV, "bin", "python"), os.path.join(VENV, "bin", "pip")
    r = run([pip, "install", *pip_flags, SOURCE], work, env)
    check(r.returncode == 0, "venv pip install SOURCE (offline, build isolation, reusing the build folder)")

    r = run([py, "-c", SIMULATION], work, env)
    info = json.loads(r.stdout.strip().splitlines()[-1]) if r.returncode == 0 else {}
    check(info.get("file", "").startswith(os.path.join(VENV, "lib")), f"flexmbd imported from the venv: {info.get('file')}")
    check(info.get("status") == "ok" and info.get("rows", 0) >= 2 and abs(info.get("t_end", 0) - 0.05) < 1e-12
          and info.get("array") and info.get("finite"),
          f"a short rigid slider-crank run from the venv: {info}")
    # a Python without NumPy (pyenv, a venv without --system-site-packages): the import names it
    r = run([py, "-c", "import sys; sys.modules['numpy'] = None; import flexmbd"], work, env, fails=True)
    check(r.returncode != 0 and "ImportError: flexmbd needs NumPy" in r.stdout, "without NumPy, the import says so")
    study = os.path.join(VENV, "bin", "flexmbd-study")
    check(os.path.isfile(study), "venv/bin/flexmbd-study installed")
    if os.path.isfile(study):
        with open(study) as f:
            first = f.readline().strip()
        check(first.startswith("#!" + os.path.join(VENV, "bin", "python")), f"its first line names the venv's python: {first}")
        study_rows(study, env, work, 2, "venv")  # a LocalCluster of 2 worker processes: they import flexmbd too

    # ----- pip install --prefix by this interpreter's pip: a prefix it does not search -----
    # (--prefix and --root pass Debian's externally-managed guard; the installed
    # flexmbd-study must find the package under its own prefix, its workers too)
    shutil.rmtree(PREFIX, ignore_errors=True)
    r = run([sys.executable, "-m", "pip", "install", *pip_flags, "--prefix", PREFIX, SOURCE], work, env)
    check(r.returncode == 0, "python3 -m pip install --prefix PREFIX SOURCE")
    r = run([sys.executable, "-c", "import importlib.util; print(importlib.util.find_spec('flexmbd') is None)"],
            work, env)
    if r.stdout.strip() != "True":
        print(f"note: {sys.executable} imports an installed flexmbd already: the prefix's script may use that one")
    # Debian's pip puts --prefix P's files under P/local (bin/, lib/python3.X/dist-packages)
    scripts = [os.path.join(d, "flexmbd-study") for d in (os.path.join(PREFIX, "bin"), os.path.join(PREFIX, "local", "bin"))
               if os.path.isfile(os.path.join(d, "flexmbd-study"))]
    check(len(scripts) == 1, f"flexmbd-study installed under the prefix: {scripts}")
    if scripts:
        study_rows(scripts[0], env, work, 2, "prefix")

shutil.rmtree(VENV, ignore_errors=True)
shutil.rmtree(PREFIX, ignore_errors=True)
if failures:
    print(f"{len(failures)} check(s) failed:\n  " + "\n  ".join(failures))
    sys.exit(1)
print("pip install: venv and prefix ok")
