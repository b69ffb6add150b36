#!/usr/bin/env python3
"""Writes the foliage scene of docs/shading.md into a directory: a glTF 2.0 file with textured PBR
materials and alpha-tested leaf cards (alphaMode MASK), its PNG textures, and a scene file lighting it
with a rect, a disk and a sphere light.

    python3 scripts/make_foliage_scene.py OUT_DIR [--leaves N]

Deterministic: the same arguments write the same bytes. Standard library only (PNG by zlib)."""
import argparse
import json
import math
import os
import random
import struct
import zlib


def write_png(path, width, height, rgba_rows):
    """8-bit RGBA PNG; rgba_rows: height rows of width*4 bytes, row 0 the top (glTF v = 0)."""
    raw = b"".join(b"\x00" + bytes(r) for r in rgba_rows)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def leaf_alpha(u, v):
    """The leaf's shape on its card, u across, v along (0 at the stem): 1 inside, 0 outside."""
    half = 0.46 * math.sin(math.pi * v) ** 0.75 * (1.0 - 0.25 * v)
    if abs(u - 0.5) >= half or v < 0.03 or v > 0.985:
        return 0
    for cu, cv, r in ((0.40, 0.42, 0.055), (0.62, 0.66, 0.04)):   # two holes bitten out of it
        if (u - cu) ** 2 + (v - cv) ** 2 < r * r:
            return 0
    return 1


def leaf_texture(n):
    rows = []
    for y in range(n):
        v = (y + 0.5) / n
        row = bytearray()
        for x in range(n):
            u = (x + 0.5) / n
            a = leaf_alpha(u, v)
            vein = abs(u - 0.5) < 0.012 or abs(abs(u - 0.5) - 0.35 * (v % 0.2) / 0.2) < 0.01
            g = 150 if vein else 110 + int(40 * v)
            row += bytes((40 if vein else 52, g, 38 if vein else 30, 255 if a else 0))
        rows.append(row)
    return rows


def checker_texture(n, cells):
    rows = []
    for y in range(n):
        row = bytearray()
        for x in range(n):
            c = ((x * cells // n) + (y * cells // n)) % 2
            row += bytes((186, 150, 118, 255) if c else (120, 92, 74, 255))
        rows.append(row)
    return rows


class Mesh:
    def __init__(self):
        self.pos, self.nrm, self.uv, self.idx = [], [], [], []

    def quad(self, p0, p1, p2, p3, uvs=((0, 0), (1, 0), (1, 1), (0, 1))):
        e1 = [p1[i] - p0[i] for i in range(3)]
        e2 = [p3[i] - p0[i] for i in range(3)]
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        ln = math.sqrt(sum(c * c for c in n)) or 1.0
        n = [c / ln for c in n]
        b = len(self.pos)
        for p, t in zip((p0, p1, p2, p3), uvs):
            self.pos.append(tuple(p))
            self.nrm.append(tuple(n))
            self.uv.append(tuple(t))
        self.idx += [b, b + 1, b + 2, b, b + 2, b + 3]

    def box(self, lo, hi):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        self.quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))   # top
        self.quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))   # +z
        self.quad((x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0))   # -z
        self.quad((x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1))   # +x
        self.quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))   # -x


def leaf_cards(mesh, n, seed):
    """A plant: n leaf cards on stems around an axis, tilted out and drooping, each a textured quad."""
    rng = random.Random(seed)
    for i in range(n):
        az = 2 * math.pi * (i * 0.618034 % 1.0) + rng.uniform(-0.2, 0.2)
        base_h = 0.35 + 1.1 * i / n + rng.uniform(-0.05, 0.05)
        tilt = math.radians(rng.uniform(35, 70))
        length, width = rng.uniform(0.75, 1.0), rng.uniform(0.38, 0.5)
        d = (math.cos(az) * math.sin(tilt), math.cos(tilt), math.sin(az) * math.sin(tilt))   # along the leaf
        s = (-math.sin(az), 0.0, math.cos(az))                                               # across it
        roll = rng.uniform(-0.35, 0.35)   # turn the blade about its axis
        s = (s[0] * math.cos(roll) + 0.0, math.sin(roll), s[2] * math.cos(roll))
        origin = (0.06 * math.cos(az), base_h, 0.06 * math.sin(az))
        p = lambda a, b: tuple(origin[k] + a * s[k] * width + b * d[k] * length for k in range(3))
        mesh.quad(p(-0.5, 0), p(0.5, 0), p(0.5, 1), p(-0.5, 1))


