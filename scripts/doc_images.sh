#!/usr/bin/env bash
# Regenerates the pictures README.md and docs/*.md show, from the commands
# the docs give for them, into docs/images/, and prints each command's
# summary line (steps, vertices) so the figures quoted beside a picture can
# be checked against it.
#
#   scripts/doc_images.sh            # every picture
#   scripts/doc_images.sh NAME...    # only these (names as below)
#   NO_BUILD=1 scripts/doc_images.sh # with the binary already built
#
# The exported models' pictures come from docs/images/render_models.sh, the
# hemicube comparisons from `cargo run --release --example hemicube_compare`
# (docs/accuracy.md gives the commands) and the scaling plots from
# `cargo run --release --example scaling_plot` on the CSV files in docs/.
# window.png and window-mesh.png are the window's screenshots, made by
# scripts/window_shots.sh (the real window under Xvfb, driven with xdotool:
# apt-get install xvfb xdotool). lightmap-threejs.png is the --lightmap model rendered by
# three.js in headless Chromium (scripts/browser/render.mjs).
set -u
cd "$(dirname "$0")/.."

[[ -n "${NO_BUILD:-}" ]] || cargo build --release --quiet || exit 1
root=$PWD
bin=$root/target/release/radiosity
out=$PWD/docs/images
base=scenes/cameras/cornell-base.sc

# The guide's tutorial room: the code block after "Save this as `room.sc`".
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
awk '/Save this as `room.sc`/ { found = 1 }
     found && /^```/ { if (inside) exit; inside = 1; next }
     inside { print }' docs/guide.md >"$work/room.sc"
# Every command runs in that folder, with the bundled scenes beside it, so
# what the pictures print (the plot's title) names the files as the docs do.
ln -s "$PWD/scenes" "$work/scenes"
cd "$work" || exit 1

# NAME | arguments (word-split; @ is docs/images/NAME.png)
pictures=(
  "rtable|scenes/rtable.sc -o @"
  "cornell|scenes/cornell.sc -o @"
  "table_chair|scenes/table_chair.sc -o @"
  "rtable-center|scenes/rtable.sc --form-factor center -o @"
  "cornell-base|scenes/cornell.sc --camera $base -o @"
  "cornell-base-mesh|scenes/cornell.sc --camera $base --mesh-lines -o @"
  "cornell-base-adaptive|scenes/cornell.sc --camera $base --adaptive -o @"
  "cornell-base-adaptive-mesh|scenes/cornell.sc --camera $base --adaptive --mesh-lines -o @"
  "office-falsecolor|scenes/office.sc -o office.png --units m --ies luminaire=scenes/luminaires/panel.ies --workplane 0.75,0.1 --workplane-out office-workplane --falsecolor @ --falsecolor-of illuminance --falsecolor-scale linear --falsecolor-max 1000"
  "convergence|room.sc -o room.png --log steps.csv --plot @"
  "daylight-office-sun|scenes/daylight-office.sc --units m --sky cie-clear --sun 2026-03-20,12:00,51.48,-0.0 --workplane 0.85,0.25 -o @"
  "lightmap-threejs|scenes/cornell.sc --lightmap baked.glb -o cornell.png"
)

wanted=("$@")
failed=0
for entry in "${pictures[@]}"; do
  IFS='|' read -r name arguments <<<"$entry"
  if ((${#wanted[@]} > 0)) && [[ " ${wanted[*]} " != *" $name "* ]]; then
    continue
  fi
  echo "== $name"
  # shellcheck disable=SC2086 # the arguments are meant to be word-split
  if ! "$bin" ${arguments//@/$out/$name.png} --no-window; then
    echo "!! $name failed" >&2
    failed=1
    continue
  fi
  # The lightmapped model as three.js shows it in headless Chromium
  # (scripts/browser: npm ci there once), from the scene's own camera.
  if [[ $name == lightmap-threejs ]] && ! node "$root/scripts/browser/render.mjs" baked.glb \
    "$out/$name.png" --show file --eye 278,273,-800 --look-at 278,273,0 --fov 39.31 --size 360x360; then
    echo "!! $name: the browser render failed" >&2
    failed=1
  fi
  # The office's work-plane plan is written beside its false-colour view.
  if [[ $name == office-falsecolor ]]; then
    cp office-workplane.png "$out/office-workplane.png"
  fi
done
exit $failed
