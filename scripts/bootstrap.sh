#!/usr/bin/env bash
# Installs every grainflow dependency from Debian 12 packages and prepares the
# OpenFOAM v1912 headers (Debian ships the libraries but no headers) from the
# matching Debian source package into a cache outside the work tree.
#
# Idempotent: a second run checks, finds nothing to do, and returns in seconds.
#
#   GRAINFLOW_CACHE   where the OpenFOAM source and its lnInclude trees live
#                     (default: /var/cache/grainflow)
set -euo pipefail

CACHE="${GRAINFLOW_CACHE:-/var/cache/grainflow}"
export DEBIAN_FRONTEND=noninteractive

PACKAGES=(
  build-essential cmake ninja-build pkg-config dpkg-dev
  openfoam libopenfoam
  openmpi-bin libopenmpi-dev
  libeigen3-dev
  libhdf5-openmpi-dev hdf5-tools
  googletest libgtest-dev libgmock-dev
  libyaml-cpp-dev
  clang libclang-rt-14-dev
  python3 python3-numpy python3-matplotlib python3-h5py python3-yaml
  paraview python3-paraview xvfb
)

log() { printf '[bootstrap] %s\n' "$*"; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# --- 1. Debian packages -------------------------------------------------------
missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  log "installing: ${missing[*]}"
  as_root apt-get update -qq
  as_root apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  log "all Debian packages present"
fi

# --- 2. OpenFOAM headers from the matching source package ---------------------
STAMP="$CACHE/openfoam-headers.stamp"
FOAM_VERSION="$(dpkg-query -W -f='${source:Version}' libopenfoam)"
if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$FOAM_VERSION" ]; then
  log "OpenFOAM headers ready in $CACHE (source $FOAM_VERSION)"
  exit 0
fi

SRC_LIST=/etc/apt/sources.list.d/grainflow-deb-src.sources
if ! apt-get indextargets --format '$(CREATED_BY)' 2>/dev/null | grep -q '^Sources$'; then
  log "enabling bookworm deb-src entry ($SRC_LIST)"
  as_root tee "$SRC_LIST" >/dev/null <<'SRC'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  as_root apt-get update -qq
fi

as_root mkdir -p "$CACHE"
work="$(mktemp -d "$CACHE/.src.XXXXXX")"
log "fetching openfoam source $FOAM_VERSION into $CACHE"
( cd "$work" && apt-get source -qq "openfoam=$FOAM_VERSION" >/dev/null )
srcdir="$(find "$work" -mindepth 1 -maxdepth 1 -type d -name 'openfoam-*' | head -n1)"
[ -n "$srcdir" ] || { log "error: apt-get source produced no openfoam-* folder in $work"; exit 1; }

# The source's own wmakeLnInclude builds each library's flat lnInclude folder.
export WM_PROJECT_DIR="$srcdir"
for lib in OpenFOAM OSspecific/POSIX finiteVolume meshTools; do
  ( cd "$srcdir/src/$lib" && "$srcdir/wmake/wmakeLnInclude" -silent . )
done

rm -rf "$CACHE/openfoam-src"
mv "$srcdir" "$CACHE/openfoam-src"
rm -rf "$work"
echo "$FOAM_VERSION" > "$STAMP"
log "OpenFOAM headers ready in $CACHE/openfoam-src"
