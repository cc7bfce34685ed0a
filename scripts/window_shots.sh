#!/usr/bin/env bash
# Makes the window's two screenshots README.md and the guide show,
# docs/images/window.png and docs/images/window-mesh.png, from the real
# window: the program opens the bundled rtable scene on a virtual X server
# (Xvfb), the script waits until the title says the solve converged, then
# presses the window's keys with xdotool (`m` shows the element mesh, `p`
# writes the screen as shown, panel included, as rtable-NNN.tiff, `q`
# quits), and the `window_shot` example checks each TIFF (lit; mesh lines
# drawn or not, as asked) and writes it as PNG.
#
#   scripts/window_shots.sh             # both pictures
#   scripts/window_shots.sh NAME...     # only these (names as below)
#   NO_BUILD=1 scripts/window_shots.sh  # with the binaries already built
#
# Needs Xvfb and xdotool (Debian/Ubuntu: apt-get install xvfb xdotool).
# Every wait has a limit, and each is on the result (the window, the
# title, the program's `wrote` line, its exit), not a guessed delay; any
# failure stops the script with exit 1 and leaves the picture in
# docs/images/ untouched.
set -euo pipefail
cd "$(dirname "$0")/.."

for tool in Xvfb xdotool; do
  command -v "$tool" >/dev/null || {
    echo "!! $tool is missing (apt-get install xvfb xdotool)" >&2
    exit 1
  }
done
[[ -n "${NO_BUILD:-}" ]] || cargo build --release --quiet --bin radiosity --example window_shot
root=$PWD
bin=$root/target/release/radiosity
shot=$root/target/release/examples/window_shot
out=docs/images

work=$(mktemp -d)
xvfb=
program=
cleanup() {
  [[ -z $program ]] || kill "$program" 2>/dev/null || true
  [[ -z $xvfb ]] || kill "$xvfb" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
die() {
  echo "!! $*" >&2
  local log
  for log in "$work"/*.log "$work"/*/*.log; do
    [[ -s $log ]] && { echo "-- ${log#"$work"/}:" >&2; cat "$log" >&2; }
  done
  exit 1
}
# Polls the command "$@" every 0.2 s until it succeeds, for at most $1 s.
within() {
  local limit=$1
  shift
  local until=$((SECONDS + limit))
  until "$@"; do
    ((SECONDS < until)) || return 1
    sleep 0.2
  done
}

# A virtual X server on a free display (it writes the number it took);
# -noreset keeps it up between the two windows.
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp -noreset 3>"$work/display" 2>"$work/xvfb.log" &
xvfb=$!
within 20 test -s "$work/display" || die "Xvfb did not start"
export DISPLAY=:$(<"$work/display")
unset WAYLAND_DISPLAY
within 20 xdotool getdisplaygeometry >/dev/null 2>&1 || die "Xvfb on $DISPLAY does not answer"

# NAME | keys pressed before `p` (the program runs in a fresh folder, so
# its screenshot is always rtable-001.tiff)
shots=(
  "window|"
  "window-mesh|m"
)

converged() {
  local title
  title=$(xdotool getwindowname "$1" 2>/dev/null) || return 1
  kill -0 "$program" 2>/dev/null || die "the program exited before converging"
  [[ $title == *" · converged"* ]]
}
wrote() { grep -q "^wrote rtable-001.tiff" "$work/$1/out.log"; }
exited() { ! kill -0 "$program" 2>/dev/null; }

wanted=("$@")
for entry in "${shots[@]}"; do
  IFS='|' read -r name keys <<<"$entry"
  if ((${#wanted[@]} > 0)) && [[ " ${wanted[*]} " != *" $name "* ]]; then
    continue
  fi
  echo "== $name"
  dir=$work/$name
  mkdir "$dir"
  (cd "$dir" && exec "$bin" "$root/scenes/rtable.sc" </dev/null >out.log 2>err.log) &
  program=$!
  window=$(timeout 30 xdotool search --sync --name '^radiosity.*rtable' | head -n 1) ||
    die "$name: no window appeared"
  within 120 converged "$window" || die "$name: the solve did not converge in 120 s"
  xdotool windowfocus --sync "$window"
  for key in $keys p; do
    xdotool key --clearmodifiers "$key"
  done
  # The program says `wrote NAME` once the file is complete.
  within 20 wrote "$name" || die "$name: p wrote no rtable-001.tiff"
  xdotool key --clearmodifiers q
  within 10 exited || die "$name: q did not close the window"
  wait "$program" || die "$name: the program failed"
  program=
  mesh=()
  [[ $keys == *m* ]] && mesh=(--mesh)
  "$shot" "$dir/rtable-001.tiff" "$out/$name.png" "${mesh[@]}" ||
    die "$name: the screenshot is not the picture asked for"
  grep -h "window closed after" "$dir/err.log" || true
done
