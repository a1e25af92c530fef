#!/usr/bin/env bash
# The Debian package as a user meets it (issue 47): builds it (scripts/package-deb.sh), makes a
# clean Debian 12 root, installs the package there with `apt-get install ./softsight_*.deb` (its
# Depends alone: no recommended packages) and uses it in that root (chroot):
#   1. softsight --version, the man page, `softsight demo` (the README's first command);
#   2. python3 -c "import softsight", and a few frames tracked from Python;
#   3. with a compiler, cmake and pkg-config installed as a user would: `pkg-config --cflags --libs
#      softsight`, examples/library built with find_package(softsight) and run, and its tracking-only
#      program built with `pkg-config softsight-track` alone, run, and checked to link neither
#      yaml-cpp, libserial nor FFmpeg.
# Needs root (debootstrap, chroot, mounting /proc in the root) and Debian's mirrors.
#   scripts/check-deb.sh              builds build-deb/'s package (scripts/package-deb.sh), checks it
#   scripts/check-deb.sh DEB          checks the package DEB (CI: the one cpack made from build/)
#   scripts/check-deb.sh --wait FILE  makes the clean root and fetches the packages it will install
#                                     now, then waits for FILE to hold the package's path (or
#                                     "skip") and checks it: CI starts this at its beginning, so the
#                                     network- and disk-bound part runs beside the compilers
# Downloads (debootstrap's and apt's .debs) are kept between runs in SOFTSIGHT_DEB_CACHE (default
# build-deb/check-deb; CI: /var/cache/softsight-ci/check-deb, like a CI's cache of apt downloads):
# only downloads, so every run still makes its root from Debian's packages and installs into it;
# an empty or missing cache is filled, the run only slower. Measured on a loaded 2-core machine:
# the package's first build 11 min (scripts/package-deb.sh); then the first check 410 s
# (debootstrap 136 s, apt-get installing the package and its 391 dependencies 173 s, the demo
# 12 s, the outside builds 54 s); docs/measurements.md has CI's numbers.
#   SOFTSIGHT_DEB_MIRROR=http://...   another Debian mirror (default deb.debian.org)
set -euo pipefail
cd "$(dirname "$0")/.."
source_dir=$PWD
start=$SECONDS
step() { echo "check-deb: [$((SECONDS - start)) s] $*"; }
fail() { echo "check-deb: FAILED: $*" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || fail "needs root (debootstrap, chroot): sudo $0"

build=${SOFTSIGHT_DEB_BUILD:-build-deb}
deb="" wait_file=""
case ${1:-} in
  "") scripts/package-deb.sh
      deb=$(ls "$build"/softsight_*.deb)
      step "package built: $deb ($(du -h "$deb" | cut -f1))" ;;
  --wait) wait_file=${2:?"--wait FILE"}; rm -f "$wait_file"
          scripts/setup.sh deb >/dev/null ;;
  *) deb=$(realpath "$1"); [ -f "$deb" ] || fail "no package $1" ;;
esac

