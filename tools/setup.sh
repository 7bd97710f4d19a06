#!/usr/bin/env bash
# Sets bedforge up on Debian 12 and then runs what is asked:
#   bash tools/setup.sh demo   install what is missing, build, run scenes/default.toml (bed to OpenFOAM case)
#   bash tools/setup.sh test   install what is missing, build, run the whole test suite
#   bash tools/setup.sh        install what is missing and build
# apt-get runs only when a package is absent. Run as root, or as a user with sudo.
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  demo|test|"") ;;
  *) echo "setup: unknown action '$1'; allowed: demo, test, or nothing" >&2; exit 2 ;;
esac

# What the program needs to build and run a scene to its answer; the demo installs only these.
packages=(g++ cmake make ninja-build pkg-config libeigen3-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libfmt-dev
          libcgal-dev libtbb-dev libgoogle-perftools-dev gmsh libgmsh-dev openfoam time)
# The rest builds the test suite (GoogleTest; the fuzz targets: clang, its libFuzzer runtime and
# its OpenMP) and runs the tools' plots (numpy, matplotlib).
if [ "${1:-}" != demo ]; then
  packages+=(libgtest-dev python3-numpy python3-matplotlib)
  if [ "${1:-}" = test ]; then packages+=(clang libclang-rt-14-dev libomp-dev); fi
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" = 0 ] || sudo=sudo
  echo "setup: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# OpenFOAM's programs abort without it (sourcing its etc/bashrc does not work on Debian).
export WM_PROJECT_DIR="${WM_PROJECT_DIR:-/usr/share/openfoam}"

# The test suite must not shrink quietly: every stage is required, and OpenFOAM's programs too.
require=OFF
if [ "${1:-}" = test ]; then
  require=ON
  for program in checkMesh simpleFoam snappyHexMesh; do
    command -v "$program" >/dev/null || { echo "setup: $program is not on PATH; the case tests need OpenFOAM (apt-get install openfoam)" >&2; exit 1; }
  done
fi
# The demo needs the program only; the test suite, everything. Ninja for a new build directory
# (an existing one keeps the generator it was made with).
tests=ON target=() generator=()
if [ "${1:-}" = demo ]; then tests=OFF target=(--target bedforge); fi
if [ ! -f build/CMakeCache.txt ]; then generator=(-G Ninja); fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DBEDFORGE_REQUIRE_ALL_STAGES=$require -DBEDFORGE_BUILD_TESTS=$tests
cmake --build build -j"$(nproc)" "${target[@]}"

case "${1:-}" in
  # Rerunnable: replaces out/default/case. Ends in the bed's pressure drop with its band; exit
  # status 4 when OpenFOAM is missing (the case is written, not solved).
  demo) ./build/bedforge run scenes/default.toml -o out/default --overwrite ;;
  test)
    ctest --test-dir build --output-on-failure -j"$(nproc)"
    # The fuzz targets: clang with libFuzzer and sanitizers, packer and importers only (which
    # also proves that build works without CGAL, gmsh and OpenFOAM); 30 s each.
    cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBEDFORGE_FUZZ=ON \
          -DBEDFORGE_WITH_CGAL=OFF -DBEDFORGE_WITH_GMSH=OFF -DBEDFORGE_BUILD_TESTS=OFF >/dev/null
    cmake --build build-fuzz -j"$(nproc)"
    ctest --test-dir build-fuzz --output-on-failure ;;
  *) ;;
esac
