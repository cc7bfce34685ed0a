"""Reading a model as `radiosity` reads it: triangles with a diffuse
reflectance, an emitted radiosity and a sidedness each, and the camera
block of a `.sc` file.

Only what changes the light is read, with the program's rules (see
`src/scene/import/obj/` and `src/scene/import/gltf.rs`):

- OBJ: every face is two-sided; `Kd` is the reflectance (default 0.8
  when a material has none, or for faces with no or an unknown material),
  a `Kd` with a channel at or above one is scaled so its brightest channel
  is 0.95; `map_Kd` multiplies `Kd` by the texture's mean linear colour
  when the file can be read; `Ke` is the emitted radiosity; a material
  with both follows `Material::with_emission` (the colour of `Ke`, the
  luminance of `Kd`). Faces are fan-triangulated (the program keeps
  convex faces whole and ear-clips the others: the same surface for the
  planar convex faces real exports are made of).
- glTF / glb: the default scene's nodes with their transforms (a
  mirroring transform reverses the winding); TRIANGLES, TRIANGLE_STRIP and
  TRIANGLE_FAN primitives; reflectance `baseColorFactor` times the mean of
  `baseColorTexture`, scaled below one like `Kd`; emission
  `emissiveFactor` x `KHR_materials_emissive_strength` x the mean of
  `emissiveTexture`; two-sided where the material is `doubleSided`.
  Primitives without a material get reflectance 0.8, one-sided.
- `--emit NAME=V`: the material, OBJ object (`o`) or group (`g`), glTF
  node or mesh named NAME emits V, keeping its reflectance as
  `Material::with_emission` says.

Needs numpy; texture means use Mitsuba's image reader (`mitsuba.Bitmap`).
"""

import json
import math
import os
import re
import struct
import sys
import tempfile

import numpy as np

DEFAULT_REFLECTANCE = 0.8
MAX_MTL_REFLECTANCE = 0.95
LUMA = np.array([0.2126, 0.7152, 0.0722])


def warn(message):
    print(f"warning: {message}", file=sys.stderr)


# ---------------------------------------------------------------- materials


class Material:
    """A diffuse material as the program keeps it: one colour, a
    reflectance factor and an emission factor (see `Material` in
    `src/scene/mod.rs`). Reflectance = color * kd, emission = color * ke."""

    def __init__(self, name, color, kd, ke):
        self.name = name
        self.color = np.asarray(color, float)
        self.kd = float(kd)
        self.ke = float(ke)

    @staticmethod
    def diffuse(name, rho):
        return Material(name, rho, 1.0, 0.0)

    def reflectance(self):
        return self.color * self.kd

    def emission(self):
        return self.color * self.ke

    def with_emission(self, e):
        """`Material::with_emission`: the colour of the emission, the
        luminance of the reflectance, no channel above its old largest."""
        e = np.asarray(e, float)
        rho = self.reflectance()
        if not e.any():
            return Material(self.name, self.color, self.kd, 0.0)
        if not rho.any():
            return Material(self.name, e, 0.0, 1.0)
        lum = lambda c: max(float(LUMA @ c), sys.float_info.min)
        k = min(lum(rho) / lum(e), rho.max() / e.max())
        return Material(self.name, e, k, 1.0)


def capped(rho):
    """A reflectance with a channel at or above one, scaled so its
    brightest channel is MAX_MTL_REFLECTANCE (as the importers do)."""
    rho = np.asarray(rho, float)
    if rho.max() >= 1.0:
        return rho * (MAX_MTL_REFLECTANCE / rho.max())
    return rho


def srgb_to_linear(c):
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def image_mean(path):
    """The mean linear RGB of an image file (8/16-bit decoded from sRGB,
    float taken as linear, alpha ignored), or None when it cannot be read."""
    try:
        import mitsuba as mi

        bmp = mi.Bitmap(path)
        fmt = bmp.component_format()
        a = np.array(bmp, dtype=np.float64)
    except Exception as e:  # unreadable or missing: the program keeps Kd
        warn(f"cannot read texture {path}: {e}")
        return None
    if a.ndim == 2:
        a = a[:, :, None]
    if a.shape[2] in (1, 2):  # grey, grey+alpha
        a = np.repeat(a[:, :, :1], 3, axis=2)
    a = a[:, :, :3]
    is_float = "Float" in str(fmt)
    if not is_float:
        a = a / (255.0 if "UInt8" in str(fmt) else 65535.0)
        a = srgb_to_linear(a)
    else:
        a = np.clip(a, 0.0, 1.0)
    return a.reshape(-1, 3).mean(axis=0)


