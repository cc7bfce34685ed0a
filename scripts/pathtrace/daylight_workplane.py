#!/usr/bin/env python3
"""Check a work plane under the CIE overcast sky against Mitsuba 3.

    daylight_workplane.py SCENE.sc --radiosity PATH [--height 0.85]
                          [--spacing 0.25] [--every 2] [--spp 65536]
                          [--batches 16] [--lux 10000] [--uniform] --work DIR

1. The program solves SCENE (`--units m --sky cie-overcast,LUXlx
   --workplane HEIGHT,SPACING`) and writes the work plane's illuminances
   (its CSV).
2. Mitsuba path-traces the same room: every `.sc` polygon and box a
   one-sided `diffuse` surface of the material's reflectance (the program
   reflects from the front only, and any face blocks light from both
   sides), under an `envmap` holding the CIE overcast sky's luminance,
   L(Z) = Lz (1 + 2 cos Z) / 3 with Lz = 9 E / (7 pi), above the horizon,
   and below it the ground as gensky makes it: luminance 0.2 E / pi.
   Before the room, the same sky over nothing is checked: a meter facing
   up must read E and one facing down the ground's 0.2 E. With --uniform,
   the sky is the program's `--sky E` instead: luminance E / pi all round.
3. At every EVERY-th work-plane point (in x and in z) a 1 cm square facing
   up carries an `irradiancemeter`; each is rendered BATCHES times at SPP
   samples, in a scene of its own, and the renders averaged.

Mitsuba's readings are kept in DIR/mitsuba-SKY-SPPxBATCHES.csv (SKY
`overcast` or `uniform`, with the lux) as they come, and a later run in
the same DIR reads a point's reading from there instead of rendering it
again: the reference does not depend on the program, so a change to the
program is checked again in seconds.

Prints each point (x, z, program, Mitsuba, difference), then the mean and
the largest relative difference and the daylight factors' means over the
points. The `.sc` reader takes what the daylight office uses (`material`
with `color` and `k_diffrefl`, `polygon`, `box`, `camera`) and refuses
anything else.
"""

import argparse
import csv
import math
import os
import subprocess
import sys

import numpy as np

GROUND_REFLECTANCE = 0.2  # gensky's, as the program's sky
DEFAULT_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def read_sc(path):
    """(materials {name: rho}, faces [(material, [vertex, ...])]) of a .sc
    file: polygons as written, boxes as six outward quadrilaterals."""
    materials, faces = {}, []
    block, name, color, k, verts = None, None, None, None, []
    for number, raw in enumerate(open(path), 1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        head = words[0]
        where = f"{path}:{number}"
        if block is None:
            if head == "material":
                block, name, color, k = "material", words[1], (1.0, 1.0, 1.0), 0.0
            elif head == "polygon":
                block, name, verts = "polygon", words[1], []
            elif head == "camera":
                block = "camera"
            elif head == "box":
                m = words[1]
                x0, y0, z0, x1, y1, z1 = map(float, words[2:8])
                c = lambda i, j, l: (  # noqa: E731
                    (x0, x1)[i], (y0, y1)[j], (z0, z1)[l])
                # Clockwise seen from outside, reversed below.
                for quad in (
                    [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],  # -x
                    [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)],  # +x
                    [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],  # -y
                    [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)],  # +y
                    [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],  # -z
                    [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)],  # +z
                ):
                    faces.append((m, quad[::-1]))
            else:
                sys.exit(f"{where}: error: this reader takes material, polygon, box and camera, not {head}")
        elif head == "end":
            if block == "material":
                materials[name] = np.array(color) * k
            elif block == "polygon":
                faces.append((name, verts))
            block = None
        elif block == "material":
            if head == "color":
                color = tuple(map(float, words[1:4]))
            elif head == "k_diffrefl":
                k = float(words[1])
            elif head != "k_emission" or float(words[1]) != 0.0:
                sys.exit(f"{where}: error: this reader takes color and k_diffrefl, not {head}")
        elif block == "polygon":
            if head != "vertex":
                sys.exit(f"{where}: error: expected vertex or end, got {head}")
            verts.append(tuple(map(float, words[1:4])))
    return materials, faces


