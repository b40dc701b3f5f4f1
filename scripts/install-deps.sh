#!/usr/bin/env bash
# Installs the Debian packages spinesim needs, only those that are missing.
# Runs as root or through sudo. Safe to run repeatedly.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libeigen3-dev            # Eigen 3.4
  libsuitesparse-dev       # CHOLMOD
  libopenblas0-pthread     # fast BLAS under supernodal CHOLMOD (reference BLAS is ~5x slower)
  libcgal-dev              # CGAL 5.5 Mesh_3
  coinor-libipopt-dev      # Ipopt 3.11
  libcli11-dev nlohmann-json3-dev libtinyxml2-dev
  libssl-dev               # libcrypto's SHA-256: the input files' hashes in every output's provenance
  zlib1g-dev liblzma-dev liblz4-dev   # compressed VTU files (VTK's zlib, LZMA and LZ4 compressors)
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-meshio python3-numpy   # independent VTU reader used by the tests
  python3-jsonschema       # an independent validator of the study files' JSON Schema (tests)
  python3-dev pybind11-dev python3-pytest   # the Python module `spinesim` and its tests
  python3-vtk9             # VTK itself (what ParaView reads and writes with): the tests' second VTU oracle
  calculix-ccx             # CalculiX 2.20: the independent FEM reference of the tests
  python3-matplotlib python3-markdown    # the demo's report.html and its plots (scripts/report.py)
  libglfw3-dev libimgui-dev libstb-dev libgl-dev   # `spinesim view` (GLFW, Dear ImGui, PNG)
  libgl1-mesa-dri xvfb xauth             # Mesa's software OpenGL and a virtual X server (view tests)
  clang libclang-rt-14-dev # libFuzzer, for the fuzz targets of the file readers (fuzz/)
  rt-tests                 # cyclictest: the machine's own real-time floor beside the loop's figures
  libopenmpi-dev openmpi-bin   # `spinesim sweep` under mpirun (OpenMPI)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