# ------------------------------------------------------------------- scene


class Model:
    """Triangles (`tris`, shape (T, 3, 3), world positions), a material
    index and a two-sided flag per triangle, the materials, and named sets
    of triangles (`groups`: name -> list of index arrays) for `--emit`."""

    def __init__(self, path, tris, mat, two_sided, materials, groups):
        self.path = path
        self.tris = tris
        self.mat = mat
        self.two_sided = two_sided
        self.materials = materials
        self.groups = groups

    def bounds(self):
        p = self.tris.reshape(-1, 3)
        return p.min(axis=0), p.max(axis=0)

    def set_emission(self, name, e):
        """`Scene::set_emission`: materials named `name` change in place;
        the triangles of objects/groups named `name` get a changed copy of
        their material. Returns the number of triangles covered."""
        named = [i for i, m in enumerate(self.materials) if m.name == name]
        members = self.groups.get(name)
        if not named and members is None:
            known = sorted({m.name for m in self.materials} | set(self.groups))
            raise SystemExit(
                f"--emit {name}: no material, object or group of that name; "
                f"there are: {', '.join(known[:30])}{' ...' if len(known) > 30 else ''}"
            )
        for i in named:
            self.materials[i] = self.materials[i].with_emission(e)
        covered = np.isin(self.mat, named)
        if members is not None:
            ids = np.unique(np.concatenate(members)) if members else np.zeros(0, int)
            ids = ids[~covered[ids]]
            for m in np.unique(self.mat[ids]):
                sel = ids[self.mat[ids] == m]
                new = self.materials[m].with_emission(e)
                if len(sel) == int((self.mat == m).sum()):
                    self.materials[m] = new
                else:
                    new.name = f"{self.materials[m].name} ({name})"
                    self.materials.append(new)
                    self.mat[sel] = len(self.materials) - 1
                covered[sel] = True
        return int(covered.sum())


