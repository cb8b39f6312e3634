#!/bin/sh
# Inside the root: Blender's GUI on a 1280x720 Xvfb screen (the maximised 3D view's region is the
# 1280x720 of the timed viewport steps), driven by gui_driver.py.
#   sh gui.sh BLEND OUTDIR
# Xvfb picks a free display itself (its abstract socket is shared with the host and other
# roots) and is killed on every way out; the wrapper's timeout kills the whole group anyway.
set -eu
: > "$2/display"
Xvfb -displayfd 3 -screen 0 1280x720x24 -nolisten tcp 3> "$2/display" > "$2/xvfb.log" 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; wait $xvfb 2>/dev/null || true' EXIT  # wait: gone before the test looks
trap 'exit 143' TERM INT HUP  # so the EXIT trap also runs when the wrapper's timeout fires
for _ in $(seq 200); do [ -s "$2/display" ] && break; sleep 0.1; done
[ -s "$2/display" ] || { echo "Xvfb did not start" >&2; cat "$2/xvfb.log" >&2; exit 1; }
DISPLAY=":$(cat "$2/display")" PYTHONWARNINGS=default blender --python-use-system-env "$1" \
  --python "$(dirname "$0")/gui_driver.py" -- "$2" > "$2/blender.log" 2>&1
