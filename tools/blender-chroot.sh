#!/usr/bin/env bash
# Run one command inside the Debian root made by tools/blender-env.sh:
#   tools/blender-chroot.sh ROOT COMMAND [ARGS...]
# /proc and /dev are bind-mounted for the command's lifetime only and always unmounted again
# (also on failure or interruption); mounts that were already there are left as they were.
# The command gets a clean environment (HOME=/root, C.UTF-8, DISPLAY if set here).
set -euo pipefail

ROOT=${1:?usage: tools/blender-chroot.sh ROOT COMMAND [ARGS...]}
shift
[ $# -gt 0 ] || { echo "usage: tools/blender-chroot.sh ROOT COMMAND [ARGS...]" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "blender-chroot: chroot needs root" >&2; exit 1; }
[ -x "$ROOT/bin/sh" ] || { echo "blender-chroot: $ROOT is not a Debian root (run make blender-env)" >&2; exit 1; }

mounted=()
unmount() {
  local i
  for (( i=${#mounted[@]}-1; i>=0; i-- )); do
    umount "${mounted[i]}" || umount -l "${mounted[i]}" || echo "blender-chroot: could not unmount ${mounted[i]}" >&2
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
env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
  ${DISPLAY:+DISPLAY=$DISPLAY} chroot "$ROOT" "$@"
