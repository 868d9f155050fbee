"""The build backend of `pip install .` (PEP 517, named by pyproject.toml).

It needs nothing but the Python standard library (no setuptools, no wheel, no download:
pyproject.toml requires no build packages), so `pip install .` works offline with or
without `--no-build-isolation`, for whichever CPython runs pip (Debian's, a venv's, a
pyenv one). The build itself is the project's CMake build (CMakeLists.txt,
python/CMakeLists.txt): one build description; this file only chooses the build folder,
runs CMake there and packs a wheel from what it built:

  flexmbd/*.py                         (python/flexmbd/, the package's Python files)
  flexmbd/_flexmbd<EXT_SUFFIX>         (the module, the engine linked in statically)
  flexmbd-V.data/scripts/flexmbd-study (python/flexmbd-study; pip writes the interpreter
                                        into its first line)
  flexmbd-V.dist-info/                 (METADATA, WHEEL, RECORD)

The build folder, first that applies:
  1. $FLEXMBD_BUILD_DIR: configured there if it has no CMakeCache.txt yet; refused if it
     was configured for another Python (its FLEXMBD_PYTHON_EXECUTABLE, the interpreter
     python/CMakeLists.txt built the module for).
  2. build/ of the source tree when it was configured for this Python (make's default
     build): built up to date (cmake --build --target _flexmbd), not compiled again.
  3. build-pip/<python tag>-<hash of the interpreter>/: configured (Release, no tests
     or benchmarks, -DPython3_EXECUTABLE=this Python's interpreter) and built; kept, so a
     second `pip install .` only rebuilds what changed.
"This Python" is the interpreter behind pip's Python: a venv's base interpreter (the
module depends on its headers and ABI, not on the venv's site-packages), so every venv
of /usr/bin/python3 can reuse the default build/. CMAKE_BUILD_PARALLEL_LEVEL sets the
build's jobs (default: the machine's cores); `pip install -v .` shows the build.
"""

import base64
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import time
import zipfile

SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
NAME = "flexmbd"
SUMMARY = "flexible multibody dynamics: the flexmbd engine (C++17) from Python"
# numpy: the results' columns are NumPy arrays (the module imports it when it makes the
# first one); distributed (Dask): flexmbd-study's cluster runs (--workers 0 runs without).
REQUIRES = ["numpy"]
EXTRAS = {"study": ["distributed"], "plot": ["matplotlib"]}


def _log(msg):
    print(f"flexmbd build: {msg}", file=sys.stderr, flush=True)


