#!/bin/bash
# Two SIGTERMs a millisecond apart, as GNU `timeout` sends them (to the process, then to its
# process group), are one request: the run stops with its checkpoint and exit code 0 every
# time. (With the second one killing the run, most such stops had ended with exit 143 and no
# message: the first stop is over within the millisecond, and the second found the default
# handler back.)
#   stop_signal_twice.sh GRAIN SCENE WORKDIR
set -u
grain=$1 scene=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
for try in 1 2 3 4 5 6 7 8; do
  rm -rf out
  "$grain" run "$scene" --output out --no-progress > run.txt 2>&1 &
  pid=$!
  for _ in $(seq 100); do  # the first log row: the run loop's handlers are installed
    [ "$(wc -l 2> /dev/null < out/log.csv || echo 0)" -ge 2 ] && break
    sleep 0.05
  done
  kill -TERM $pid
  sleep 0.001
  kill -TERM $pid 2> /dev/null
  wait $pid
  code=$?
  if [ $code -ne 0 ] || ! grep -q "^grain: received SIGTERM; stopped after step" run.txt ||
    [ -z "$(ls out/checkpoint_*.h5 2> /dev/null)" ]; then
    echo "FAIL try $try: exit $code (expected 0 with the stop message and a checkpoint):"
    cat run.txt
    failures=$((failures + 1))
  else
    echo "ok try $try: $(grep -o 'stopped after step [0-9]*' run.txt)"
  fi
done
[ $failures -eq 0 ] || { echo "$failures of 8 double signals killed the run"; exit 1; }
echo "every double SIGTERM stopped the run cleanly"