def sky_envmap(lux, uniform, width=512, height=256):
    """A latitude-longitude bitmap of the CIE overcast sky of horizontal
    illuminance `lux` and its ground, or (`uniform`) of luminance lux / pi
    all round as the program's `--sky V`; +y up (Mitsuba's envmap: row 0
    at the zenith)."""
    theta = (np.arange(height) + 0.5) / height * math.pi  # from +y
    cos_z = np.cos(theta)
    if uniform:
        row = np.full(height, lux / math.pi)
    else:
        lz = 9.0 * lux / (7.0 * math.pi)
        ground = GROUND_REFLECTANCE * lux / math.pi
        row = np.where(cos_z > 0.0, lz * (1.0 + 2.0 * cos_z) / 3.0, ground)
    image = np.repeat(row[:, None], width, axis=1)
    return np.repeat(image[:, :, None], 3, axis=2).astype(np.float32)


def meter(mi, point, normal, spp, size=0.005):
    """A 2 size square at `point` facing `normal` (+y or -y) carrying an
    irradiance meter."""
    T = mi.ScalarTransform4f
    turn = T().rotate([1, 0, 0], -90.0) if normal > 0 else T().rotate([1, 0, 0], 90.0)
    return {
        "type": "rectangle",
        "to_world": T().translate(list(point)) @ turn @ T().scale([size, size, 1.0]),
        "sensor": {
            "type": "irradiancemeter",
            "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }


def scene_dict(mi, materials, faces, sky, meters):
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 64, "rr_depth": 5},
        "sky": {"type": "envmap", "bitmap": mi.Bitmap(sky)},
    }
    for i, (name, verts) in enumerate(faces):
        rho = materials[name]
        pts = np.array(verts, dtype=np.float32)
        tris = np.array([[0, k, k + 1] for k in range(1, len(pts) - 1)], dtype=np.uint32)
        mesh = mi.Mesh(f"face{i}", len(pts), len(tris))
        params = mi.traverse(mesh)
        params["vertex_positions"] = mi.Float(pts.ravel())
        params["faces"] = mi.UInt32(tris.ravel())
        params.update()
        mesh.set_bsdf(mi.load_dict({"type": "diffuse",
                                    "reflectance": {"type": "rgb", "value": rho.tolist()}}))
        d[f"face{i}"] = mesh
    for k, m in enumerate(meters):
        d[f"meter{k}"] = m
    return mi.load_dict(d)


def irradiance(mi, scene, spp, batches, seed):
    """The meter's reading, the mean of `batches` renders of `spp`
    samples each, summed in double precision: one render of millions of
    samples sums them in the film's single precision, and drifts (a
    meter under the open ground read 1.6 % high at 4 M samples)."""
    sensor = scene.sensors()[0]
    values = [float(np.mean(np.array(mi.render(scene, sensor=sensor, spp=spp,
                                               seed=seed * 1000 + b))))
              for b in range(batches)]
    return float(np.mean(values))


def kept_readings(path):
    """{(x, y, z): lux} of the readings kept in `path` (none if absent);
    the sky-alone meters are at the keys ("up",) and ("down",)."""
    kept = {}
    if os.path.exists(path):
        with open(path) as f:
            for row in csv.DictReader(f):
                key = (row["x"],) if row["y"] == "" else (row["x"], row["y"], row["z"])
                kept[key] = float(row["lux"])
    return kept