def _version():
    with open(os.path.join(SOURCE, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(\s*flexmbd\s+VERSION\s+([0-9.]+)", f.read())
    if not m:
        raise RuntimeError("no 'project(flexmbd VERSION ...)' in CMakeLists.txt")
    return m.group(1)


def _dist_info():
    return f"{NAME}-{_version()}.dist-info"


def _tag():
    """The wheel's tag: this CPython's (cp311-cp311-linux_x86_64)."""
    if sys.implementation.name != "cpython":
        raise RuntimeError(f"flexmbd's module is built for CPython, not {sys.implementation.name}")
    py = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    plat = re.sub(r"[^A-Za-z0-9_]", "_", sysconfig.get_platform())
    return f"{py}-{py}{sys.abiflags}-{plat}"


def _interpreter():
    """This Python's interpreter without its venv (the module is built against it)."""
    base = getattr(sys, "_base_executable", None) or sys.executable
    return os.path.realpath(base if os.path.exists(base) else sys.executable)


def _cached_python(build_dir):
    """The interpreter a configured build folder builds the module for (python/CMakeLists.txt
    records it as FLEXMBD_PYTHON_EXECUTABLE), or None."""
    found = {}
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt"), encoding="utf-8", errors="replace") as f:
            for line in f:
                name = line.split(":", 1)[0]
                if name in ("FLEXMBD_PYTHON_EXECUTABLE", "Python3_EXECUTABLE", "_Python3_EXECUTABLE") and "=" in line:
                    found[name] = line.split("=", 1)[1].strip()
    except OSError:
        pass
    for name in ("FLEXMBD_PYTHON_EXECUTABLE", "Python3_EXECUTABLE", "_Python3_EXECUTABLE"):
        if found.get(name):
            return found[name]
    return None


def _same_python(exe):
    if not exe:
        return False
    mine = {_interpreter(), os.path.realpath(sys.executable)}
    return os.path.realpath(exe) in mine


def _build_dir():
    """(folder, whether it must be configured) by the rules of the module's docstring."""
    given = os.environ.get("FLEXMBD_BUILD_DIR")
    if given:
        given = os.path.abspath(given)
        exe = _cached_python(given)
        if exe is None:
            if os.path.exists(os.path.join(given, "CMakeCache.txt")):
                raise RuntimeError(f"FLEXMBD_BUILD_DIR={given} builds no Python module "
                                   "(configured with FLEXMBD_BUILD_PYTHON=OFF?)")
            return given, True
        if not _same_python(exe):
            raise RuntimeError(f"FLEXMBD_BUILD_DIR={given} was configured for the Python {exe}, "
                               f"not {_interpreter()} (the one running pip): unset FLEXMBD_BUILD_DIR "
                               "or name another folder")
        return given, False
    default = os.path.join(SOURCE, "build")
    if _same_python(_cached_python(default)):
        return default, False
    key = hashlib.sha256(_interpreter().encode()).hexdigest()[:8]
    own = os.path.join(SOURCE, "build-pip", f"{_tag().split('-')[0]}-{key}")
    return own, _cached_python(own) is None


def _run(cmd):
    _log("$ " + " ".join(cmd))
    # the build's output on stderr: pip shows it with -v, and keeps stdout for itself
    r = subprocess.run(cmd, stdout=sys.stderr, stderr=sys.stderr)
    if r.returncode != 0:
        raise RuntimeError(f"command failed (exit {r.returncode}): {' '.join(cmd)}")


def _cmake_build():
    """Builds the module; returns the path of the built _flexmbd extension."""
    cmake = shutil.which("cmake")
    if cmake is None:
        raise RuntimeError("cmake not found (Debian: scripts/setup.sh installs it and the engine's packages)")
    build, configure = _build_dir()
    if configure:
        _log(f"configuring {build} for {_interpreter()}")
        _run([cmake, "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
              f"-DPython3_EXECUTABLE={_interpreter()}", "-DFLEXMBD_BUILD_PYTHON=ON",
              "-DFLEXMBD_BUILD_TESTS=OFF", "-DFLEXMBD_BUILD_BENCHMARKS=OFF"])
    else:
        _log(f"reusing the build folder {build} (configured for {_cached_python(build)})")
    cmd = [cmake, "--build", build, "--target", "_flexmbd"]
    if not os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
        cmd += ["-j", str(os.cpu_count() or 1)]
    start = time.monotonic()
    _run(cmd)
    _log(f"module built (up to date) in {time.monotonic() - start:.1f} s")
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    module = os.path.join(build, "python", "flexmbd", "_flexmbd" + suffix)
    if not os.path.isfile(module):
        found = [n for n in os.listdir(os.path.join(build, "python", "flexmbd")) if n.startswith("_flexmbd")]
        raise RuntimeError(f"no {module} after the build (found {found}): built for another Python?")
    return module


def _metadata():
    lines = ["Metadata-Version: 2.1", f"Name: {NAME}", f"Version: {_version()}", f"Summary: {SUMMARY}",
             "Requires-Python: >=3.8"]
    lines += [f"Requires-Dist: {r}" for r in REQUIRES]
    for extra, reqs in EXTRAS.items():
        lines.append(f"Provides-Extra: {extra}")
        lines += [f'Requires-Dist: {r}; extra == "{extra}"' for r in reqs]
    readme = os.path.join(SOURCE, "README.md")
    body = ""
    if os.path.isfile(readme):
        with open(readme, encoding="utf-8") as f:
            body = f.read()
        lines.append("Description-Content-Type: text/markdown")
    return "\n".join(lines) + "\n\n" + body


def _wheel_file(tag):
    return f"Wheel-Version: 1.0\nGenerator: flexmbd_backend {_version()}\nRoot-Is-Purelib: false\nTag: {tag}\n"


def _study_script():
    """python/flexmbd-study with '#!python' first: pip puts the installing interpreter there."""
    with open(os.path.join(SOURCE, "python", "flexmbd-study"), "rb") as f:
        text = f.read()
    first, rest = text.split(b"\n", 1)
    assert first.startswith(b"#!"), "python/flexmbd-study must start with #!"
    return b"#!python\n" + rest


class _Wheel:
    """A wheel being written: its files with their RECORD lines."""

    def __init__(self, path):
        self.zip = zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED)
        self.record = []

    def add(self, name, data, executable=False):
        info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
        info.compress_type = zipfile.ZIP_DEFLATED
        info.external_attr = ((0o755 if executable else 0o644) | 0o100000) << 16
        self.zip.writestr(info, data)
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        self.record.append(f"{name},sha256={digest},{len(data)}")

    def close(self, record_name):
        self.record.append(f"{record_name},,")
        self.zip.writestr(zipfile.ZipInfo(record_name, date_time=(2020, 1, 1, 0, 0, 0)),
                          "\n".join(self.record) + "\n")
        self.zip.close()


# ----- the PEP 517 hooks -----------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    d = os.path.join(metadata_directory, _dist_info())
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata())
    with open(os.path.join(d, "WHEEL"), "w", encoding="utf-8") as f:
        f.write(_wheel_file(_tag()))
    return _dist_info()


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    module = _cmake_build()
    tag = _tag()
    version = _version()
    name = f"{NAME}-{version}-{tag}.whl"
    path = os.path.join(wheel_directory, name)
    wheel = _Wheel(path)
    package = os.path.join(SOURCE, "python", "flexmbd")
    for f in sorted(os.listdir(package)):
        if f.endswith(".py"):
            with open(os.path.join(package, f), "rb") as src:
                wheel.add(f"flexmbd/{f}", src.read())
    with open(module, "rb") as src:
        wheel.add(f"flexmbd/{os.path.basename(module)}", src.read(), executable=True)
    wheel.add(f"{NAME}-{version}.data/scripts/flexmbd-study", _study_script(), executable=True)
    info = _dist_info()
    wheel.add(f"{info}/METADATA", _metadata().encode())
    wheel.add(f"{info}/WHEEL", _wheel_file(tag).encode())
    wheel.add(f"{info}/top_level.txt", b"flexmbd\n")
    wheel.close(f"{info}/RECORD")
    _log(f"wrote {name} ({os.path.getsize(path) / 1e6:.1f} MB)")
    return name


def build_sdist(sdist_directory, config_settings=None):
    """The source tree without build folders, git data and caches."""
    base = f"{NAME}-{_version()}"
    name = base + ".tar.gz"
    skip_dirs = {".git", "__pycache__", ".pytest_cache"}

    def keep(rel):
        top = rel.split(os.sep, 1)[0]
        return not (top.startswith("build") or any(p in skip_dirs for p in rel.split(os.sep)))

    with tarfile.open(os.path.join(sdist_directory, name), "w:gz", format=tarfile.PAX_FORMAT) as tar:
        for root, dirs, files in os.walk(SOURCE):
            rel_root = os.path.relpath(root, SOURCE)
            dirs[:] = sorted(d for d in dirs if keep(os.path.normpath(os.path.join(rel_root, d))))
            for f in sorted(files):
                rel = os.path.normpath(os.path.join(rel_root, f))
                if keep(rel) and not f.endswith(".pyc"):
                    tar.add(os.path.join(root, f), arcname=f"{base}/{rel}", recursive=False)
        pkg_info = _metadata().encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size = len(pkg_info)
        info.mtime = int(time.time())
        tar.addfile(info, io.BytesIO(pkg_info))
    return name
