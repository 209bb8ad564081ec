#!/usr/bin/env bash
# Runs a CFD-DEM tutorial's Allrun on a fresh copy in the build tree; the tutorial's own
# analyse.py decides pass or fail against its reference (exit status).
# usage: run_tutorial.sh SOURCE_DIR BUILD_DIR WORK_DIR CASE [Allrun arguments...]
set -euo pipefail
src="$1" build="$2" work="$3" case="$4"
shift 4
rm -rf "$work"
mkdir -p "$work/cfd-dem"
cp "$src/tutorials/cfd-dem/run_case.sh" "$work/cfd-dem/"
cp "$src/tutorials/cfd-dem/foam_case.py" "$work/cfd-dem/"
cp "$src/tutorials/run_index.py" "$work/"
cp -r "$src/tutorials/cfd-dem/$case" "$work/cfd-dem/"
cd "$work/cfd-dem/$case"
./Allclean
# A user's own file in the case folder (e.g. `./Allrun > log.Allrun 2>&1`) must survive the
# run, and the case's inputs must come out unchanged.
echo "the user's own log" > log.Allrun
find . -type f ! -name log.Allrun -print0 | sort -z | xargs -0 sha256sum > "$work/inputs.sha256"
GRAINFLOW_SOURCE_DIR="$src" GRAINFLOW_BUILD_DIR="$build" ./Allrun "$@"
fail=0
grep -qx "the user's own log" log.Allrun || { echo "run_tutorial: Allrun deleted or changed log.Allrun" >&2; fail=1; }
sha256sum --quiet -c "$work/inputs.sha256" || { echo "run_tutorial: Allrun changed the inputs above" >&2; fail=1; }
# Everything the run wrote is ignored by git in the source tree, so that `git status` stays
# clean after a tutorial runs in place (skipped when the source is not a git checkout).
if git -C "$src" rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  while IFS= read -r -d '' f; do
    rel="tutorials/cfd-dem/$case/${f#./}"
    grep -q " ${f}\$" "$work/inputs.sha256" && continue
    [ "$f" = ./log.Allrun ] && continue
    git -C "$src" check-ignore -q --no-index "$rel" ||
      { echo "run_tutorial: $rel is written by Allrun but not ignored by git" >&2; fail=1; }
  done < <(find . -type f -print0)
fi
exit "$fail"