def load_model(path, sides="as-loaded"):
    """Reads an OBJ or glTF/glb model. `sides`: 'as-loaded', 'one'
    (`--one-sided`) or 'two' (`--two-sided`)."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        model = load_obj(path)
    elif ext in (".glb", ".gltf"):
        model = load_gltf(path)
    else:
        raise SystemExit(f"{path}: not an .obj, .gltf or .glb file")
    if sides == "one":
        model.two_sided[:] = False
    elif sides == "two":
        model.two_sided[:] = True
    return model


# --------------------------------------------------------------------- OBJ


def _mtl_color(words, file, line):
    vals = words[1:]
    if len(vals) not in (1, 3):
        raise SystemExit(f"{file}:{line}: `{words[0]}` takes 1 or 3 numbers")
    c = np.array([float(x) for x in vals], float)
    if (c < 0).any() or not np.isfinite(c).all():
        raise SystemExit(f"{file}:{line}: negative or non-finite `{words[0]}`")
    return np.repeat(c, 3) if len(c) == 1 else c


_MAP_OPTS = {"-o": 3, "-s": 3, "-t": 3, "-mm": 2, "-blendu": 1, "-blendv": 1, "-bm": 1,
             "-boost": 1, "-cc": 1, "-clamp": 1, "-imfchan": 1, "-texres": 1, "-type": 1}


def _map_file(rest):
    w = rest.split()
    i = 0
    while i < len(w) and w[i] in _MAP_OPTS:
        n = _MAP_OPTS[w[i]]
        i += 1
        for _ in range(n):
            if i < len(w) and (n < 3 or _is_number(w[i])):
                i += 1
            else:
                break
    if i >= len(w):
        return None
    # The rest of the line from that word on (names with spaces are kept).
    m = re.match(r"\s*" + r"\s+".join(re.escape(x) for x in w[:i]) + r"\s*(.*)$", rest)
    return (m.group(1) if m else " ".join(w[i:])).strip().replace("\\", "/")


def _is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def read_mtl(path):
    """name -> Material for one MTL file (the program's rules)."""
    out = {}
    with open(path, "rb") as f:
        text = f.read().decode("utf-8", "replace").lstrip("\ufeff")
    cur = None
    blocks = []
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        key = words[0]
        if key == "newmtl":
            cur = {"name": line[len("newmtl"):].strip(), "kd": None, "ke": np.zeros(3), "map": None}
            blocks.append(cur)
        elif cur is None:
            continue
        elif key == "Kd":
            kd = _mtl_color(words, path, n)
            cur["kd"] = capped(kd)
        elif key == "Ke":
            cur["ke"] = _mtl_color(words, path, n)
        elif key == "map_Kd":
            cur["map"] = _map_file(line[len("map_Kd"):])
    folder = os.path.dirname(path)
    missing = []
    for b in blocks:
        kd = b["kd"] if b["kd"] is not None else np.full(3, DEFAULT_REFLECTANCE)
        if b["map"]:
            tex_path = os.path.join(folder, b["map"])
            t = image_mean(tex_path) if os.path.exists(tex_path) else None
            if t is None:
                missing.append(b["map"])
            else:
                kd = kd * t
        m = Material.diffuse(b["name"], kd).with_emission(b["ke"])
        out[b["name"]] = m
    if missing:
        warn(f"{path}: {len(missing)} map_Kd texture(s) not read (first {missing[0]}); "
             "their materials keep Kd, as the program does")
    return out


def load_obj(path):
    with open(path, "rb") as f:
        text = f.read().decode("utf-8", "replace").lstrip("\ufeff")
    folder = os.path.dirname(path)
    verts = []
    tris = []  # vertex index triples
    tri_mat = []
    tri_set = []
    materials = [Material.diffuse("(no usemtl)", np.full(3, DEFAULT_REFLECTANCE))]
    mat_index = {}
    library = {}
    current_mat = 0
    obj_name = None
    group_names = []
    sets = {}
    current_set = None
    for raw in text.splitlines():
        if not raw or raw[0] == "#":
            continue
        line = raw.split("#", 1)[0]
        words = line.split()
        if not words:
            continue
        key = words[0]
        if key == "v":
            verts.append((float(words[1]), float(words[2]), float(words[3])))
        elif key == "f":
            idx = []
            nv = len(verts)
            for w in words[1:]:
                i = int(w.split("/", 1)[0])
                idx.append(i - 1 if i > 0 else nv + i)
            if current_set is None:
                key_ = (obj_name, tuple(group_names))
                current_set = sets.setdefault(key_, len(sets))
            for k in range(1, len(idx) - 1):
                tris.append((idx[0], idx[k], idx[k + 1]))
                tri_mat.append(current_mat)
                tri_set.append(current_set)
        elif key == "usemtl":
            name = line[line.index("usemtl") + 6:].strip()
            if name not in mat_index:
                if name in library:
                    materials.append(library[name])
                else:
                    warn(f"{path}: material `{name}` is defined by no library: default 0.8")
                    materials.append(Material.diffuse(name, np.full(3, DEFAULT_REFLECTANCE)))
                mat_index[name] = len(materials) - 1
            current_mat = mat_index[name]
        elif key == "mtllib":
            rest = line[line.index("mtllib") + 6:].strip()
            names = [rest] if os.path.isfile(os.path.join(folder, rest)) else rest.split()
            for name in names:
                p = os.path.join(folder, name.replace("\\", "/"))
                if os.path.isfile(p):
                    library.update(read_mtl(p))
                else:
                    warn(f"{path}: cannot read material library {p}")
        elif key == "o":
            obj_name = line[line.index("o") + 1:].strip() or None
            current_set = None
        elif key == "g":
            group_names = words[1:]
            current_set = None
    v = np.array(verts, float)
    t = np.array(tris, np.int64)
    tri_set = np.array(tri_set, np.int64)
    groups = {}
    for (o, gs), s in sets.items():
        ids = np.nonzero(tri_set == s)[0]
        for name in ([o] if o else []) + list(gs):
            groups.setdefault(name, []).append(ids)
    return Model(path, v[t], np.array(tri_mat, np.int64), np.ones(len(t), bool),
                 materials, groups)


# -------------------------------------------------------------------- glTF

_COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
              5125: np.uint32, 5126: np.float32}
_COUNT = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _read_glb(data, path):
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67:
        raise SystemExit(f"{path}: not a glb file")
    off = 12
    js, bin_ = None, None
    while off < len(data):
        clen, ctype = struct.unpack_from("<II", data, off)
        chunk = data[off + 8: off + 8 + clen]
        if ctype == 0x4E4F534A:
            js = json.loads(chunk)
        elif ctype == 0x004E4942:
            bin_ = chunk
        off += 8 + clen
    return js, bin_


