#!/usr/bin/env bash
# Installs the Debian packages beamsim needs, only those that are missing.
# Run as root on Debian bookworm (or with sudo available).
set -euo pipefail
# zlib1g-dev: CRC-32 of output manifests and journals. clang with
# libclang-rt-14-dev (libFuzzer, only recommended by clang) and libomp-dev
# (clang's OpenMP): the fuzzing run of scripts/test.sh. python3: the test of
# the layout's rules (tests/layers.py). chromium: test_index_html shows each
# output directory's index.html in a headless browser. python3-dev, python3-numpy,
# python3-pytest: the Python module (bindings/python) and its tests; python3-venv,
# python3-pip and python3-setuptools: `pip install .` of the module into a
# virtual environment, and its test; python3-matplotlib: beamsim.plot and its
# test.
# libopenmpi-dev and openmpi-bin: the program's MPI build and its test under
# mpirun (docs/cluster.md). octave and liboctave-dev (mkoctfile): the MEX
# functions of bindings/matlab and their test. libchipmunk-dev: the chipmunk backend
# (backends/chipmunk, Chipmunk2D 7). libnanoflann-dev: the exact k-d tree of
# the Markov chain's nearest-neighbour walks (src/analysis/markov_kdtree.cpp).
pkgs=(build-essential cmake pkg-config libgsl-dev libcmocka-dev libfyaml-dev libbox2d-dev
      libmatio-dev libchipmunk-dev gnuplot-nox fonts-dejavu-core libcairo2-dev ffmpeg zlib1g-dev
      clang libclang-rt-14-dev libomp-dev python3 chromium python3-dev python3-numpy
      python3-pytest python3-venv python3-pip python3-setuptools python3-matplotlib
      libnanoflann-dev libopenmpi-dev openmpi-bin
      octave liboctave-dev)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "beamsim: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
