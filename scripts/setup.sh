#!/usr/bin/env bash
# Installs what knitscale needs from Debian 12 packages (idempotent; silent when all is there).
# Needs root (or sudo) only when something is missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build git pkg-config
  libeigen3-dev          # linear algebra (3.4)
  libceres-dev           # response-surface fitting (2.1)
  nlohmann-json3-dev     # JSON input (3.11)
  libhdf5-dev            # material database and results (1.10)
  libsuitesparse-dev     # CHOLMOD: supernodal Cholesky of the shell tangent (5.12)
  libmumps-seq-dev       # MUMPS: multifrontal LDLT of indefinite shell tangents (docs/solver.md)
  libopenblas0-pthread   # optimized BLAS behind CHOLMOD (docs/solver.md "Benchmark"): Debian's
                         # alternatives select it over ATLAS for libblas.so.3 (priority 100 vs 35)
  catch2                 # tests (2.13)
  libcli11-dev           # command lines (2.1)
  libopenmpi-dev openmpi-bin   # distributed database sweep
  python3-matplotlib python3-h5py python3-numpy   # figures (Debian's /usr/bin/python3)
)
# The test suite (scripts/test.sh sets KNIT_SETUP_TESTS=1) also reads our VTU/VTP/PVD files with
# VTK's own readers, the library ParaView is built on (CTest vtk_check, scripts/vtk_check.py):
# 57 MB to fetch, 297 MB installed with its Qt dependencies, 12 s to install here. Until session
# 39 it was left out and the check always skipped (exit 77), so it could not fail in CI.
if [ "${KNIT_SETUP_TESTS:-0}" = 1 ]; then
  PACKAGES+=(python3-vtk9)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
