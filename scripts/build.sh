#!/usr/bin/env bash
# Configures and builds softsight in ./build (Release). Extra arguments go to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
GENERATOR=()
command -v ninja >/dev/null && GENERATOR=(-G Ninja)
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build "${GENERATOR[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
elif [ $# -gt 0 ]; then
  # Configured again only when an option asks for something the cache does not hold already:
  # .ci/run builds first and scripts/test.sh then calls this with the same options, and a second
  # configure recompiled 30 targets (the stream's and the commands' flags came out different).
  again=0
  for arg in "$@"; do
    case $arg in
      -D*=*) kv=${arg#-D} name=${kv%%=*} name=${name%%:*} value=${kv#*=}
             grep -qxF -e "$name:BOOL=$value" -e "$name:STRING=$value" -e "$name:PATH=$value" \
               -e "$name:FILEPATH=$value" -e "$name:UNINITIALIZED=$value" build/CMakeCache.txt || again=1 ;;
      *) again=1 ;;
    esac
  done
  if [ "$again" = 1 ]; then cmake -S . -B build "$@"; fi
fi
cmake --build build --parallel "$(nproc)"
