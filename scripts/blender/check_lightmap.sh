#!/usr/bin/env bash
# Bakes a scene with --lightmap, renders the .glb in Blender from the
# program's camera and prints how Blender's picture differs from the
# program's own.
#
#   scripts/blender/check_lightmap.sh SCENE [radiosity options ...]
#
# Runs `radiosity SCENE OPTIONS -o WORK/picture.png --lightmap WORK/model.glb`,
# takes the picture's camera from `radiosity SCENE OPTIONS --info` (the
# scene's camera, or the one the options give), then runs
# render_lightmap.py in Blender on the .glb with that camera: it prints
# each material's Emission wiring and the relative block error of its
# render against the picture (4 x 4-pixel blocks, linear light).
#
# Environment: RADIOSITY (default target/release/radiosity), BLENDER
# (default blender), WORK (default target/blender-check), ENGINE (cycles,
# the default, or eevee), SAMPLES (default 16), BLENDER_OPTIONS (more options for
# render_lightmap.py, e.g. "--view-transform Filmic"). Needs Blender 3.x
# or later with its glTF importer (Debian: apt-get install blender
# python3-numpy).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
radiosity=${RADIOSITY:-target/release/radiosity}
blender=${BLENDER:-blender}
work=${WORK:-target/blender-check}
engine=${ENGINE:-cycles}
samples=${SAMPLES:-16}
options=${BLENDER_OPTIONS:-}
if (($# < 1)); then
  sed -n '2,20s/^# \{0,1\}//p' "$0" >&2
  exit 2
fi
scene=$1
shift
mkdir -p "$work"
work=$(cd "$work" && pwd)
"$radiosity" "$scene" "$@" -q --no-window -o "$work/picture.png" --lightmap "$work/model.glb"
camera=$("$radiosity" "$scene" "$@" --info | sed -n 's/^camera[^:]*: //p')
if [[ $camera != --eye* ]]; then
  echo "check_lightmap.sh: error: --info names no camera" >&2
  exit 1
fi
# shellcheck disable=SC2086 # the camera and options are meant to be word-split
"$blender" -b --factory-startup --python "$here/render_lightmap.py" -- \
  "$work/model.glb" "$work/blender-$engine.png" $camera \
  --engine "$engine" --samples "$samples" $options --compare "$work/picture.png" \
  >"$work/blender.log" 2>&1 || {
  tail -n 30 "$work/blender.log" >&2
  exit 1
}
grep -E '^(material |problem: |note: |rendered |relative )' "$work/blender.log"
echo "picture $work/picture.png, Blender $work/blender-$engine.png"
