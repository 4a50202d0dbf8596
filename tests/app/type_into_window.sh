#!/bin/sh
# Runs the command given (a windowed `spidar-mr run`) and, once its window is up, types into it
# with xdotool as a person would: the right hand away (Up held 1.5 s), the left hand closing (Z
# held 1 s), then the space bar (emergency stop). Meant to run under xvfb-run (no window
# manager: the window is focused directly). Usage: type_into_window.sh COMMAND ARGS...
"$@" &
pid=$!
wid=$(timeout 60 xdotool search --sync --name '^spidar-mr' 2>/dev/null | head -n 1)
if [ -z "$wid" ]; then
  echo "type_into_window.sh: no spidar-mr window appeared within 60 s" >&2
  kill "$pid" 2>/dev/null
  wait "$pid"
  exit 97
fi
xdotool windowfocus --sync "$wid"
sleep 1.5  # the first frames
xdotool keydown Up
sleep 1.5
xdotool keyup Up
xdotool keydown z
sleep 1.0
xdotool keyup z
xdotool key space
wait "$pid"
code=$?
# xvfb-run's own exit status replaces the command's when its cleanup fails (status 5): the
# command's is said here for the test to read.
echo "type_into_window.sh: spidar-mr exited with $code" >&2
exit $code
