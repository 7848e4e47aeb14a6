#!/usr/bin/env bash
# Installs the Debian packages beamsim needs, only those that are missing.
# Run as root on Debian bookworm (or with sudo available).
set -euo pipefail
pkgs=(build-essential cmake pkg-config libgsl-dev libcmocka-dev libfyaml-dev libbox2d-dev
      libmatio-dev gnuplot-nox fonts-dejavu-core libcairo2-dev ffmpeg)
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
