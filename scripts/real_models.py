#!/usr/bin/env python3
"""Solve the real exported models of tests/models under a uniform sky and
print the rows of docs/performance.md's "Real models at real size" table.

    real_models.py [--radiosity target/release/radiosity] [--max-steps N]
                   [--work DIR] [MODEL ...]

Each model (by default every level, room and house listed below) is run
as `radiosity MODEL --sky 1 --no-window -o DIR/NAME.pfm --stats ...
--log ...` at default options (so a model whose default mesh the vertex
budget coarsened is refined once, and its row says how), under /usr/bin/time for the whole
process's wall and CPU seconds and peak memory. With --max-steps a model
that has not converged by then says so in its row. One model at a time:
on a shared machine, the CPU seconds are the steadier figure.
"""

import argparse
import csv
import json
import os
import subprocess
import sys

MODELS = [
    "tests/models/godot/room.glb",
    "tests/models/sauerbraten/zdm2.obj",
    "tests/models/sauerbraten/pandora.obj",
    "tests/models/redeclipse/fortitude.obj",
    "tests/models/godot/zdm2.glb",
    "tests/models/xeogl/vianney_house_2/scene.gltf",
]


def run(radiosity, model, work, max_steps):
    name = model.replace("/", "_")
    stats = os.path.join(work, name + ".json")
    log = os.path.join(work, name + ".csv")
    timing = os.path.join(work, name + ".time")
    cmd = [
        "/usr/bin/time", "-f", "%e %U %S %M", "-o", timing,
        radiosity, model, "--sky", "1", "--no-window",
        "-o", os.path.join(work, name + ".pfm"),
        "--stats", stats, "--log", log,
    ]
    if max_steps:
        cmd += ["--max-steps", str(max_steps)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall, user, system, kb = open(timing).read().split()[-4:]
    s = json.load(open(stats))
    steps = list(csv.DictReader(open(log)))
    # `seconds` is the solve's time so far; a sky step (the sky's one,
    # gathered at once, or a facet's) is the difference from the row
    # before: its shooter is a sky facet, numbered after the model's
    # polygons.
    sky_seconds, sky_steps, before = 0.0, 0, 0.0
    for r in steps:
        if int(r["shooter"]) >= s["polygons"]:
            sky_seconds += float(r["seconds"]) - before
            sky_steps += 1
        before = float(r["seconds"])
    sky = "step" if sky_steps == 1 else "{} steps".format(sky_steps)
    state = "converged" if s["converged"] else "not converged ({:.2%} unshot)".format(
        s["unshot_fraction"])
    # A coarsened default mesh is refined once: say how much it split.
    passes = s.get("adaptive", [])
    refined = ""
    if len(passes) > 1:
        first = passes[0]
        refined = ", refined once ({:,} of {:,} elements over the threshold split, +{:,} vertices, {:.0f} s)".format(
            first["split"], first["over_threshold"],
            passes[-1]["vertices"] - first["vertices"], first["refine_seconds"])
    return "| `{}` | {:,} / {:,} | {}: {:,} steps (the sky's {} in {:.0f} s){}, {:.0f} s wall, {:.0f} s CPU | {:.0f} MB |".format(
        model.replace("tests/models/", ""), s["polygons"], s["vertices"], state, s["steps"],
        sky, sky_seconds, refined, float(wall), float(user) + float(system), int(kb) / 1024)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("models", nargs="*", default=MODELS)
    p.add_argument("--radiosity", default="target/release/radiosity")
    p.add_argument("--max-steps", type=int, default=0)
    p.add_argument("--work", default="real-models")
    a = p.parse_args()
    os.makedirs(a.work, exist_ok=True)
    print("| model | polygons / element vertices | `--sky 1` | peak memory |")
    print("|---|---|---|---|")
    for model in a.models:
        print(run(a.radiosity, model, a.work, a.max_steps))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
