#!/usr/bin/env bash
# Runs one command inside the OpenFOAM environment:
#
#   scripts/foam_env.sh blockMesh -case some/case
#
# Every OpenFOAM program (blockMesh, foamProbe, ...) needs the variables that OpenFOAM's bashrc
# exports (WM_PROJECT_DIR, to find etc/controlDict; FOAM_SIGFPE, ...).
#
#   GRAINFLOW_FOAM_BASHRC   environment file to source (default: Debian's
#                           /usr/share/openfoam/etc/bashrc)
#
# Debian's bashrc is sourced with `set -u` and `set -e` off: it expands unset variables and
# calls bin/foamEtcFile and bin/foamCleanPath, which Debian does not ship. Those two
# "No such file or directory" messages are harmless (only FOAM_API stays empty and PATH is not
# de-duplicated) and are filtered out; any other message of the bashrc is passed on.
set +eu

bashrc="${GRAINFLOW_FOAM_BASHRC:-/usr/share/openfoam/etc/bashrc}"
if [ "$#" -eq 0 ]; then
  echo "usage: $0 command [args...]  (runs the command in the OpenFOAM environment)" >&2
  exit 2
fi
if [ ! -r "$bashrc" ]; then
  echo "foam_env.sh: OpenFOAM environment file '$bashrc' not found;" \
    "run scripts/bootstrap.sh (installs Debian's openfoam) or set GRAINFLOW_FOAM_BASHRC." >&2
  exit 2
fi

errlog="$(mktemp "${TMPDIR:-/tmp}/foam_env.XXXXXX")" || exit 2
# The bashrc reads its own arguments from "$@" (e.g. WM_LABEL_SIZE=64): give it none.
_foam_env_args=("$@")
set --
# shellcheck disable=SC1090
. "$bashrc" 2>"$errlog"
grep -v -E '/bin/(foamEtcFile|foamCleanPath): No such file or directory$' "$errlog" >&2
rm -f "$errlog"

set -- "${_foam_env_args[@]}"
unset _foam_env_args errlog bashrc
exec "$@"
