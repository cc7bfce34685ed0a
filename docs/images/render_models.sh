#!/usr/bin/env bash
# Renders each model collected in tests/models/ to docs/images/models/NAME.png
# (480x360), with the options that light it, for the README and the guide.
#
#   docs/images/render_models.sh            # every model
#   docs/images/render_models.sh NAME...    # only these (names as below)
#   NO_BUILD=1 docs/images/render_models.sh # with the binary already built
#
# A model that fails to render is reported and skipped; the others are
# still rendered. The exit code is 1 when any was skipped. The biplane under
# a sky stops after 40 steps: its full solve takes minutes.
set -u
cd "$(dirname "$0")/../.."

[[ -n "${NO_BUILD:-}" ]] || cargo build --release --quiet || exit 1
bin=target/release/radiosity
out=docs/images/models
mkdir -p "$out"
mcguire_camera=tests/models/mcguire/camera.sc

# NAME | scene | options (word-split)
models=(
  "mcguire-original|tests/models/mcguire/CornellBox-Original.obj|--camera $mcguire_camera"
  "mcguire-sphere|tests/models/mcguire/CornellBox-Sphere.obj|--camera $mcguire_camera --lenmax 0.1"
  "tinyobjloader-cornell|tests/models/tinyobjloader/cornell_box.obj|--emit light=10"
  "raylib-plane|tests/models/raylib/plane.obj|--sky 1 --one-sided --lenmax 50 --max-steps 40"
  "threejs-verify|tests/models/threejs/verify.obj|--sky 1"
  "khronos-box|tests/models/khronos/Box.gltf|--sky 1"
  "khronos-cameras|tests/models/khronos/Cameras.gltf|--sky 1"
  "raylib-greenman|tests/models/raylib/greenman.glb|--sky 1 --lenmax 1"
)

wanted=("$@")
failed=0
for entry in "${models[@]}"; do
  IFS='|' read -r name scene options <<<"$entry"
  if ((${#wanted[@]} > 0)) && [[ " ${wanted[*]} " != *" $name "* ]]; then
    continue
  fi
  echo "== $name"
  # shellcheck disable=SC2086 # the options are meant to be split into words
  if ! "$bin" "$scene" $options --size 480x360 --no-window -q -o "$out/$name.png" 2>"$out/.stderr"; then
    echo "skipped $name: $(grep -m1 'error' "$out/.stderr")"
    failed=1
  fi
  grep 'warning' "$out/.stderr"
  rm -f "$out/.stderr"
done
exit $failed
