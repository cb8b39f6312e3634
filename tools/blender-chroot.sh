#!/usr/bin/env bash
# Run one command inside the Debian root made by tools/blender-env.sh:
#   tools/blender-chroot.sh [--timeout SECONDS] ROOT COMMAND [ARGS...]
# /proc and /dev are bind-mounted in a private mount namespace made for this command only
# (unshare --mount): nobody else sees them, and they are gone when the command ends, however
# it ends (error, interruption, timeout, even SIGKILL); concurrent commands never share them.
# With --timeout the command's whole process group (Xvfb, Blender, ...) gets TERM after
# SECONDS and KILL 10 s later, and this script exits with 124.
# The command gets a clean environment (HOME=/root, C.UTF-8, DISPLAY if set here).
set -euo pipefail

usage="usage: tools/blender-chroot.sh [--timeout SECONDS] ROOT COMMAND [ARGS...]"
limit=()
if [ "${1:-}" = --timeout ]; then
  [[ ${2:-} =~ ^[0-9]+$ ]] || { echo "$usage" >&2; exit 2; }
  limit=(timeout --kill-after=10 "$2")
  shift 2
fi
ROOT=${1:?$usage}
shift
[ $# -gt 0 ] || { echo "$usage" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "blender-chroot: chroot needs root" >&2; exit 1; }
[ -x "$ROOT/bin/sh" ] || { echo "blender-chroot: $ROOT is not a Debian root (run make blender-env)" >&2; exit 1; }
command -v unshare >/dev/null || { echo "blender-chroot: needs unshare (util-linux)" >&2; exit 1; }

status=0
env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
  ${DISPLAY:+DISPLAY=$DISPLAY} "${limit[@]}" unshare --mount --propagation private -- sh -c \
  'root=$1; shift; mount --bind /proc "$root/proc" && mount --bind /dev "$root/dev" && exec chroot "$root" "$@"' \
  sh "$ROOT" "$@" || status=$?
[ "$status" != 124 ] || echo "blender-chroot: timed out after ${limit[2]} s: $*" >&2
exit "$status"
