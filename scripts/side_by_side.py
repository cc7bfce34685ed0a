#!/usr/bin/env python3
"""Put several OBJ models side by side in one OBJ, for a model of a
quarter of a million triangles built from real exports.

    side_by_side.py OUT.obj MODEL.obj [MODEL.obj ...]

The models are placed along +x in the order given, each one's bounding
box a tenth of its width past the one before, so none overlaps another
(light still passes between them where they are open). Their vertices,
texture coordinates and normals are renumbered; their materials and
groups get the model's file name as a prefix (`pandora_slot2`), so two
models' `slot2` stay two materials and `--emit` names stay unique; one
`OUT.mtl` holds every model's materials. A model may be given twice (a
second copy is placed further along). Faces are copied as they are:
what the program warns about in a model alone it warns about here.
"""

import os
import sys


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read().splitlines()


def x_extent(lines):
    lo, hi = float("inf"), float("-inf")
    for line in lines:
        if line.startswith("v "):
            x = float(line.split()[1])
            lo, hi = min(lo, x), max(hi, x)
    if lo > hi:
        sys.exit("error: a model has no vertices")
    return lo, hi


def index(token, count, offset):
    """One index of a face corner, renumbered: OBJ counts from 1, and a
    negative index counts back from the last one defined so far."""
    if token == "":
        return ""
    i = int(token)
    if i < 0:
        i = count + 1 + i
    return str(i + offset)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, models = sys.argv[1], sys.argv[2:]
    mtl_out = os.path.splitext(out)[0] + ".mtl"
    obj, mtl = ["mtllib " + os.path.basename(mtl_out)], []
    offsets = [0, 0, 0]  # v, vt, vn written so far
    at, seen, triangles = 0.0, {}, 0
    for model in models:
        lines = read(model)
        name = os.path.splitext(os.path.basename(model))[0]
        seen[name] = seen.get(name, 0) + 1
        prefix = name if seen[name] == 1 else "{}{}".format(name, seen[name])
        lo, hi = x_extent(lines)
        dx = at - lo
        at += (hi - lo) * 1.1
        counts = [0, 0, 0]
        for line in lines:
            key = line.split(maxsplit=1)[0] if line.strip() else ""
            if key == "v":
                p = line.split()
                obj.append("v {:.6f} {}".format(float(p[1]) + dx, " ".join(p[2:])))
                counts[0] += 1
            elif key == "vt":
                obj.append(line)
                counts[1] += 1
            elif key == "vn":
                obj.append(line)
                counts[2] += 1
            elif key == "f":
                corners = []
                for c in line.split()[1:]:
                    parts = c.split("/")
                    corners.append("/".join(
                        index(t, counts[k], offsets[k]) for k, t in enumerate(parts)))
                obj.append("f " + " ".join(corners))
                triangles += len(corners) - 2
            elif key in ("g", "o", "usemtl"):
                rest = line.split(maxsplit=1)
                obj.append("{} {}_{}".format(key, prefix, rest[1] if len(rest) > 1 else ""))
            elif key == "mtllib":
                for lib in line.split()[1:]:
                    path = os.path.join(os.path.dirname(model), lib)
                    for m in read(path):
                        if m.startswith("newmtl "):
                            m = "newmtl {}_{}".format(prefix, m.split(maxsplit=1)[1])
                        mtl.append(m)
            elif key in ("s", "#", ""):
                obj.append(line)
        for k in range(3):
            offsets[k] += counts[k]
        print("{}: {:,} vertices, placed {:+.1f} along x".format(model, counts[0], dx))
    with open(out, "w") as f:
        f.write("\n".join(obj) + "\n")
    with open(mtl_out, "w") as f:
        f.write("\n".join(mtl) + "\n")
    print("{}: {:,} triangles".format(out, triangles))


if __name__ == "__main__":
    main()
