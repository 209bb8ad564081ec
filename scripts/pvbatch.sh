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
  # Our own Xvfb on a free display (-displayfd); pvbatch fails to connect to the one that
  # xvfb-run starts (it guards it with an xauth cookie), local connections to this one work.
  fifo="$(mktemp -u /tmp/grainflow-xvfb.XXXXXX)"
  mkfifo "$fifo"
  Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x1024x24 3> "$fifo" > /dev/null 2>&1 &
  xvfb=$!
  trap 'kill $xvfb 2> /dev/null && wait $xvfb 2> /dev/null; rm -f "$fifo"' EXIT
  read -r -t 30 display < "$fifo" || { echo "error: Xvfb did not start" >&2; exit 1; }
  status=0
  DISPLAY=":$display" pvbatch --force-onscreen-rendering "$@" || status=$?
  exit $status
fi
exec pvbatch --force-onscreen-rendering "$@"
