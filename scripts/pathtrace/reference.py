#!/usr/bin/env python3
"""Path-trace the picture that `radiosity MODEL [--sky S] [--emit NAME=V]
--camera CAM.sc` solves, with Mitsuba 3.

    reference.py MODEL --camera CAM.sc [--sky S] [--emit NAME=V ...]
                 [--one-sided | --two-sided] [--size WxH] --spp N
                 [--batches K] [--seed S] -o OUT.npz|.pfm|.exr

The scene (see models.py for how the model is read):
- each material becomes a `diffuse` BSDF of the program's reflectance,
  wrapped in `twosided` where the program treats the face as two-sided;
- an emitting material gets an `area` emitter of radiance E / pi (E the
  emitted radiosity); a two-sided emitting face becomes two one-sided
  faces, each moved 1e-5 of the scene's diagonal towards its own front
  so that each side is found first from its own side (Mitsuba's area
  emitters light the front only);
- `--sky S` is a `constant` environment of radiance S / pi: an unoccluded
  plane receives irradiance S, as under the program's sky;
- the `path` integrator (max depth 64, Russian roulette from depth 5,
  emitters and sky hidden from the camera), `hdrfilm` with a box filter,
  a `perspective` sensor with the camera block's eye, look-at, up and
  vertical field of view, the near plane at 1e-3 of the eye-look-at
  distance, as the program's view.

Out: linear RGB radiance (the program's radiosity / pi). An `.npz` holds
`radiance` (H, W, 3, row 0 at the top), `batches` (K independent partial
means, K = --batches, for the noise estimate), `mask` (pixels whose
every sub-pixel ray, 4 x 4 a pixel, meets geometry that does not emit)
and `lamp` (pixels where some sub-pixel ray meets an emitter).
Timings go to stdout as one JSON line (seconds: import, read, load,
render, mask, total).
"""

import argparse
import json
import os
import sys
import time

T0 = time.perf_counter()

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import models  # noqa: E402
import pictures  # noqa: E402

DEFAULT_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def import_mitsuba(variant):
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        if os.path.exists(DEFAULT_LLVM):
            os.environ["DRJIT_LIBLLVM_PATH"] = DEFAULT_LLVM
    import mitsuba as mi

    mi.set_variant(variant)
    return mi


def rgb(v):
    return {"type": "rgb", "value": [float(x) for x in v]}


def mesh(mi, name, tris, bsdf, emitter=None):
    """A Mitsuba mesh of triangles (T, 3, 3), flat-shaded (no vertex
    normals: shading follows the geometric normal, as in the program)."""
    props = mi.Properties()
    props["bsdf"] = bsdf
    if emitter is not None:
        props["emitter"] = emitter
    n = len(tris)
    m = mi.Mesh(name, 3 * n, n, props=props)
    p = mi.traverse(m)
    p["vertex_positions"] = mi.Float(tris.reshape(-1).astype(np.float32))
    p["faces"] = mi.UInt32(np.arange(3 * n, dtype=np.uint32))
    p.update()
    return m


def scene_dict(mi, model, cam, size, sky=None, max_depth=64, hide_emitters=True):
    """The Mitsuba scene dict of `model` seen by `cam` (a models.read_camera
    dict) at `size` (W, H)."""
    lo, hi = model.bounds()
    diag = float(np.linalg.norm(hi - lo))
    eye = np.array(cam["eye"], float)
    look = np.array(cam["lookat"], float)
    dist = float(np.linalg.norm(look - eye))
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth, "rr_depth": 5,
                       "hide_emitters": hide_emitters},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": float(cam["fov"]),
            "near_clip": 1e-3 * dist,
            "far_clip": 10.0 * (diag + dist) + 1.0,
            "to_world": mi.ScalarTransform4f().look_at(
                origin=eye.tolist(), target=look.tolist(), up=list(cam["up"])),
            "film": {"type": "hdrfilm", "width": size[0], "height": size[1],
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": 1},
        },
    }
    if sky is not None and np.any(sky > 0):
        d["sky"] = {"type": "constant", "radiance": rgb(sky / np.pi)}
    shift = 1e-5 * diag
    for k, m in enumerate(model.materials):
        for two in (False, True):
            sel = (model.mat == k) & (model.two_sided == two)
            if not sel.any():
                continue
            tris = model.tris[sel]
            diffuse = {"type": "diffuse", "reflectance": rgb(m.reflectance())}
            e = m.emission()
            if not e.any():
                bsdf = {"type": "twosided", "bsdf": diffuse} if two else diffuse
                d[f"m{k}_{int(two)}"] = mesh(mi, f"m{k}_{int(two)}", tris, mi.load_dict(bsdf))
                continue
            sides = [tris]
            if two:
                sides.append(tris[:, [0, 2, 1]])
            for s, t in enumerate(sides):
                if two:
                    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
                    ln = np.linalg.norm(n, axis=1, keepdims=True)
                    t = t + shift * (n / np.where(ln > 0, ln, 1))[:, None, :]
                emitter = mi.load_dict({"type": "area", "radiance": rgb(e / np.pi)})
                d[f"e{k}_{s}"] = mesh(mi, f"e{k}_{s}", t, mi.load_dict(diffuse), emitter)
    return d


