#!/usr/bin/env python3
"""The error of one picture against a reference, over the pixels that
show non-emitting geometry.

    compare.py TEST REF.npz [--radiosity] [--mask FILE.npz]

TEST is a .pfm, .exr or .npz picture; with --radiosity it is the
program's radiosity B and is divided by pi first (B = pi L for a diffuse
surface). REF is a reference.py .npz (its `mask` is used unless --mask
names another .npz; with `batches` its own noise is reported too).

Prints one JSON line: `l1_4` (the headline: relative L1 of luminance on
4 x 4 pixel blocks), `l1_1` and `l1_8` (single pixels, 8 x 8 blocks),
`bias` (relative error of the mean luminance), `ref_noise` (the expected
`l1_4` of the reference itself) and `mask_fraction`. See README.md.
"""

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pictures  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("test")
    ap.add_argument("ref")
    ap.add_argument("--radiosity", action="store_true", help="TEST holds radiosity: divide by pi")
    ap.add_argument("--mask", help=".npz whose `mask` selects the pixels (default: REF's)")
    a = ap.parse_args()
    test, _ = pictures.read_picture(a.test)
    if a.radiosity:
        test = test / np.pi
    ref, batches = pictures.read_picture(a.ref)
    z = np.load(a.mask or a.ref)
    if "mask" not in z:
        raise SystemExit(f"{a.mask or a.ref}: no mask (made by reference.py without --no-mask)")
    mask = z["mask"]
    if test.shape != ref.shape or mask.shape != ref.shape[:2]:
        raise SystemExit(f"sizes differ: {test.shape} {ref.shape} mask {mask.shape}")
    m = pictures.metrics(test, ref, mask, batches)
    m["mask_fraction"] = float(mask.mean())
    print(json.dumps({k: (round(v, 5) if isinstance(v, float) else v) for k, v in m.items()}))


if __name__ == "__main__":
    main()
