#!/usr/bin/env bash
# Installs every Debian package softsight needs to build, test, benchmark and run its demo.
# Non-interactive and idempotent: packages already present are left alone. Run as root or with sudo.
#   scripts/setup.sh           what the build, the tests and CI need
#   scripts/setup.sh deb       also what the Debian package needs (scripts/package-deb.sh: man pages
#                              by help2man, dpkg-shlibdeps) and its check (scripts/check-deb.sh:
#                              debootstrap makes the clean Debian 12 root)
#   scripts/setup.sh docs      also doxygen, for the API reference (`cmake --build build --target docs`)
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  lld                    # the linker (CMakeLists.txt: -fuse-ld=lld, much faster than GNU ld's links)
  libopencv-dev          # image processing, video I/O, calibration, GUI (OpenCV 4.6)
  libavutil-dev          # FFmpeg's log (OpenCV decodes with FFmpeg): which frames a decoder found damaged
  libavcodec-dev libavformat-dev  # FFmpeg's own marks of the frames it concealed damage in
  libswscale-dev         # H.264/MPEG-4 frames converted to BGR as OpenCV does (io/libav_video_reader.h)
  libyaml-cpp-dev        # configuration files
  libcli11-dev           # command-line parsing
  libserial-dev          # serial link to the pneumatic board
  libaravis-dev aravis-tools libusb-1.0-0-dev  # GenICam cameras (--camera aravis:ID); Debian 12's aravis-0.8.pc needs libusb-1.0.pc too
  libzmq3-dev cppzmq-dev nlohmann-json3-dev  # --publish / listen / --target-from: ZeroMQ and its JSON records
  libgtest-dev libgmock-dev  # tests
  libbenchmark-dev       # benchmarks
  xvfb xauth xdotool     # the live window's tests run under a virtual X server
  libx11-dev             # the live window checks the X display before opening a window
  opencv-doc             # real sample images with known answers for the golden tests (chessboards, ...)
  clang libfuzzer-14-dev # fuzz targets (scripts/fuzz.sh): clang's libFuzzer with ASan + UBSan
  pybind11-dev python3-dev python3-numpy python3-pytest python3-dask python3-distributed python3-opencv  # the Python package (python/), its tests and Dask batch runs
  python3-venv python3-pip python3-setuptools python3-wheel  # `pip install .` (setup.py) and its check in a fresh virtual environment
  mypy python3-tqdm      # the stubs' `mypy --strict` test; progress=True's bar (the tests cover it with and without)
  python3-zmq            # softsight.stream.subscribe (the stream's Python end) and its test
  python3-pandas         # Table.to_pandas(), track_many's summary and stream.to_dataframe, as docs/python.md uses them
  libboost-dev           # softsight serve: Boost.Beast and Boost.Asio (header-only), the web server
  chromium chromium-driver python3-selenium  # serve's end-to-end test drives the page in a headless browser
)

for group in "$@"; do
  case $group in
    deb) PACKAGES+=(help2man dpkg-dev debootstrap) ;;
    docs) PACKAGES+=(doxygen) ;;
    *) echo "setup: unknown group '$group' (deb, docs)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
