#!/usr/bin/env bash
# Runs Python with the modules a grainflow script needs (h5py, numpy, yaml, matplotlib): the
# first of $GRAINFLOW_PYTHON, /usr/bin/python3 and the python3 on PATH that imports them all.
# The python3 first on PATH may lack them (a pyenv or conda one); Debian's /usr/bin/python3
# has them with `apt install python3-h5py python3-numpy python3-yaml python3-matplotlib`.
#
#   scripts/python.sh SCRIPT.py [ARGS...]          needs what SCRIPT.py imports of the four
#   scripts/python.sh --needs h5py,numpy [ARGS...]  needs these (for `- <<'PY'` and -c)
#   scripts/python.sh --which (SCRIPT.py | --needs MODULES)   prints the interpreter's path
#
# Every tutorial, benchmark, test and CMake check finds its interpreter through this file.
# When none fits it prints one message (the modules, the interpreters tried, the fix) and
# exits 1.
set -euo pipefail

which_only=0
if [ "${1:-}" = "--which" ]; then
  which_only=1
  shift
fi
needs=()
if [ "${1:-}" = "--needs" ]; then
  IFS=', ' read -r -a needs <<< "${2:?--needs takes a list such as h5py,numpy}"
  shift 2
elif [ -n "${1:-}" ] && [ -f "$1" ]; then
  # The four modules among SCRIPT.py's imports (import a, b.c as d / from a.b import c).
  while IFS= read -r m; do needs+=("$m"); done < <(
    grep -hE '^[[:space:]]*(import|from)[[:space:]]' "$1" |
      sed -E 's/^[[:space:]]*from[[:space:]]+([A-Za-z0-9_.]+).*/\1/; s/^[[:space:]]*import[[:space:]]+//' |
      tr ',' '\n' | awk '{split($1, part, "."); print part[1]}' |
      grep -xE 'h5py|numpy|yaml|matplotlib' | sort -u || true)
else
  echo "scripts/python.sh: give a Python script or --needs MODULES (got '${1:-}')" >&2
  exit 2
fi

candidates=()
[ -n "${GRAINFLOW_PYTHON:-}" ] && candidates+=("$GRAINFLOW_PYTHON")
candidates+=(/usr/bin/python3)
on_path="$(command -v python3 || true)"
[ -n "$on_path" ] && candidates+=("$on_path")

check="import sys
missing = []
for m in sys.argv[1:]:
    try:
        __import__(m)
    except Exception:
        missing.append(m)
print(' '.join(missing))
sys.exit(1 if missing else 0)"

tried=()
for py in "${candidates[@]}"; do
  if [ ! -x "$py" ] && ! command -v "$py" > /dev/null 2>&1; then
    tried+=("$py (not found)")
    continue
  fi
  if missing="$("$py" -c "$check" "${needs[@]}" 2> /dev/null)"; then
    if [ "$which_only" = 1 ]; then
      echo "$py"
      exit 0
    fi
    # A script that still cannot import them under this interpreter does not come back here.
    GRAINFLOW_PYTHON_CHOSEN="$py" exec "$py" "$@"
  fi
  tried+=("$py (lacks ${missing:-a working Python 3})")
done

{
  echo "error: no Python 3 with ${needs[*]} for grainflow; tried:"
  for t in "${tried[@]}"; do echo "  $t"; done
  echo "install them with 'apt install python3-h5py python3-numpy python3-yaml python3-matplotlib'"
  echo "(then /usr/bin/python3 has them), or set GRAINFLOW_PYTHON to a Python 3 that has them"
} >&2
exit 1