cache=$(realpath -m "${SOFTSIGHT_DEB_CACHE:-build-deb/check-deb}")
work=$PWD/$build/check-deb-run  # This run's root (removed at the end) and logs (kept).
rm -rf --one-file-system "$work" && mkdir -p "$work"
mirror=${SOFTSIGHT_DEB_MIRROR:-http://deb.debian.org/debian}
archives=$cache/apt-archives  # Downloaded packages, kept between runs.
root=$work/root
mkdir -p "$cache/debootstrap" "$archives/partial"

cleanup() {
  for m in var/cache/apt/archives proc; do
    if mountpoint -q "$root/$m" 2>/dev/null; then umount "$root/$m"; fi
  done
  # --one-file-system: never follow a mount left behind out of the root.
  if [ -d "$root" ]; then rm -rf --one-file-system "$root"; fi
}
trap cleanup EXIT
trap 'exit 143' TERM INT  # (stopped by CI when the suite fails first: the EXIT trap still cleans up)

# A minimal Debian 12 (debootstrap's minbase: apt, dpkg, bash, coreutils), made afresh each run
# from the cached .debs. dpkg's force-unsafe-io, as Debian's own build roots (sbuild, pbuilder)
# use: no fsync per file in a root that is thrown away (the ~400 packages' unpacking was
# disk-bound).
debootstrap --variant=minbase --cache-dir="$cache/debootstrap" bookworm "$root" "$mirror" \
  > "$work/debootstrap.log" 2>&1 ||
  { tail -n 20 "$work/debootstrap.log"; fail "debootstrap (log: $work/debootstrap.log)"; }
cat > "$root/etc/apt/sources.list" <<SOURCES
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
SOURCES
echo force-unsafe-io > "$root/etc/dpkg/dpkg.cfg.d/softsight-unsafe-io"
step "clean Debian 12 root made (debootstrap minbase)"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount --bind "$archives" "$root/var/cache/apt/archives"
# Nothing in the root starts services while packages are installed.
printf '#!/bin/sh\nexit 101\n' > "$root/usr/sbin/policy-rc.d" && chmod +x "$root/usr/sbin/policy-rc.d"
in_root() { chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
                   DEBIAN_FRONTEND=noninteractive "$@"; }

in_root apt-get update -qq
# Fetched now, installed by nothing: the package's Depends as they were last (libopencv-dev and
# the runtime libraries dpkg-shlibdeps names) and the tools step 3 installs. Only downloads (into
# the cache): the root stays clean, `apt-get install ./softsight_*.deb` below resolves the real
# Depends, and a name missing here is downloaded there (slower, not wrong).
in_root apt-get install --download-only -y -qq --no-install-recommends libopencv-dev python3 \
  python3-numpy libserial1 libyaml-cpp0.7 libzmq5 libaravis-0.8-0 libx11-6 \
  g++ cmake make pkg-config > "$work/apt-prefetch.log" 2>&1 ||
  { tail -n 5 "$work/apt-prefetch.log"; echo "check-deb: (fetching ahead failed: apt-get install fetches)"; }
step "packages fetched ($(find "$archives" -maxdepth 1 -name '*.deb' | wc -l) .debs in $archives)"
if [ -n "$wait_file" ]; then
  until [ -s "$wait_file" ]; do sleep 2; done
  deb=$(cat "$wait_file")
  if [ "$deb" = skip ]; then step "no package to check (skip)"; exit 0; fi
  [ -f "$deb" ] || fail "no package $deb"
fi
cp "$deb" "$root/tmp/"
mkdir -p "$root/tmp/example"
cp examples/library/CMakeLists.txt examples/library/*.cc "$root/tmp/example/"
cp examples/markers.yaml "$root/tmp/"
step "root ready, installing $(basename "$deb")"
in_root sh -c 'cd /tmp && apt-get install -y -qq --no-install-recommends ./softsight_*.deb' \
  > "$work/apt-install.log" 2>&1 || { tail -n 30 "$work/apt-install.log"; fail "apt-get install ./softsight_*.deb"; }
installed=$(grep -c "^Setting up " "$work/apt-install.log" || true)
step "installed with its dependencies ($installed packages set up)"

# 1. The program, its man page and the demo.
in_root softsight --version
in_root test -f /usr/share/man/man1/softsight.1.gz || fail "no softsight.1.gz"
in_root test -f /usr/share/man/man1/softsight-track.1.gz || fail "no softsight-track.1.gz"
in_root sh -c 'cd /tmp && softsight demo --out-dir /tmp/demo_out' > "$work/demo.log" 2>&1 ||
  { cat "$work/demo.log"; fail "softsight demo"; }
tail -n 4 "$work/demo.log"
in_root sh -c 'ls /tmp/demo_out/*.csv' >/dev/null || fail "softsight demo wrote no CSV"
step "softsight demo ran"

# 2. Python: Debian's python3 finds the module in /usr/lib/python3/dist-packages.
in_root python3 -c "
import softsight
assert softsight.__file__.startswith('/usr/lib/python3/dist-packages/'), softsight.__file__
table = softsight.track('synth:bending', '/tmp/markers.yaml', max_frames=10)
found = int(table['red_found'].sum())
assert found == 10, found
print('check-deb: python3: softsight', softsight.__version__, 'from', softsight.__file__, '- red found in', found, 'of 10 frames')
"
step "python3 -c 'import softsight' ran"

# 3. Building against the library, with the tools a user installs for that.
in_root apt-get install -y -qq --no-install-recommends g++ cmake make pkg-config \
  > "$work/apt-tools.log" 2>&1 || { tail -n 30 "$work/apt-tools.log"; fail "installing g++ cmake make pkg-config"; }
echo "check-deb: pkg-config --cflags --libs softsight: $(in_root pkg-config --cflags --libs softsight)"
echo "check-deb: pkg-config --cflags --libs softsight-track: $(in_root pkg-config --cflags --libs softsight-track)"
# (The compilers' output goes to a log: OpenCV 4.6's headers warn under C++20 without -isystem.)
in_root sh -c 'cmake -S /tmp/example -B /tmp/example/build -DCMAKE_BUILD_TYPE=Release &&
               cmake --build /tmp/example/build' > "$work/example-cmake.log" 2>&1 ||
  { tail -n 30 "$work/example-cmake.log"; fail "the find_package(softsight) example did not build"; }
in_root /tmp/example/build/track_rendered /tmp/markers.yaml 30
in_root /tmp/example/build/track_colour 20
in_root /tmp/example/build/custom_kind /tmp/custom-kind 40
in_root sh -c 'c++ -std=c++20 -O1 /tmp/example/track_rendered.cc -o /tmp/track_rendered_pc \
               $(pkg-config --cflags --libs softsight) &&
               c++ -std=c++20 -O1 /tmp/example/track_colour.cc -o /tmp/track_colour_pc \
               $(pkg-config --cflags --libs softsight-track)' > "$work/example-pkg-config.log" 2>&1 ||
  { tail -n 30 "$work/example-pkg-config.log"; fail "the pkg-config builds"; }
in_root /tmp/track_rendered_pc /tmp/markers.yaml 30
in_root /tmp/track_colour_pc 20
needed=$(in_root sh -c 'ldd /tmp/track_colour_pc' | awk '{print $1}' | tr '\n' ' ')
case $needed in
  *serial*|*avformat*|*avcodec*|*yaml*|*softsight_io*|*softsight_config*) fail "track_colour loads $needed" ;;
esac
echo "check-deb: tracking alone loads $(echo "$needed" | wc -w) libraries, none of yaml-cpp, libserial or FFmpeg"
step "find_package(softsight) and pkg-config builds ran"
echo "check-deb: all checks passed in $((SECONDS - start)) s"
