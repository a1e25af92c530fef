#!/usr/bin/env bash
# The installed library and Python package, used as an outside project would (ctest install.*):
#   check-install.sh prefix   BUILD WORK  cmake --install of BUILD into WORK/prefix
#   check-install.sh cmake    BUILD WORK  examples/library built with find_package(softsight), run
#                                         (custom_kind: a kind of marker of its own, registered)
#   check-install.sh pkg-config BUILD WORK  the same sources built with `pkg-config softsight` and
#                                         `pkg-config softsight-track` only (tracking alone links
#                                         neither yaml-cpp, the serial port nor FFmpeg)
#   check-install.sh pip      BUILD WORK  `pip install --no-build-isolation .` into a fresh virtual
#                                         environment (reusing BUILD), imported, used, uninstalled
# Each step prints what it checks and exits non-zero at the first thing that is wrong.
set -euo pipefail
mode=$1 build=$(cd "$2" && pwd) work=$3
source_dir=$(cd "$(dirname "$0")/.." && pwd)
prefix=$work/prefix
config=$source_dir/examples/markers.yaml
fail() { echo "check-install ($mode): $*" >&2; exit 1; }

case $mode in
  prefix)
    rm -rf "$prefix"
    cmake --install "$build" --prefix "$prefix" >/dev/null
    for f in include/softsight/softsight.h include/softsight/pipeline/tracking_session.h \
             include/softsight/version.h bin/softsight; do
      [ -e "$prefix/$f" ] || fail "$f not installed"
    done
    # Only the API: what the program or the tests alone use is not installed.
    for f in include/softsight/gui include/softsight/sim/corruption.h \
             include/softsight/io/frame_grabber.h include/softsight/io/read_ahead_source.h \
             include/softsight/io/paced_source.h; do
      [ ! -e "$prefix/$f" ] || fail "$f installed, but it is not part of the library's API"
    done
    # The libraries: shared and versioned (or static, -DBUILD_SHARED_LIBS=OFF), one pkg-config
    # file per module and one for all.
    libdir=$(dirname "$(find "$prefix" -name softsight.pc | head -1)")/..
    if grep -q "^BUILD_SHARED_LIBS:BOOL=ON" "$build/CMakeCache.txt"; then
      version=$(sed -n 's/^Version: //p' "$libdir/pkgconfig/softsight.pc")
      for f in libsoftsight_core.so "libsoftsight_core.so.${version%.*}" "libsoftsight_core.so.$version"; do
        [ -e "$libdir/$f" ] || fail "$f not installed in $libdir"
      done
      soname=$(readelf -d "$libdir/libsoftsight_pipeline.so" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
      [ "$soname" = "libsoftsight_pipeline.so.${version%.*}" ] || fail "libsoftsight_pipeline.so's soname is '$soname'"
    fi
    for m in core geometry track sim calib control io config pipeline; do
      [ -e "$libdir/pkgconfig/softsight-$m.pc" ] || fail "softsight-$m.pc not installed"
    done
    # The installed program finds its plugins from where it was installed.
    "$prefix/bin/softsight" synth --help >/dev/null || fail "the installed program cannot run synth"
    echo "check-install: installed into $prefix"
    ;;
  cmake)
    out=$work/cmake-example
    rm -rf "$out"
    cmake -S "$source_dir/examples/library" -B "$out" -DCMAKE_PREFIX_PATH="$prefix" \
          -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$out" >/dev/null
    "$out/track_rendered" "$config" 30
    "$out/track_colour" 20
    "$out/custom_kind" "$work/custom-kind" 40
    ;;
  pkg-config)
    out=$work/pkg-config-example
    mkdir -p "$out"
    pc_dir=$(dirname "$(find "$prefix" -name softsight.pc | head -1)")
    [ -n "$pc_dir" ] || fail "no softsight.pc under $prefix"
    export PKG_CONFIG_PATH=$pc_dir
    # Shared libraries outside the system's folders: the programs find them with an rpath.
    rpath="-Wl,-rpath,$(pkg-config --variable=libdir softsight)"
    flags=$(pkg-config --cflags --libs softsight)
    # With the warnings CI builds softsight with: here (-I, unlike an imported CMake target's
    # -isystem) the installed headers must not warn in a user's build either, e.g. designated
    # initializers under -Wextra. OpenCV 4.6's own headers mix enums, which C++20 deprecates.
    # shellcheck disable=SC2086  # the flags are words
    c++ -std=c++20 -O1 -Wall -Wextra -Werror -Wno-deprecated-enum-enum-conversion \
        "$source_dir/examples/library/track_rendered.cc" -o "$out/track_rendered" $flags "$rpath"
    "$out/track_rendered" "$config" 30
    # shellcheck disable=SC2086
    c++ -std=c++20 -O1 -Wall -Wextra -Werror -Wno-deprecated-enum-enum-conversion \
        "$source_dir/examples/library/custom_kind.cc" -o "$out/custom_kind" $flags "$rpath"
    "$out/custom_kind" "$work/custom-kind-pc" 40
    # Tracking alone: the track module's flags name only it, the modules below it (geometry: the
    # marker finder's MeasureOptions; core) and OpenCV's core.
    flags=$(pkg-config --cflags --libs softsight-track)
    echo "check-install: pkg-config --libs softsight-track: $(pkg-config --libs softsight-track)"
    if grep -q "^BUILD_SHARED_LIBS:BOOL=ON" "$build/CMakeCache.txt"; then
      for lib in $(pkg-config --libs-only-l softsight-track); do
        case $lib in -lsoftsight_track|-lsoftsight_geometry|-lsoftsight_core|-lopencv_core) ;; *) fail "softsight-track links $lib" ;; esac
      done
    fi
    # shellcheck disable=SC2086
    c++ -std=c++20 -O1 "$source_dir/examples/library/track_colour.cc" -o "$out/track_colour" $flags "$rpath"
    "$out/track_colour" 20
    needed=$(readelf -d "$out/track_colour" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
    case $needed in *serial*|*avformat*|*yaml*|*softsight_io*|*softsight_config*) fail "track_colour needs $needed" ;; esac
    echo "check-install: track_colour needs only: $needed"
    ;;
  pip)
    venv=$work/venv
    rm -rf "$venv"
    # The interpreter the build was configured for (ctest passes it; a pyenv python3 first on PATH
    # lacks Debian's numpy, setuptools and wheel).
    "${SOFTSIGHT_PYTHON:-/usr/bin/python3}" -m venv --system-site-packages "$venv"  # numpy, dask: Debian
    # pip builds in the source tree; SOFTSIGHT_BUILD_DIR makes it reuse this build's extension.
    # Its own temporary folder and no cache: nothing shared with other pip runs on the machine.
    mkdir -p "$work/pip-tmp"
    if ! (cd "$source_dir" && TMPDIR=$work/pip-tmp SOFTSIGHT_BUILD_DIR=$build PIP_NO_INDEX=1 \
          PIP_NO_CACHE_DIR=1 "$venv/bin/pip" install --no-build-isolation --no-deps . \
          > "$work/pip-install.log" 2>&1); then
      tail -n 30 "$work/pip-install.log" >&2
      fail "pip install failed (whole log: $work/pip-install.log)"
    fi
    cd "$work"   # Not the source tree: the package must come from the environment.
    env -u PYTHONPATH "$venv/bin/python" - "$config" <<'PY'
import sys, softsight, importlib.metadata as m
assert softsight.__file__.startswith(sys.prefix), softsight.__file__
# The extension and the shared libraries it links (when the build has them) come from the
# environment, not from the build tree.
loaded = {line.split()[-1] for line in open("/proc/self/maps") if "softsight" in line and ".so" in line}
outside = [f for f in loaded if not f.startswith(sys.prefix)]
assert not outside, f"loaded from outside the environment: {outside}"
assert m.version("softsight") == softsight.__version__
table = softsight.track("synth:bending", sys.argv[1], max_frames=10)
found = int(table["red_found"].sum())
assert found == 10, f"red found in {found} of 10 frames"
print("check-install: pip-installed softsight", softsight.__version__, "found red in", found, "of 10 frames")
PY
    "$venv/bin/pip" uninstall -y -q softsight || fail "pip uninstall failed"
    left=$(find "$venv/lib" -maxdepth 3 -name 'softsight*')
    [ -z "$left" ] || fail "pip uninstall left $left"
    echo "check-install: pip uninstall removed it"
    ;;
  *) fail "unknown mode (prefix, cmake, pkg-config, pip)" ;;
esac
