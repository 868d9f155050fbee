#!/bin/sh
# Installs the Debian 12 packages flexmbd needs, only those that are missing.
# Run as root (or with sudo available). Idempotent: does nothing when all are present.
set -eu
PACKAGES="build-essential cmake libeigen3-dev libsundials-dev libsuitesparse-dev \
libgtest-dev libbenchmark-dev nlohmann-json3-dev python3-matplotlib libsiconos-numerics-dev \
libhdf5-dev libspectra-dev python3-dev pybind11-dev python3-numpy python3-pytest python3-distributed python3-pandas python3-h5py python3-scipy \
python3-venv python3-pip calculix-ccx chromium doxygen"
missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
# npm (the viewer's three.js comes from the npm registry): the machine's own Node.js if
# it has one, else Debian's
command -v npm >/dev/null 2>&1 || missing="$missing npm"
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
else
  echo "setup: all packages present"
fi

# The browser viewer's three.js (viewer/package.json, its exact version locked in
# viewer/package-lock.json), compiled into the engine by CMake.
here=$(cd "$(dirname "$0")/.." && pwd)
if [ ! -f "$here/viewer/node_modules/three/build/three.module.min.js" ]; then
  echo "setup: installing three.js from the npm registry into viewer/node_modules"
  (cd "$here/viewer" && npm ci --no-audit --no-fund --loglevel=error)
fi