def gltf(out_dir, leaves):
    parts = {"ground": Mesh(), "stone": Mesh(), "lacquer": Mesh(), "brass": Mesh(), "leaf": Mesh()}
    parts["ground"].quad((-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6), ((0, 6), (6, 6), (6, 0), (0, 0)))
    parts["stone"].box((-0.45, 0.0, -0.45), (0.45, 0.3, 0.45))      # the pot
    parts["stone"].box((1.6, 0.0, -1.9), (2.6, 1.4, -0.9))          # a block behind
    parts["lacquer"].box((-2.6, 0.0, 0.4), (-1.8, 0.8, 1.2))        # a glossy red cube
    parts["brass"].box((0.9, 0.0, 1.3), (1.3, 0.25, 1.7))           # a small brass block
    leaf_cards(parts["leaf"], leaves, 7)

    blob = bytearray()
    views, accessors, meshes = [], [], []

    def add(data, fmt, count, comps, ctype, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(struct.pack("<%d%s" % (len(data), fmt), *data))
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off, "target": target})
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": comps}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    materials = [
        {"name": "ground", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0,
                                                    "roughnessFactor": 0.85}},
        {"name": "stone", "pbrMetallicRoughness": {"baseColorFactor": [0.62, 0.60, 0.56, 1.0],
                                                   "metallicFactor": 0.0, "roughnessFactor": 0.55}},
        {"name": "lacquer", "pbrMetallicRoughness": {"baseColorFactor": [0.62, 0.08, 0.05, 1.0],
                                                     "metallicFactor": 0.0, "roughnessFactor": 0.25}},
        {"name": "brass", "pbrMetallicRoughness": {"baseColorFactor": [0.91, 0.78, 0.42, 1.0],
                                                   "metallicFactor": 1.0, "roughnessFactor": 0.5}},
        {"name": "leaf", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "metallicFactor": 0.0,
                                                  "roughnessFactor": 0.6},
         "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True},
    ]
    for mi, name in enumerate(("ground", "stone", "lacquer", "brass", "leaf")):
        m = parts[name]
        flat = [c for p in m.pos for c in p]
        lo = [min(p[k] for p in m.pos) for k in range(3)]
        hi = [max(p[k] for p in m.pos) for k in range(3)]
        a_pos = add(flat, "f", len(m.pos), "VEC3", 5126, 34962, (lo, hi))
        a_nrm = add([c for n in m.nrm for c in n], "f", len(m.nrm), "VEC3", 5126, 34962)
        a_uv = add([c for t in m.uv for c in t], "f", len(m.uv), "VEC2", 5126, 34962)
        a_idx = add(m.idx, "I", len(m.idx), "SCALAR", 5125, 34963)
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": a_pos, "NORMAL": a_nrm,
                                                                     "TEXCOORD_0": a_uv},
                                                      "indices": a_idx, "material": mi}]})
    with open(os.path.join(out_dir, "foliage.bin"), "wb") as f:
        f.write(blob)
    doc = {
        "asset": {"version": "2.0", "generator": "microshadow scripts/make_foliage_scene.py"},
        "scene": 0, "scenes": [{"nodes": list(range(len(meshes)))}],
        "nodes": [{"mesh": i} for i in range(len(meshes))],
        "meshes": meshes, "materials": materials,
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}],
        "images": [{"uri": "ground.png"}, {"uri": "leaf.png"}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "buffers": [{"uri": "foliage.bin", "byteLength": len(blob)}],
        "bufferViews": views, "accessors": accessors,
    }
    with open(os.path.join(out_dir, "foliage.gltf"), "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--leaves", type=int, default=24)
    ap.add_argument("--size", type=int, nargs=2, default=(960, 640), metavar=("W", "H"))
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    write_png(os.path.join(a.out_dir, "leaf.png"), 128, 128, leaf_texture(128))
    write_png(os.path.join(a.out_dir, "ground.png"), 64, 64, checker_texture(64, 8))
    gltf(a.out_dir, a.leaves)
    scene = {
        "meshes": [{"file": "foliage.gltf"}],
        "camera": {"eye": [3.2, 3.1, 5.2], "target": [0.0, 0.9, 0.0], "up": [0, 1, 0], "fov_y": 45,
                   "width": a.size[0], "height": a.size[1]},
        "lights": [
            {"corner": [-0.9, 3.4, -2.4], "edge_s": [1.4, 0, 0], "edge_t": [0, 0, 1.0], "power": 260},
            {"shape": "disk", "center": [-3.2, 2.6, 2.4], "normal": [0.8, -0.45, -0.4], "radius": 0.45,
             "power": [110, 80, 50]},
            {"shape": "sphere", "center": [2.3, 2.4, 1.4], "radius": 0.25, "power": [40, 55, 90]},
        ],
        "render": {"samples": 1024},
    }
    with open(os.path.join(a.out_dir, "foliage.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