def coverage(mi, scene, size, n=4):
    """(mask, lamp): pixels whose every one of n x n sub-pixel rays meets
    non-emitting geometry; pixels where any meets an emitter."""
    import drjit as dr

    w, h = size
    off = (np.arange(n) + 0.5) / n
    ys, xs, oy, ox = np.meshgrid(np.arange(h), np.arange(w), off, off, indexing="ij")
    px = ((xs + ox) / w).ravel().astype(np.float32)
    py = ((ys + oy) / h).ravel().astype(np.float32)
    sensor = scene.sensors()[0]
    ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(mi.Float(px), mi.Float(py)),
                               mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    hit = np.array(si.is_valid(), bool)
    lamp = np.array(dr.select(si.is_valid(), si.shape.is_emitter(), False), bool)
    hit = hit.reshape(h, w, n * n)
    lamp = lamp.reshape(h, w, n * n)
    return (hit & ~lamp).all(axis=2), lamp.any(axis=2)


def render(mi, scene, spp, seed, pass_spp):
    """The mean of ceil(spp / pass_spp) renders of at most pass_spp samples
    a pixel each, every pass with its own seed: (H, W, 3) radiance."""
    acc = None
    done = 0
    k = 0
    while done < spp:
        n = min(pass_spp, spp - done)
        img = np.array(mi.render(scene, seed=(seed * 4099 + k) % 2**31, spp=n), dtype=np.float64)[:, :, :3]
        acc = img * n if acc is None else acc + img * n
        done += n
        k += 1
    return acc / spp


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("model")
    ap.add_argument("--camera", required=True, help=".sc file with a camera block")
    ap.add_argument("--sky", help="V or R,G,B: the program's --sky radiosity")
    ap.add_argument("--emit", action="append", default=[], metavar="NAME=V",
                    help="as the program's --emit (repeatable)")
    sides = ap.add_mutually_exclusive_group()
    sides.add_argument("--one-sided", action="store_true")
    sides.add_argument("--two-sided", action="store_true")
    ap.add_argument("--size", help="WxH (default: the camera block's size)")
    ap.add_argument("--spp", type=int, required=True, help="samples a pixel in all")
    ap.add_argument("--batches", type=int, default=1,
                    help="split the samples into this many independent means (noise estimate)")
    ap.add_argument("--pass-spp", type=int, default=64,
                    help="samples a pixel per render call (bounds memory)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-depth", type=int, default=64)
    ap.add_argument("--show-emitters", action="store_true",
                    help="draw directly seen emitters and sky (hidden by default)")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--no-mask", action="store_true", help="skip the coverage rays")
    ap.add_argument("-o", "--output", required=True, help=".npz, .pfm or .exr")
    a = ap.parse_args(argv)

    mi = import_mitsuba(a.variant)
    t_import = time.perf_counter()
    sides_opt = "one" if a.one_sided else "two" if a.two_sided else "as-loaded"
    model = models.load_model(a.model, sides_opt)
    for item in a.emit:
        if "=" not in item:
            raise SystemExit(f"--emit: expected NAME=V, got `{item}`")
        name, value = item.rsplit("=", 1)
        model.set_emission(name, models.parse_rgb(value, "--emit"))
    cam = models.read_camera(a.camera)
    size = models.parse_size(a.size) if a.size else tuple(cam["size"])
    sky = models.parse_rgb(a.sky, "--sky") if a.sky else None
    t_read = time.perf_counter()
    scene = mi.load_dict(scene_dict(mi, model, cam, size, sky, a.max_depth,
                                     not a.show_emitters))
    t_load = time.perf_counter()
    k = max(1, a.batches)
    per = [a.spp // k + (1 if i < a.spp % k else 0) for i in range(k)]
    batches = [render(mi, scene, n, a.seed * 1000 + i, a.pass_spp) for i, n in enumerate(per) if n]
    weights = np.array([n for n in per if n], float)
    img = np.tensordot(weights / weights.sum(), np.stack(batches), axes=1)
    t_render = time.perf_counter()
    extra = {}
    if not a.no_mask:
        extra["mask"], extra["lamp"] = coverage(mi, scene, size)
    t_mask = time.perf_counter()
    out = a.output
    if out.endswith(".npz"):
        if len(batches) > 1:
            extra["batches"] = np.stack(batches).astype(np.float32)
        np.savez_compressed(out, radiance=img.astype(np.float32), **extra)
    elif out.endswith(".pfm"):
        pictures.write_pfm(out, img)
    elif out.endswith(".exr"):
        mi.Bitmap(img.astype(np.float32)).write(out)
    else:
        raise SystemExit(f"{out}: expected .npz, .pfm or .exr")
    t_end = time.perf_counter()
    print(json.dumps({
        "spp": a.spp, "size": list(size), "triangles": int(len(model.tris)),
        "import": round(t_import - T0, 3), "read": round(t_read - t_import, 3),
        "load": round(t_load - t_read, 3), "render": round(t_render - t_load, 3),
        "mask": round(t_mask - t_render, 3), "total": round(t_end - T0, 3),
    }))


if __name__ == "__main__":
    main()
