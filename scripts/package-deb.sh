#!/usr/bin/env bash
# Builds the Debian package, build-deb/softsight_<version>_<arch>.deb (cmake/package.cmake says what
# it holds), in its own tree configured for Debian's folders: /usr, the shared libraries in
# /usr/lib/<arch>, the Python module in /usr/lib/python3/dist-packages, man pages from --help.
# No tests or benchmarks in that tree: the first run compiles the program, the library and the
# Python module (~10 min on 2 cores), later runs only what changed.
#   scripts/package-deb.sh                 # then: sudo apt-get install ./build-deb/softsight_*.deb
#   scripts/package-deb.sh -DFOO=BAR       # extra CMake options for the first configure
# SOFTSIGHT_DEB_BUILD names another tree than build-deb/. An existing tree is set to the package's
# folders (/usr), man pages and Debian's python3 and built again: CI packages its tested build/
# that way (.ci/run), which recompiles only the launcher (it holds the plugins' folder relative to
# its own) instead of a third build of everything. Note that a tree set to /usr installs its
# libraries without an rpath: install it under /usr, or make the package.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh deb
build=${SOFTSIGHT_DEB_BUILD:-build-deb}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$build/CMakeCache.txt" ]; then
  # Debian's python3 (a pyenv or virtualenv python3 first on PATH is not what the package's
  # module is for).
  cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
        -DBUILD_SHARED_LIBS=ON -DSOFTSIGHT_MAN_PAGES=ON -DSOFTSIGHT_BUILD_TESTS=OFF \
        -DSOFTSIGHT_BUILD_BENCHMARKS=OFF -DPython3_EXECUTABLE=/usr/bin/python3 "$@"
else
  cmake -S . -B "$build" -DCMAKE_INSTALL_PREFIX=/usr -DBUILD_SHARED_LIBS=ON -DSOFTSIGHT_MAN_PAGES=ON \
        -DPython3_EXECUTABLE=/usr/bin/python3 "$@" >/dev/null
fi
cmake --build "$build" --parallel "$(nproc)"
rm -f "$build"/softsight_*.deb
(cd "$build" && cpack -G DEB)
deb=$(ls "$build"/softsight_*.deb)
echo "package-deb: $deb ($(du -h "$deb" | cut -f1))"
