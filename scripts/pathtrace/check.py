#!/usr/bin/env python3
"""The convention check: the program's picture (radiosity B) against
Mitsuba's (radiance L) on three small scenes whose answer is known, so
that B / pi = L is seen to hold before any real model is compared.

    check.py [--radiosity PATH] [--spp N] [--keep DIR]

1. plane: a square of reflectance 0.5 (OBJ, two-sided) seen from above
   under `--sky 1`: B = 0.5 exactly, L = 0.5 / pi.
2. lamp: the same square emitting 1 (`--emit lamp=1`, no sky), seen
   directly (reference.py --show-emitters): B = 1, L = 1 / pi.
3. box: a closed unit room of reflectance 0.5 with a ceiling lamp (part
   of the ceiling) and a block on the floor, seen from inside: every
   interreflection, where the converged radiosity solution should agree
   with the path tracer to within its meshing error.

Prints, per scene, the mean of B / pi and of L over the pixels that see
geometry, their ratio, the relative L1 on 4 x 4 blocks, the reference's
own noise in that metric, and the wall seconds of each run.
"""

import argparse
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pictures  # noqa: E402
import runs  # noqa: E402

MTL = """newmtl grey
Kd 0.5 0.5 0.5
newmtl lamp
Kd 0.5 0.5 0.5
"""


def quad(v, a, b, c, d):
    v += [a, b, c, d]
    n = len(v)
    return f"f {n - 3} {n - 2} {n - 1} {n}\n"


def plane_obj():
    v = []
    f = quad(v, (0, 0, 0), (0, 0, 2), (2, 0, 2), (2, 0, 0))
    return v, "usemtl grey\n" + f


def box_obj():
    """Unit room; the ceiling is a 3 x 3 grid whose middle cell is the lamp;
    a 0.3 block stands on the floor. Faces face inward (both sides count)."""
    v = []
    s = "usemtl grey\n"
    s += quad(v, (0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0))  # floor
    s += quad(v, (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))  # back z=0
    s += quad(v, (0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1))  # front z=1
    s += quad(v, (0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1))  # x=0
    s += quad(v, (1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0))  # x=1
    cuts = [0, 1 / 3, 2 / 3, 1]
    lamp = ""
    for i in range(3):
        for j in range(3):
            x0, x1, z0, z1 = cuts[i], cuts[i + 1], cuts[j], cuts[j + 1]
            f = quad(v, (x0, 1, z0), (x1, 1, z0), (x1, 1, z1), (x0, 1, z1))
            if i == 1 and j == 1:
                lamp = f
            else:
                s += f
    s += "usemtl lamp\n" + lamp
    s += "usemtl grey\n"
    a, b = 0.55, 0.85  # block x and z from a to b, 0.3 high
    h = 0.3
    s += quad(v, (a, h, a), (a, h, b), (b, h, b), (b, h, a))
    s += quad(v, (a, 0, a), (b, 0, a), (b, h, a), (a, h, a))
    s += quad(v, (a, 0, b), (a, h, b), (b, h, b), (b, 0, b))
    s += quad(v, (a, 0, a), (a, h, a), (a, h, b), (a, 0, b))
    s += quad(v, (b, 0, a), (b, 0, b), (b, h, b), (b, h, a))
    return v, s


CASES = {
    # name: (obj, camera block, radiosity options, reference extra options)
    "plane": (plane_obj, "eye 1 3 1.2\nlookat 1 0 1\nup 0 1 0\nfov 30",
              ["--sky", "1"], []),
    "lamp": (plane_obj, "eye 1 3 1.2\nlookat 1 0 1\nup 0 1 0\nfov 30",
             ["--emit", "grey=1"], ["--show-emitters"]),
    "box": (box_obj, "eye 0.5 0.5 0.98\nlookat 0.45 0.4 0\nup 0 1 0\nfov 70",
            ["--emit", "lamp=10"], []),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--radiosity", default="radiosity", help="the program to run")
    ap.add_argument("--spp", type=int, default=1024, help="Mitsuba samples a pixel")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--keep", help="keep the files in this folder")
    a = ap.parse_args()
    size = tuple(int(x) for x in a.size.split("x"))
    work = a.keep or tempfile.mkdtemp(prefix="pathtrace-check-")
    os.makedirs(work, exist_ok=True)
    print("scene  mean B/pi  mean L    ratio    relL1(4x4) ref noise  ours s  mitsuba s")
    for name, (make, camera, opts, extra) in CASES.items():
        v, faces = make()
        obj = os.path.join(work, f"{name}.obj")
        with open(os.path.join(work, "check.mtl"), "w") as f:
            f.write(MTL)
        with open(obj, "w") as f:
            f.write("mtllib check.mtl\n")
            f.writelines(f"v {x} {y} {z}\n" for x, y, z in v)
            f.write(faces)
        cam = os.path.join(work, f"{name}.sc")
        with open(cam, "w") as f:
            f.write(f"camera\n{camera}\nend\n")
        ours_pfm = os.path.join(work, f"{name}-ours.pfm")
        t_ours = runs.radiosity(a.radiosity, obj, cam, size, ours_pfm, opts,
                                log=os.path.join(work, f"{name}-ours.log"))
        ref = os.path.join(work, f"{name}-ref.npz")
        _, t_ref = runs.reference(obj, cam, size, ref, a.spp, opts, batches=4, extra=extra,
                                  log=os.path.join(work, f"{name}-ref.log"))
        ours = pictures.read_pfm(ours_pfm) / np.pi
        z = np.load(ref)
        mask = z["mask"] | z["lamp"] if name == "lamp" else z["mask"]
        mine, theirs = pictures.luminance(ours)[mask].mean(), pictures.luminance(
            z["radiance"])[mask].mean()
        l1 = pictures.rel_l1(ours, z["radiance"], mask, 4)
        noise = pictures.noise_l1(z["batches"], mask, 4)
        print(f"{name:6} {mine:.6f}  {theirs:.6f}  {mine / theirs:.5f}  {l1:.4f}     {noise:.4f}"
              f"    {t_ours['wall']:6.1f}  {t_ref['wall']:6.1f}")
    print(f"files in {work}")


if __name__ == "__main__":
    main()
