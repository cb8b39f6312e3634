#!/usr/bin/env bash
# Run one command inside the Debian root made by tools/blender-env.sh:
#   tools/blender-chroot.sh [--timeout SECONDS] ROOT COMMAND [ARGS...]
# /proc and /dev are bind-mounted for the command's lifetime only and always unmounted again
# (also on failure, interruption or timeout); mounts that were already there are left as they
# were. With --timeout the command's whole process group (Xvfb, Blender, ...) gets TERM after
# SECONDS and KILL 10 s later, and this script still unmounts and exits with 124.
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

mounted=()
unmount() {
  local i
  for (( i=${#mounted[@]}-1; i>=0; i-- )); do
    umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" \
      || echo "blender-chroot: could not unmount ${mounted[i]}" >&2
  done
}
trap unmount EXIT
trap 'exit 130' INT TERM HUP
for dir in proc dev; do
  if ! mountpoint -q "$ROOT/$dir"; then
    mount --bind "/$dir" "$ROOT/$dir"
    mounted+=("$ROOT/$dir")
  fi
done
status=0
env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
  ${DISPLAY:+DISPLAY=$DISPLAY} "${limit[@]}" chroot "$ROOT" "$@" || status=$?
[ "$status" != 124 ] || echo "blender-chroot: timed out after ${limit[2]} s: $*" >&2
exit "$status"