def keep_reading(path, key, lux):
    """Appends one reading to `path` (written with its header if new)."""
    new = not os.path.exists(path)
    with open(path, "a") as f:
        if new:
            f.write("x,y,z,lux\n")
        cells = list(key) + [""] * (3 - len(key))
        f.write(",".join(cells) + f",{lux!r}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--radiosity", required=True)
    ap.add_argument("--height", type=float, default=0.85)
    ap.add_argument("--spacing", type=float, default=0.25)
    ap.add_argument("--every", type=int, default=2)
    ap.add_argument("--spp", type=int, default=65536)
    ap.add_argument("--batches", type=int, default=16)
    ap.add_argument("--lux", type=float, default=10000.0)
    ap.add_argument("--uniform", action="store_true",
                    help="a uniform sky of luminance LUX / pi all round (--sky LUX) instead")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)

    stem = os.path.splitext(os.path.basename(a.scene))[0]
    # The program runs in DIR: a path to it is made absolute (a bare name
    # is looked up on PATH).
    program = os.path.abspath(a.radiosity) if os.sep in a.radiosity else a.radiosity
    subprocess.run(
        [program, os.path.abspath(a.scene), "--units", "m", "--sky",
         f"{a.lux:g}" if a.uniform else f"cie-overcast,{a.lux:g}lx", "--workplane", f"{a.height:g},{a.spacing:g}",
         "-o", "plane.png", "--no-window", "-q"],
        cwd=a.work, check=True)
    with open(os.path.join(a.work, f"{stem}-workplane.csv")) as f:
        rows = list(csv.DictReader(f))
    xs = sorted({float(r["x"]) for r in rows})
    zs = sorted({float(r["z"]) for r in rows})
    keep_x, keep_z = set(xs[::a.every]), set(zs[::a.every])
    points = [(float(r["x"]), float(r["y"]), float(r["z"]), float(r["e"]))
              for r in rows if float(r["x"]) in keep_x and float(r["z"]) in keep_z]

    if a.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        if os.path.exists(DEFAULT_LLVM):
            os.environ["DRJIT_LIBLLVM_PATH"] = DEFAULT_LLVM
    import mitsuba as mi
    mi.set_variant(a.variant)

    sky = sky_envmap(a.lux, a.uniform)
    kept_path = os.path.join(
        a.work, f"mitsuba-{'uniform' if a.uniform else 'overcast'}-{a.lux:g}lx-"
        f"{a.spp}x{a.batches}.csv")
    kept = kept_readings(kept_path)

    def reading(key, build, seed):
        """The kept reading at `key`, or the render of the scene `build()`
        makes, kept."""
        if key not in kept:
            kept[key] = irradiance(mi, build(), a.spp, a.batches, seed)
            keep_reading(kept_path, key, kept[key])
        return kept[key]

    # The sky alone: up must read E, down the ground's 0.2 E.
    up = reading(("up",), lambda: scene_dict(
        mi, {}, [], sky, [meter(mi, (0, 0, 0), 1, a.spp)]), 1)
    down = reading(("down",), lambda: scene_dict(
        mi, {}, [], sky, [meter(mi, (0, 0, 0), -1, a.spp)]), 2)
    below = a.lux if a.uniform else GROUND_REFLECTANCE * a.lux
    print(f"sky alone: up {up:.1f} lx (expected {a.lux:g}), down {down:.1f} lx "
          f"(expected {below:g})")
    if abs(up / a.lux - 1) > 0.01 or abs(down / below - 1) > 0.01:
        sys.exit("error: the environment map is not the sky the program solves")

    materials, faces = read_sc(a.scene)
    diffs, ours, theirs = [], [], []
    print(f"{'x':>6} {'z':>7} {'program':>9} {'Mitsuba':>9} {'diff':>7}")
    for k, (x, y, z, e) in enumerate(points):
        # One meter a scene: Mitsuba attaches an endpoint to one shape.
        m = reading((f"{x:g}", f"{y:g}", f"{z:g}"), lambda: scene_dict(
            mi, materials, faces, sky, [meter(mi, (x, y, z), 1, a.spp)]), 100 + k)
        diffs.append(e / m - 1.0)
        ours.append(e)
        theirs.append(m)
        print(f"{x:6.3f} {z:7.3f} {e:9.1f} {m:9.1f} {100 * (e / m - 1):+6.2f}%", flush=True)
    diffs = np.array(diffs)
    print(f"{len(points)} points at {a.height:g} m, {a.batches} x {a.spp} samples each: "
          f"mean difference {100 * diffs.mean():+.2f} %, mean |difference| "
          f"{100 * np.abs(diffs).mean():.2f} %, largest {100 * np.abs(diffs).max():.2f} %; "
          f"DF mean over them {100 * np.mean(ours) / a.lux:.2f} % (program), "
          f"{100 * np.mean(theirs) / a.lux:.2f} % (Mitsuba)")


if __name__ == "__main__":
    main()
