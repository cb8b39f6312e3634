#!/usr/bin/env bash
# Build, once, a Debian 13 (trixie) root folder holding Debian's Blender 4.3.2 (Python 3.13,
# NumPy 2.2) and what its GUI needs under Xvfb, for `make test-blender`.
#   tools/blender-env.sh ROOT
# ROOT is reused while it holds the mark of a finished build (packages added to the list below
# since are installed into it). The build happens in ROOT.partial and is renamed to ROOT only
# when complete, so an interrupted build never looks finished.
# Needs root (debootstrap, mount, chroot) and Debian's mirror (DEBIAN_MIRROR to use another).
set -euo pipefail

ROOT=${1:?usage: tools/blender-env.sh ROOT}
ROOT=${ROOT%/}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
MARK=.drt-blender-env
# Debian's blender only recommends python3-numpy; pytest runs the core tests on its Python 3.13, whose texture tests
# write and read images with python3-openimageio; xvfb, Mesa and ImageMagick's `import` run the GUI.
PACKAGES=(blender python3-numpy python3-openimageio python3-pytest xvfb xauth libgl1-mesa-dri libegl1 libgl1 imagemagick)
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

fail() { echo "blender-env: $*" >&2; exit 1; }

install_packages() {  # ROOT LOG
  ln -sf /proc/self/mounts "$1/etc/mtab"  # Blender lists the mounted file systems from it
  "$HERE/blender-chroot.sh" "$1" sh -c "apt-get update -q && \
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends ${PACKAGES[*]} && apt-get clean" \
    >> "$2" 2>&1 \
    || { tail -n 20 "$2" >&2; fail "installing packages in the Debian root failed (full log: $2)"; }
}

if [ -f "$ROOT/$MARK" ]; then
  if [ "$(sed -n 2p "$ROOT/$MARK")" != "packages: ${PACKAGES[*]}" ]; then
    [ "$(id -u)" = 0 ] || fail "$ROOT needs more packages, which needs root; run as root"
    echo "blender-env: installing ${PACKAGES[*]} into $ROOT"
    install_packages "$ROOT" "$ROOT.log"
    { sed -n 1p "$ROOT/$MARK"; echo "packages: ${PACKAGES[*]}"; } > "$ROOT/$MARK.new"
    mv "$ROOT/$MARK.new" "$ROOT/$MARK"
  fi
  echo "blender-env: reusing $ROOT ($(head -n 1 "$ROOT/$MARK"))"
  exit 0
fi
[ ! -e "$ROOT" ] || fail "$ROOT exists but is not a finished build; remove it (check that nothing is mounted under it) and run again"
[ "$(id -u)" = 0 ] || fail "building the Debian root needs root (debootstrap, mount and chroot); run as root"
if ! command -v debootstrap >/dev/null 2>&1; then
  command -v apt-get >/dev/null 2>&1 || fail "debootstrap is not installed and there is no apt-get to install it"
  echo "blender-env: installing debootstrap"
  apt-get install -y debootstrap >/dev/null || fail "could not install debootstrap with apt-get"
fi
curl -fsS --max-time 20 -o /dev/null "$MIRROR/dists/trixie/Release" \
  || fail "cannot reach Debian's mirror $MIRROR (set DEBIAN_MIRROR to a reachable one)"

PARTIAL=$ROOT.partial
if [ -e "$PARTIAL" ]; then
  if findmnt -rn -o TARGET | grep -qF -- "$PARTIAL/"; then
    fail "$PARTIAL has file systems mounted under it; unmount them first"
  fi
  echo "blender-env: removing the unfinished $PARTIAL"
  rm -rf --one-file-system "$PARTIAL"
fi
mkdir -p "$(dirname "$ROOT")"

start=$(date +%s)
echo "blender-env: debootstrap trixie into $PARTIAL (about 2 minutes)"
debootstrap --variant=minbase trixie "$PARTIAL" "$MIRROR" > "$PARTIAL.log" 2>&1 \
  || { tail -n 20 "$PARTIAL.log" >&2; fail "debootstrap failed (full log: $PARTIAL.log)"; }
cp /etc/resolv.conf "$PARTIAL/etc/resolv.conf"
echo "blender-env: apt-get install ${PACKAGES[*]} (about 3 minutes)"
install_packages "$PARTIAL" "$PARTIAL.log"
version=$("$HERE/blender-chroot.sh" "$PARTIAL" blender --version 2>/dev/null | head -n 1)
[[ $version == Blender* ]] || fail "blender does not run in $PARTIAL (full log: $PARTIAL.log)"
printf '%s\npackages: %s\n' "$version, built $(date -u +%FT%TZ)" "${PACKAGES[*]}" > "$PARTIAL/$MARK"
mv "$PARTIAL" "$ROOT"
mv "$PARTIAL.log" "$ROOT.log"
echo "blender-env: $version ready in $ROOT ($(( $(date +%s) - start )) s)"
