#!/usr/bin/env bash
# Create (if missing) the virtual environment VENV with Python X.Y and install REQUIREMENTS into it.
#   tools/venv.sh VENV REQUIREMENTS X.Y PYTHON
# The wheels are downloaded once into WHEELHOUSE (default: the user's cache, ~/.cache/drt/wheelhouse)
# and installed from there: a fresh clone's venvs then cost no download (the bpy wheels are 350 to
# 400 MB each), which pip's own HTTP cache does not give on every machine.
# PYTHON is the interpreter to create it with (a name on PATH or a path). When it does not run as
# Python X.Y (missing, or a pyenv shim for a version that is not selected), pyenv's own install of
# X.Y is used if there is one, so a machine with pyenv needs no PATH changes.
set -euo pipefail

VENV=${1:?usage: tools/venv.sh VENV REQUIREMENTS X.Y PYTHON}
REQUIREMENTS=${2:?} VERSION=${3:?} PYTHON=${4:?}
WHEELHOUSE=${WHEELHOUSE:-${XDG_CACHE_HOME:-$HOME/.cache}/drt/wheelhouse}

is_version() {  # INTERPRETER: runs and is Python $VERSION
  "$1" -c "import sys; sys.exit(f'{sys.version_info[0]}.{sys.version_info[1]}' != '$VERSION')" >/dev/null 2>&1
}

if [ ! -x "$VENV/bin/python" ]; then
  found=
  for candidate in "$PYTHON" "${PYENV_ROOT:-$HOME/.pyenv}"/versions/"$VERSION"*/bin/python"$VERSION"; do
    if is_version "$candidate"; then found=$candidate; break; fi
  done
  if [ -z "$found" ]; then
    echo "error: no Python $VERSION found ($PYTHON does not run as Python $VERSION, nor does any pyenv install);" \
         "install it, or pass its path in the make variable for it (e.g. PYTHON${VERSION/./}=/path/to/python$VERSION)" >&2
    exit 1
  fi
  echo "creating $VENV with $(command -v "$found")"
  "$found" -m venv "$VENV"
fi
is_version "$VENV/bin/python" || {
  echo "error: $VENV is not a Python $VERSION environment; remove it and run make again" >&2; exit 1; }
mkdir -p "$WHEELHOUSE"
# pip download keeps the files already in WHEELHOUSE; the install then needs no index.
"$VENV/bin/python" -m pip download --disable-pip-version-check --quiet --only-binary=:all: \
  --dest "$WHEELHOUSE" -r "$REQUIREMENTS"
"$VENV/bin/python" -m pip install --disable-pip-version-check --no-index --find-links "$WHEELHOUSE" -r "$REQUIREMENTS"
