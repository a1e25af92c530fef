#!/bin/sh
# Copies the shared board code (protocol + inner loop) into the sketch's src/ folder, which the
# Arduino IDE and arduino-cli compile with the sketch. Run again after changing the shared code.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
dst="$here/softsight_board/src"
mkdir -p "$dst"
for f in include/softsight/control/board_config.h src/control/protocol.h src/control/board.h \
         src/control/protocol.cc src/control/board.cc; do
  name=$(basename "$f")
  case "$name" in *.cc) name="${name%.cc}.cpp" ;; esac
  sed -e 's|#include "softsight/control/|#include "|' -e 's|#include "control/|#include "|' \
    "$root/$f" > "$dst/$name"
done
echo "shared code copied to $dst"
