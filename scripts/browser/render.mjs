// Renders a glTF binary in headless Chromium with three.js's GLTFLoader,
// as a web page shows it, and writes the canvas as a PNG.
//
//   node render.mjs MODEL.glb OUT.png --eye X,Y,Z --look-at X,Y,Z
//        [--up X,Y,Z] [--fov DEG] [--size WxH] [--show file|colours|base]
//
// The camera options mean what the program's own options of those names
// mean (a vertical field of view in degrees), so a picture the program
// writes and one rendered here can be compared pixel for pixel.
//
// --show file (the default): the file's own materials with no light
// added, so what shows is what the file emits (a baked lightmap in
// `emissiveTexture`): the renderer as the guide's three.js snippet makes
// it, with its defaults. --show colours: every mesh drawn unlit in its
// COLOR_0 vertex colours (the program's `--export` baked light). --show
// base: every mesh drawn unlit in its material's base colour and base
// colour texture (the albedo a viewer's own lights would shade), to see
// how a model's textures lie on it.
//
// Chromium is /usr/bin/chromium (Debian's `chromium` package) unless
// CHROMIUM names another; WebGL runs on SwiftShader, so no GPU is needed.

import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const here = path.dirname(fileURLToPath(import.meta.url));

function usage(message) {
  console.error(`render.mjs: error: ${message}`);
  console.error(
    "usage: node render.mjs MODEL.glb OUT.png --eye X,Y,Z --look-at X,Y,Z [--up X,Y,Z] [--fov DEG] [--size WxH] [--show file|colours|base]",
  );
  process.exit(2);
}

function triple(name, text) {
  const v = (text ?? "").split(",").map(Number);
  if (v.length !== 3 || !v.every(Number.isFinite)) {
    usage(`${name} must be X,Y,Z, got \`${text}\``);
  }
  return v;
}

const args = process.argv.slice(2);
const positional = [];
const options = { up: "0,1,0", fov: "45", size: "320x240", show: "file" };
for (let k = 0; k < args.length; k++) {
  if (args[k].startsWith("--")) {
    const key = args[k].slice(2).replace("-a", "A");
    if (!(key in options) && key !== "eye" && key !== "lookAt") {
      usage(`unknown option ${args[k]}`);
    }
    if (k + 1 >= args.length) usage(`${args[k]} needs a value`);
    options[key] = args[++k];
  } else {
    positional.push(args[k]);
  }
}
if (positional.length !== 2) usage("give MODEL.glb and OUT.png");
const [model, out] = positional;
if (!fs.existsSync(model)) usage(`cannot read ${model}`);
const eye = triple("--eye", options.eye);
const lookAt = triple("--look-at", options.lookAt);
const up = triple("--up", options.up);
const fov = Number(options.fov);
if (!(fov > 0 && fov < 180)) usage(`--fov must be in (0, 180), got \`${options.fov}\``);
const size = /^(\d+)x(\d+)$/.exec(options.size);
if (!size) usage(`--size must be WxH, got \`${options.size}\``);
const [width, height] = [Number(size[1]), Number(size[2])];
if (!["file", "colours", "base"].includes(options.show)) {
  usage(`--show must be file, colours or base, got \`${options.show}\``);
}

// The page: three.js from node_modules, the model as /model.glb.
const page = `<!doctype html><html><body style="margin:0">
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
  "three/addons/": "/three/examples/jsm/"}}</script>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
const settings = ${JSON.stringify({ eye, lookAt, up, fov, width, height, show: options.show })};
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(settings.width, settings.height);
// Colour space and tone mapping stay at three.js's defaults (sRGB output,
// no tone mapping), as a page that only loads the file has them.
renderer.setClearColor(0x000000, 1);
document.body.appendChild(renderer.domElement);
const camera = new THREE.PerspectiveCamera(settings.fov, settings.width / settings.height, 1e-3, 1e7);
camera.position.set(...settings.eye);
camera.up.set(...settings.up);
camera.lookAt(...settings.lookAt);
new GLTFLoader().load("/model.glb", (gltf) => {
  const scene = gltf.scene;
  // Near and far planes that fit the model, so depth precision holds.
  const box = new THREE.Box3().setFromObject(scene);
  const reach = box.getSize(new THREE.Vector3()).length() + camera.position.distanceTo(box.getCenter(new THREE.Vector3()));
  camera.near = reach * 1e-5;
  camera.far = reach * 2;
  camera.updateProjectionMatrix();
  if (settings.show === "colours") {
    scene.traverse((o) => {
      if (o.isMesh) o.material = new THREE.MeshBasicMaterial({ vertexColors: true, side: o.material.side });
    });
  } else if (settings.show === "base") {
    scene.traverse((o) => {
      if (o.isMesh) {
        const m = o.material;
        o.material = new THREE.MeshBasicMaterial({ color: m.color, map: m.map, side: m.side });
      }
    });
  }
  renderer.render(scene, camera);
  window.rendered = renderer.domElement.toDataURL("image/png");
}, undefined, (e) => { window.failed = String(e && e.message || e); });
</script></body></html>`;

const types = { ".js": "text/javascript", ".glb": "model/gltf-binary", ".html": "text/html" };
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(req.url.split("?")[0]);
  let file;
  if (url === "/") {
    res.writeHead(200, { "content-type": "text/html" });
    return res.end(page);
  } else if (url === "/model.glb") {
    file = model;
  } else if (url.startsWith("/three/")) {
    file = path.join(here, "node_modules", url.slice(1));
    if (!file.startsWith(path.join(here, "node_modules", "three"))) file = null;
  }
  if (!file || !fs.existsSync(file)) {
    res.writeHead(404);
    return res.end();
  }
  res.writeHead(200, { "content-type": types[path.extname(file)] ?? "application/octet-stream" });
  fs.createReadStream(file).pipe(res);
});
await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
const { port } = server.address();

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
});
let code = 0;
try {
  const tab = await browser.newPage({ viewport: { width, height } });
  tab.on("pageerror", (e) => console.error(`page error: ${e.message}`));
  await tab.goto(`http://127.0.0.1:${port}/`);
  await tab.waitForFunction(() => window.rendered || window.failed, null, { timeout: 120000 });
  const failed = await tab.evaluate(() => window.failed);
  if (failed) {
    console.error(`render.mjs: error: three.js could not load ${model}: ${failed}`);
    code = 1;
  } else {
    const data = await tab.evaluate(() => window.rendered);
    const png = Buffer.from(data.split(",")[1], "base64");
    const tmp = `${out}.part`;
    fs.writeFileSync(tmp, png);
    fs.renameSync(tmp, out);
  }
} finally {
  await browser.close();
  server.close();
}
process.exit(code);
