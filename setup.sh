#!/usr/bin/env bash
# Set-up of knee_contact on Debian 12: installs the Debian packages it needs
# (only those missing, so a second run is quiet), then configures (Release)
# and builds into build/. Run as root; idempotent.
set -euo pipefail
cd "$(dirname "$0")"

# libdeal.ii-dev brings deal.II 9.4 with Trilinos, SuiteSparse (UMFPACK),
# Boost, muparser and MPI; numdiff, perl and mpiexec serve deal.II's test
# machinery; gmsh meshes .geo scenes; OpenBLAS makes UMFPACK 5-6x faster than
# the reference BLAS; nlohmann-json writes summary.json with real numbers;
# the condensed contact solver calls CHOLMOD (libsuitesparse-dev) and METIS;
# zlib inflates compressed VTU meshes; meshio and VTK 9 (Python) write the
# mesh files of other programs that the format tests read. The iterative
# solver path calls Trilinos ML (libtrilinos-ml-dev) and initialises MPI
# itself (mpi-default-dev); the sparse path's distributed factor calls
# MUMPS (libmumps-dev); libdeal.ii-dev brings all three, named here
# because the code uses them directly.
packages="cmake make g++ libdeal.ii-dev numdiff perl openmpi-bin gmsh
          libtrilinos-ml-dev mpi-default-dev libmumps-dev
          libopenblas0-pthread nlohmann-json3-dev python3-matplotlib
          libsuitesparse-dev libmetis-dev zlib1g-dev python3-meshio
          python3-vtk9"
missing=""
for package in $packages; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null |
    grep -q "install ok installed" || missing="$missing $package"
done
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
    --no-install-recommends $missing >/dev/null
fi

mkdir -p build
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >build/configure.log 2>&1 ||
    { cat build/configure.log; exit 1; }
fi
# Two compile jobs at most: a deal.II translation unit needs over 1 GB.
if ! cmake --build build -j2 >build/build.log 2>&1; then
  tail -n 40 build/build.log
  exit 1
fi
