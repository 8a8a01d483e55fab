#!/usr/bin/env bash
# Installs, from Debian packages, whatever codyna needs and the machine lacks.
#   scripts/deps.sh        everything: the CLI, the GUI, the tests, the sanitizer and fuzz
#                          builds, the Python module, the benchmarks and their peers
#   scripts/deps.sh cli    what the command-line program needs to build and everything it
#                          links (scripts/demo.sh; GNU Octave, 2.5 of the 5 minutes apt takes
#                          for this set on a fresh machine, comes with the full set)
# Runs as root (or through sudo when not root). Safe to run again: it only calls apt-get when a
# package is missing. The cli set is part of the full one: installing it first and the rest
# later changes nothing already built (docs/performance.md, "Build time").
set -euo pipefail

CLI_PKGS=(
  build-essential cmake pkg-config
  clang  # the compiler scripts/build.sh uses for new trees (half GCC's compile time, the same results)
  libomp-dev  # OpenMP for clang: SUNDIALS' CMake package asks for it
  ninja-build  # the build tool scripts/build.sh uses (it falls back to make without it)
  libeigen3-dev libsundials-dev libhdf5-dev libmatio-dev
  nlohmann-json3-dev libcli11-dev
  libmujoco-dev  # MJCF import and export (codyna import, codyna export-mjcf); the build skips both without
  liburdfdom-dev  # URDF import (core/io/import_urdf.cpp, the ROS parser); the build works without it
  openmpi-bin libopenmpi-dev  # mpirun -np N codyna sweep (app/sweep_mpi.cpp, tests/cli/sweep_mpi.sh); the build works without
)
ALL_PKGS=(
  "${CLI_PKGS[@]}"
  libgtest-dev libgmock-dev libbenchmark-dev
  octave octave-control  # the exports run in GNU Octave (tests, docs; the demo too when installed)
  libmujoco-samples  # MuJoCo's own MJCF models (/usr/share/mujoco/model): imported by the peer and CLI tests
  libsimbody-dev  # the Simbody peer of the work-precision study (bench/simbody_*.cpp, peer.simbody_agrees)
  libclang-rt-14-dev  # clang 14's fuzzer and sanitizer runtimes (scripts/sanitize.sh, scripts/fuzz.sh)
  liboctave-dev  # codyna_plant.mex, the plant stepped from Octave (app/mex)
  python3 python3-scipy python3-h5py python3-numpy
  python3-matplotlib  # scripts/plot_work_precision.py (work-precision plots, Agg backend)
  pybind11-dev python3-dev python3-pytest  # the Python module (python/) and its pytest suite
  # the GUI (codyna-gui) and its tests: Qt 6 widgets, OpenGL, Charts, SVG export,
  # and a virtual X server with Mesa's software OpenGL for the rendering tests
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev qt6-charts-dev qt6-svg-dev
  libgl-dev xvfb xauth libgl1-mesa-dri
)

case "${1:-all}" in
  cli) PKGS=("${CLI_PKGS[@]}") ;;
  all) PKGS=("${ALL_PKGS[@]}") ;;
  *) echo "usage: $0 [cli]" >&2; exit 2 ;;
esac

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PKGS[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
