#!/bin/sh
# Inside the root: Blender's GUI on a 1600x900 Xvfb screen, driven by gui_driver.py.
#   sh gui.sh BLEND OUTDIR
set -eu
rm -f /tmp/.X99-lock /tmp/.X11-unix/X99  # left by an earlier run that was killed
Xvfb :99 -screen 0 1600x900x24 -nolisten tcp > "$2/xvfb.log" 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -e /tmp/.X11-unix/X99 ] && break; sleep 0.1; done
DISPLAY=:99 blender "$1" --python "$(dirname "$0")/gui_driver.py" -- "$2" > "$2/blender.log" 2>&1
