#!/usr/bin/env bash
# Runs ParaView's pvbatch on a script, headless: on an Xvfb virtual X server of its own, with
# --force-onscreen-rendering. Debian's ParaView 5.11 is built for X only (no EGL, no OSMesa):
# its offscreen render window (pvbatch's default, or --force-offscreen-rendering) still needs
# an X server and aborts with "bad X server connection" without one, and even under Xvfb;
# an on-screen window on Xvfb renders.
#
#   scripts/pvbatch.sh SCRIPT.py [ARGS...]   exit 1 with one message when pvbatch is missing
#   scripts/pvbatch.sh --check               exit 0 when pvbatch and a display can be had
#
# scripts/bootstrap.sh installs paraview, python3-paraview and xvfb.
set -euo pipefail

missing=""
command -v pvbatch > /dev/null 2>&1 || missing="pvbatch (apt install paraview python3-paraview)"
if ! command -v Xvfb > /dev/null 2>&1 && [ -z "${DISPLAY:-}" ]; then
  missing="${missing:+$missing, }Xvfb (apt install xvfb) or a DISPLAY"
fi
if [ "${1:-}" = "--check" ]; then
  [ -z "$missing" ]
  exit
fi
if [ -n "$missing" ]; then
  echo "error: ParaView rendering needs $missing; scripts/bootstrap.sh installs them" >&2
  exit 1
fi
if command -v Xvfb > /dev/null 2>&1; then
  # Our own Xvfb on a free display (-displayfd), for this run only (pvbatch fails to connect
  # to the one xvfb-run starts, guarded by an xauth cookie). Seen here: pvbatch now and then
  # aborts with "bad X server connection" on a fresh Xvfb (more often with other X servers
  # running), so runs of this script take turns (flock), and an attempt that fails so is
  # made again on a new server, up to three times.
  exec 9> /tmp/grainflow-pvbatch.lock
  flock -w 600 9 || { echo "error: waited 600 s for another pvbatch run to end" >&2; exit 1; }
  work="$(mktemp -d /tmp/grainflow-pvbatch.XXXXXX)"
  xvfb=""
  trap '[ -z "$xvfb" ] || { kill $xvfb 2> /dev/null && wait $xvfb 2> /dev/null; }; rm -rf "$work"' EXIT
  for attempt in 1 2 3; do
    mkfifo "$work/display"
    Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x1024x24 3> "$work/display" 9>&- \
      > /dev/null 2>&1 &
    xvfb=$!
    read -r -t 30 display < "$work/display" || { echo "error: Xvfb did not start" >&2; exit 1; }
    sleep 1
    status=0
    DISPLAY=":$display" pvbatch --force-onscreen-rendering "$@" > "$work/out" 2>&1 || status=$?
    kill $xvfb 2> /dev/null && wait $xvfb 2> /dev/null
    xvfb=""
    rm -f "$work/display"
    if [ $status -ne 0 ] && [ $attempt -lt 3 ] && grep -q "bad X server connection" "$work/out"; then
      echo "pvbatch.sh: pvbatch could not connect to Xvfb (attempt $attempt); again" >&2
      continue
    fi
    cat "$work/out"
    exit $status
  done
fi
exec pvbatch --force-onscreen-rendering "$@"
