#!/usr/bin/env bash
# Installs the Debian packages Flexfit needs to build, test and run its demo, third-party
# meshes the tests read included.
# Idempotent and quiet: when every package is present it prints nothing and exits 0.
set -euo pipefail

packages=(
  build-essential cmake pkg-config     # toolchain
  ninja-build                          # builds every target's objects in parallel (CGAL's one TU alone takes 1-2 min)
  libeigen3-dev                        # linear algebra
  libassimp-dev                        # mesh import (OBJ, STL, PLY, OFF, glTF)
  libcli11-dev                         # command line
  libfmt-dev                           # formatting of the command-line output
  libgtest-dev libgmock-dev            # tests
  libbenchmark-dev                     # benchmarks
  libtomlplusplus-dev                  # scene files (TOML, with the line of every key)
  libcgal-dev                          # simulation remeshing (Polygon Mesh Processing)
  libfcl-dev                           # FCL: reference for collision tests and benchmarks
  python3-matplotlib                   # plots of experiment results (/usr/bin/python3)
  pybind11-dev python3-dev python3-numpy  # the Python module (NumPy views of the state)
  python3-pytest                       # the Python tests
  python3-distributed python3-pandas   # sweeps on a Dask cluster, their table as a DataFrame
  python3-vtk9                         # the tests read our VTK frames with VTK's own reader
  libglfw3-dev libimgui-dev            # viewer: window, input, user interface
  libgl-dev libegl-dev libegl-mesa0    # viewer: OpenGL 3.3, EGL surfaceless
  libgl1-mesa-dri                      # viewer: Mesa software rendering (llvmpipe)
  libpng-dev                           # viewer: PNG screenshots
  xvfb xauth                           # viewer tests: a virtual X server
  assimp-testmodels                    # third-party meshes: the tests read them (Wuson, damaged files), the benchmarks press tools into them
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
