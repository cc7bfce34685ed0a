#!/usr/bin/env python3
"""Render a baked lightmap (`--lightmap`) in a real browser with three.js
and compare it with the program's own picture of the same view.

    lightmap_threejs.py [--radiosity target/release/radiosity] [--work DIR]
                        [--chromium chromium] [--three DIR]
                        SCENE [radiosity options ...]

Runs `radiosity SCENE OPTIONS -o DIR/picture.png --lightmap DIR/baked.glb`
(the options must fix the camera the picture uses: a scene with a camera,
or --eye/--look-at/--up/--fov, and --size WxH), then loads `baked.glb` with
three.js's GLTFLoader (no extra code: default renderer, sRGB output, no
tone mapping, no lights) at the picture's camera in headless Chromium
(SwiftShader WebGL), takes a screenshot and prints how the two pictures
differ: the mean absolute difference of the 8-bit codes over every pixel
and channel, and the fraction of pixels whose largest channel differs by
more than 8 and by more than 32 codes (edges, where the two rasterisers
cover pixels differently, make up most of those).

three.js is taken from DIR/node_modules/three (`--three`, default
target/npm, installed there with `npm install --prefix target/npm three`
when missing). Needs python3 with no extra modules, node/npm and
Chromium (Debian: `apt-get install chromium`).
"""

import argparse
import functools
import http.server
import json
import os
import struct
import subprocess
import sys
import threading
import zlib

PAGE = """<!doctype html>
<html><head><meta charset="utf-8">
<style>html,body{margin:0;background:#000;overflow:hidden}</style>
<script type="importmap">
{"imports": {"three": "/three/build/three.module.js",
             "three/addons/": "/three/examples/jsm/"}}
</script></head><body>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
const cam = CAMERA;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(cam.width, cam.height);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(cam.fov, cam.width / cam.height, cam.near, cam.far);
camera.position.set(...cam.eye);
camera.up.set(...cam.up);
camera.lookAt(...cam.lookat);
new GLTFLoader().load('/baked.glb', (gltf) => {
  scene.add(gltf.scene);
  renderer.render(scene, camera);
  document.title = 'rendered';
});
</script></body></html>
"""


def read_png(path):
    """An 8-bit RGB or RGBA PNG as (width, height, rows of RGB bytes)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    at, idat, width, height, kind = 8, b"", 0, 0, 2
    while at < len(data):
        (length,) = struct.unpack(">I", data[at:at + 4])
        tag = data[at + 4:at + 8]
        body = data[at + 8:at + 8 + length]
        if tag == b"IHDR":
            width, height, depth, kind = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and kind in (2, 6), f"{path}: 8-bit RGB(A) only"
        elif tag == b"IDAT":
            idat += body
        at += 12 + length
    channels = 3 if kind == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        prev = line
        rows.append(bytes(line[x] for x in range(stride) if x % channels < 3))
    return width, height, rows


def camera_of(radiosity, scene, options):
    """The picture's camera, from `--info`'s `--eye ... --fov ...` line
    and the picture's size."""
    out = subprocess.run([radiosity, scene, *options, "--info"], check=True,
                         capture_output=True, text=True).stdout
    words = " ".join(l.strip() for l in out.splitlines()).split()
    cam = {}
    for flag, key in [("--eye", "eye"), ("--look-at", "lookat"), ("--up", "up")]:
        if flag in words:
            cam[key] = [float(v) for v in words[words.index(flag) + 1].split(",")]
    if "--fov" in words:
        cam["fov"] = float(words[words.index("--fov") + 1])
    missing = {"eye", "lookat", "up", "fov"} - cam.keys()
    if missing:
        sys.exit(f"--info names no {', '.join(sorted(missing))}:\n{out}")
    return cam


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--radiosity", default="target/release/radiosity")
    ap.add_argument("--work", default="target/lightmap-threejs")
    ap.add_argument("--chromium", default="chromium")
    ap.add_argument("--three", default="target/npm")
    ap.add_argument("scene")
    ap.add_argument("options", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    three = os.path.join(a.three, "node_modules", "three")
    if not os.path.exists(os.path.join(three, "package.json")):
        subprocess.run(["npm", "install", "--prefix", a.three, "--no-audit", "--no-fund",
                        "three"], check=True)
    picture = os.path.join(a.work, "picture.png")
    glb = os.path.join(a.work, "baked.glb")
    subprocess.run([a.radiosity, a.scene, *a.options, "-q", "-o", picture,
                    "--lightmap", glb], check=True)
    width, height, want = read_png(picture)
    cam = camera_of(a.radiosity, a.scene, a.options)
    span = max(abs(c) for c in cam["eye"] + cam["lookat"]) or 1.0
    cam.update(width=width, height=height, near=span * 1e-4, far=span * 100)

    root = os.path.abspath(a.work)
    with open(os.path.join(root, "index.html"), "w") as f:
        f.write(PAGE.replace("CAMERA", json.dumps(cam)))
    three_abs = os.path.abspath(three)

    class Handler(http.server.SimpleHTTPRequestHandler):
        def translate_path(self, path):
            if path.startswith("/three/"):
                return os.path.join(three_abs, path[len("/three/"):].split("?")[0])
            return super().translate_path(path)

        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(Handler, directory=root))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    shot = os.path.join(root, "threejs.png")
    url = f"http://127.0.0.1:{server.server_address[1]}/index.html"
    subprocess.run([a.chromium, "--headless", "--no-sandbox", "--hide-scrollbars",
                    "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                    "--force-device-scale-factor=1", f"--window-size={width},{height}",
                    "--virtual-time-budget=20000", f"--screenshot={shot}", url],
                   check=True, capture_output=True)
    server.shutdown()
    w2, h2, got = read_png(shot)
    if (w2, h2) != (width, height):
        sys.exit(f"screenshot is {w2}x{h2}, the picture {width}x{height}")
    total, over8, over32 = 0, 0, 0
    for y in range(height):
        for x in range(width):
            d = [abs(want[y][3 * x + c] - got[y][3 * x + c]) for c in range(3)]
            total += sum(d)
            over8 += max(d) > 8
            over32 += max(d) > 32
    n = width * height
    print(f"{a.scene}: {width}x{height}, mean |difference| {total / (3 * n):.2f} codes; "
          f"pixels off by more than 8 codes {over8 / n:.2%}, by more than 32 {over32 / n:.2%}")
    print(f"picture {picture}, three.js {shot}")


if __name__ == "__main__":
    main()