def _node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], float).reshape(4, 4).T
    t = np.eye(4)
    r = np.eye(4)
    s = np.eye(4)
    if "translation" in node:
        t[:3, 3] = node["translation"]
    if "rotation" in node:
        x, y, z, w = node["rotation"]
        r[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    if "scale" in node:
        s[:3, :3] = np.diag(node["scale"])
    return t @ r @ s


def load_gltf(path):
    import base64
    import urllib.parse

    with open(path, "rb") as f:
        data = f.read()
    folder = os.path.dirname(path)
    if data[:4] == b"glTF":
        js, glb_bin = _read_glb(data, path)
    else:
        js, glb_bin = json.loads(data.decode("utf-8")), None
    buffers = []
    for i, b in enumerate(js.get("buffers", [])):
        uri = b.get("uri")
        if uri is None:
            buffers.append(glb_bin)
        elif uri.startswith("data:"):
            buffers.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            with open(os.path.join(folder, urllib.parse.unquote(uri)), "rb") as f:
                buffers.append(f.read())

    def view_bytes(i):
        bv = js["bufferViews"][i]
        b = buffers[bv["buffer"]]
        start = bv.get("byteOffset", 0)
        return b[start: start + bv["byteLength"]], bv.get("byteStride", 0)

    def accessor(i):
        a = js["accessors"][i]
        dt = np.dtype(_COMPONENT[a["componentType"]])
        n = _COUNT[a["type"]]
        count = a["count"]
        if "bufferView" in a:
            raw, stride = view_bytes(a["bufferView"])
            off = a.get("byteOffset", 0)
            size = n * dt.itemsize
            if stride and stride != size:
                rows = np.frombuffer(raw, np.uint8, count=stride * (count - 1) + size, offset=off)
                rows = np.lib.stride_tricks.as_strided(rows, (count, size), (stride, 1))
                out = rows.copy().view(dt).reshape(count, n)
            else:
                out = np.frombuffer(raw, dt, count=count * n, offset=off).reshape(count, n)
            out = out.copy()
        else:
            out = np.zeros((count, n), dt)
        if "sparse" in a:
            sp = a["sparse"]
            ii = sp["indices"]
            raw, _ = view_bytes(ii["bufferView"])
            idx = np.frombuffer(raw, _COMPONENT[ii["componentType"]], count=sp["count"],
                                offset=ii.get("byteOffset", 0))
            vv = sp["values"]
            raw, _ = view_bytes(vv["bufferView"])
            vals = np.frombuffer(raw, dt, count=sp["count"] * n, offset=vv.get("byteOffset", 0))
            out[idx.astype(np.int64)] = vals.reshape(-1, n)
        return out

    def texture_mean(info):
        if info is None:
            return None
        img = js["images"][js["textures"][info["index"]]["source"]]
        if "bufferView" in img:
            raw, _ = view_bytes(img["bufferView"])
            suffix = ".png" if "png" in img.get("mimeType", "") else ".jpg"
            with tempfile.NamedTemporaryFile(suffix=suffix, delete=False) as f:
                f.write(raw)
            try:
                return image_mean(f.name)
            finally:
                os.unlink(f.name)
        uri = img.get("uri", "")
        if uri.startswith("data:"):
            raw = base64.b64decode(uri.split(",", 1)[1])
            with tempfile.NamedTemporaryFile(suffix=".img", delete=False) as f:
                f.write(raw)
            try:
                return image_mean(f.name)
            finally:
                os.unlink(f.name)
        return image_mean(os.path.join(folder, urllib.parse.unquote(uri)))

    materials = []
    double_sided = []
    for i, m in enumerate(js.get("materials", [])):
        name = m.get("name") or f"materials[{i}]"
        pbr = m.get("pbrMetallicRoughness", {})
        rho = np.array(pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], float)
        t = texture_mean(pbr.get("baseColorTexture"))
        if t is not None:
            rho = rho * t
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
            "emissiveStrength", 1.0)
        e = np.array(m.get("emissiveFactor", [0, 0, 0]), float) * strength
        t = texture_mean(m.get("emissiveTexture"))
        if t is not None:
            e = e * t
        materials.append(Material.diffuse(name, capped(rho)).with_emission(e))
        double_sided.append(bool(m.get("doubleSided", False)))
    default_material = None

    tris, mats, sides = [], [], []
    groups = {}
    count = 0

    def add_group(name, first, last):
        if name:
            groups.setdefault(name, []).append(np.arange(first, last))

    def walk(i, parent):
        nonlocal count, default_material
        node = js["nodes"][i]
        world = parent @ _node_matrix(node)
        if "mesh" in node:
            first = count
            mesh = js["meshes"][node["mesh"]]
            mirrored = np.linalg.det(world[:3, :3]) < 0
            for prim in mesh["primitives"]:
                mode = prim.get("mode", 4)
                if mode not in (4, 5, 6):
                    continue
                pos = accessor(prim["attributes"]["POSITION"]).astype(np.float64)
                if "indices" in prim:
                    idx = accessor(prim["indices"]).reshape(-1).astype(np.int64)
                else:
                    idx = np.arange(len(pos))
                if mode == 4:
                    t = idx[: len(idx) // 3 * 3].reshape(-1, 3)
                elif mode == 5:  # strip: odd triangles reversed
                    k = np.arange(len(idx) - 2)
                    a, b, c = idx[k], idx[k + 1], idx[k + 2]
                    odd = k % 2 == 1
                    t = np.stack([a, np.where(odd, c, b), np.where(odd, b, c)], axis=1)
                else:  # fan
                    k = np.arange(1, len(idx) - 1)
                    t = np.stack([np.full(len(k), idx[0]), idx[k], idx[k + 1]], axis=1)
                p = (np.c_[pos, np.ones(len(pos))] @ world.T)[:, :3]
                tri = p[t]
                if mirrored:
                    tri = tri[:, [0, 2, 1]]
                if "material" in prim:
                    mid = prim["material"]
                    ds = double_sided[mid]
                else:
                    if default_material is None:
                        materials.append(Material.diffuse("(no material)",
                                                          np.full(3, DEFAULT_REFLECTANCE)))
                        double_sided.append(False)
                        default_material = len(materials) - 1
                    mid, ds = default_material, False
                tris.append(tri)
                mats.append(np.full(len(tri), mid, np.int64))
                sides.append(np.full(len(tri), ds, bool))
                count += len(tri)
            add_group(node.get("name"), first, count)
            add_group(mesh.get("name"), first, count)
        for c in node.get("children", []):
            walk(c, world)

    scenes = js.get("scenes", [])
    if scenes:
        roots = scenes[js.get("scene", 0)].get("nodes", [])
    else:
        children = {c for n in js.get("nodes", []) for c in n.get("children", [])}
        roots = [i for i in range(len(js.get("nodes", []))) if i not in children]
    for r in roots:
        walk(r, np.eye(4))
    if not tris:
        raise SystemExit(f"{path}: no triangles")
    return Model(path, np.concatenate(tris), np.concatenate(mats), np.concatenate(sides),
                 materials, groups)


# ------------------------------------------------------------------ camera


def read_camera(path):
    """The `camera ... end` block of a `.sc` file as a dict: eye, lookat,
    up (default 0 1 0), fov (degrees, default 45), size (default 640 480)."""
    with open(path, encoding="utf-8-sig") as f:
        text = f.read()
    tokens = []
    for line in text.splitlines():
        tokens += line.split("#", 1)[0].split()
    try:
        i = tokens.index("camera")
    except ValueError:
        raise SystemExit(f"{path}: no camera block")
    cam = {"up": [0.0, 1.0, 0.0], "fov": 45.0, "size": [640, 480]}
    i += 1
    arity = {"eye": 3, "lookat": 3, "up": 3, "fov": 1, "size": 2}
    while i < len(tokens) and tokens[i] != "end":
        key = tokens[i]
        if key not in arity:
            raise SystemExit(f"{path}: unknown camera field `{key}`")
        vals = tokens[i + 1: i + 1 + arity[key]]
        cam[key] = [float(v) for v in vals] if arity[key] > 1 else float(vals[0])
        i += 1 + arity[key]
    if "eye" not in cam or "lookat" not in cam:
        raise SystemExit(f"{path}: the camera needs eye and lookat")
    cam["size"] = [int(v) for v in cam["size"]]
    return cam


def parse_rgb(text, what):
    """`V` or `R,G,B` as on the program's command line."""
    parts = text.split(",")
    if len(parts) not in (1, 3):
        raise SystemExit(f"{what}: expected V or R,G,B, got `{text}`")
    v = np.array([float(p) for p in parts], float)
    return np.repeat(v, 3) if len(v) == 1 else v


def parse_size(text):
    m = re.fullmatch(r"(\d+)x(\d+)", text)
    if not m:
        raise SystemExit(f"--size: expected WxH, got `{text}`")
    return int(m.group(1)), int(m.group(2))
