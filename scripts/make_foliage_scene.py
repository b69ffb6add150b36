#!/usr/bin/env python3
"""Writes the foliage demo scene of docs/shading.md ("Alpha-tested occluders") into a directory:

    scripts/make_foliage_scene.py OUTDIR     # then: microshadow OUTDIR/foliage.json -o foliage.png

A glTF 2.0 file with textured PBR materials (a checkered ground, a stone pedestal, a striped metal ball, a
stem) and a plant of leaf cards cut out by a leaf-shaped alpha mask (alphaMode MASK, cutoff 0.5), lit by a
rect, a disk and a sphere light. Everything is generated (deterministic: a fixed seed), so the repository
holds this script, not the binaries. Standard library only (zlib for the PNGs)."""
import json
import math
import os
import random
import struct
import sys
import zlib


def png(path, w, h, rgba):
    """8-bit RGBA PNG from a flat list of (r, g, b, a) tuples, row 0 at the top."""
    raw = bytearray()
    for y in range(h):
        raw.append(0)
        for x in range(w):
            raw.extend(max(0, min(255, int(c))) for c in rgba[y * w + x])

    def chunk(t, d):
        c = zlib.crc32(t + d) & 0xFFFFFFFF
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", c)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(bytes(raw), 9)))
        f.write(chunk(b"IEND", b""))


def leaf_texture(path):
    """A pointed leaf along u with a midrib and veins; transparent around it and in a bite out of one side."""
    w, h = 128, 64
    px = []
    for y in range(h):
        for x in range(w):
            u, v = (x + 0.5) / w, (y + 0.5) / h
            half = 0.46 * math.sin(math.pi * min(max((u - 0.04) / 0.92, 0.0), 1.0)) ** 0.8  # half width at u
            d = abs(v - 0.5)
            bite = (u - 0.62) ** 2 + ((v - 0.88) * 1.6) ** 2 < 0.012
            inside = d < half and not bite
            f = (u - 1.1 * d) * 7.0
            vein = d < 0.015 or abs(f - math.floor(f) - 0.5) < 0.035
            g = 0.55 + 0.25 * (1 - d / max(half, 1e-3))
            col = (40, int(120 + 90 * g), 45) if not vein else (90, 170, 70)
            px.append(col + ((255 if inside else 0),))
    png(path, w, h, px)


def checker_texture(path):
    w = h = 64
    px = []
    for y in range(h):
        for x in range(w):
            c = ((x // 32) + (y // 32)) % 2
            n = random.randint(-8, 8)
            px.append((170 + n, 120 + n, 90 + n, 255) if c else (210 + n, 200 + n, 180 + n, 255))
    png(path, w, h, px)


def stripe_texture(path):
    w, h = 64, 32
    px = []
    for y in range(h):
        for x in range(w):
            px.append((60, 90, 200, 255) if (x // 8) % 2 else (230, 190, 60, 255))
    png(path, w, h, px)


class Mesh:
    def __init__(self):
        self.pos, self.uv, self.nrm = [], [], []

    def tri(self, a, b, c, ta, tb, tc, n=None):
        if n is None:
            e1 = [b[i] - a[i] for i in range(3)]
            e2 = [c[i] - a[i] for i in range(3)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            ln = math.sqrt(sum(x * x for x in n)) or 1.0
            n = [x / ln for x in n]
            n = [n, n, n]
        self.pos += [a, b, c]
        self.uv += [ta, tb, tc]
        self.nrm += n

    def quad(self, p0, p1, p2, p3, uv=((0, 0), (1, 0), (1, 1), (0, 1))):
        self.tri(p0, p1, p2, uv[0], uv[1], uv[2])
        self.tri(p0, p2, p3, uv[0], uv[2], uv[3])

    def box(self, lo, hi):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        for f in ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)):
            self.quad(*[c[i] for i in f])


def sphere(m, c, r, nu=32, nv=16):
    def p(i, j):
        th, ph = 2 * math.pi * i / nu, math.pi * j / nv
        n = (math.sin(ph) * math.cos(th), math.cos(ph), math.sin(ph) * math.sin(th))
        return tuple(c[k] + r * n[k] for k in range(3)), n, (i / nu, j / nv)

    for i in range(nu):
        for j in range(nv):
            a, b, cc, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            for t in ((a, b, cc), (a, cc, d)):
                m.tri(t[0][0], t[1][0], t[2][0], t[0][2], t[1][2], t[2][2], [t[0][1], t[1][1], t[2][1]])


def plant(leaves, stem, n_leaves, seed):
    rnd = random.Random(seed)
    base = (0.0, 0.5, 0.0)
    stem.box((-0.035, 0.5, -0.035), (0.035, 2.3, 0.035))
    for k in range(n_leaves):
        t = k / (n_leaves - 1)
        y = base[1] + 0.25 + 1.95 * t
        az = k * 2.39996 + rnd.uniform(-0.2, 0.2)          # golden angle
        length = 1.05 - 0.45 * t + rnd.uniform(-0.05, 0.05)
        width = 0.5 * length
        droop = 0.35 + 0.5 * t + rnd.uniform(-0.1, 0.1)     # radians below horizontal at the tip
        d = (math.cos(az) * math.cos(droop), -math.sin(droop) * 0.6 + 0.25, math.sin(az) * math.cos(droop))
        ln = math.sqrt(sum(x * x for x in d))
        d = tuple(x / ln for x in d)
        side = (-math.sin(az), 0.0, math.cos(az))
        roll = rnd.uniform(-0.5, 0.5)
        up = (d[1] * side[2] - d[2] * side[1], d[2] * side[0] - d[0] * side[2], d[0] * side[1] - d[1] * side[0])
        s = tuple(math.cos(roll) * side[i] + math.sin(roll) * up[i] for i in range(3))
        o = (0.0, y, 0.0)
        p0 = tuple(o[i] - 0.5 * width * s[i] for i in range(3))
        p1 = tuple(o[i] + length * d[i] - 0.5 * width * s[i] for i in range(3))
        p2 = tuple(o[i] + length * d[i] + 0.5 * width * s[i] for i in range(3))
        p3 = tuple(o[i] + 0.5 * width * s[i] for i in range(3))
        leaves.quad(p0, p1, p2, p3, ((0, 0), (1, 0), (1, 1), (0, 1)))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_foliage_scene.py OUTDIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    random.seed(15)
    leaf_texture(os.path.join(out, "leaf.png"))
    checker_texture(os.path.join(out, "checker.png"))
    stripe_texture(os.path.join(out, "stripes.png"))

    ground, pedestal, ball, stem, leaves = Mesh(), Mesh(), Mesh(), Mesh(), Mesh()
    ground.quad((-6, 0, -6), (-6, 0, 6), (6, 0, 6), (6, 0, -6), ((0, 0), (0, 6), (6, 6), (6, 0)))
    pedestal.box((-0.45, 0.0, -0.45), (0.45, 0.5, 0.45))
    sphere(ball, (1.35, 0.42, 0.75), 0.42)
    plant(leaves, stem, 26, 7)

    # (mesh, material): materials 0 ground, 1 pedestal, 2 ball, 3 stem, 4 leaves
    meshes = [(ground, 0), (pedestal, 1), (ball, 2), (stem, 3), (leaves, 4)]
    blob = bytearray()
    views, accessors, gmeshes = [], [], []

    def add(data, fmt, n, typ, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        for item in data:
            blob.extend(struct.pack(fmt, *item))
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
        acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": n, "type": typ}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    for m, mat in meshes:
        lo = [min(p[i] for p in m.pos) for i in range(3)]
        hi = [max(p[i] for p in m.pos) for i in range(3)]
        ip = add(m.pos, "<3f", len(m.pos), "VEC3", (lo, hi))
        inn = add(m.nrm, "<3f", len(m.nrm), "VEC3")
        it = add(m.uv, "<2f", len(m.uv), "VEC2")
        gmeshes.append({"primitives": [{"attributes": {"POSITION": ip, "NORMAL": inn, "TEXCOORD_0": it}, "material": mat}]})
    with open(os.path.join(out, "foliage.bin"), "wb") as f:
        f.write(blob)

    def mat(tex, rough, metal=0.0, color=(1, 1, 1, 1), alpha=None):
        pbr = {"baseColorFactor": list(color), "metallicFactor": metal, "roughnessFactor": rough}
        if tex is not None:
            pbr["baseColorTexture"] = {"index": tex}
        m = {"pbrMetallicRoughness": pbr}
        if alpha:
            m.update({"alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True})
        return m

    gltf = {
        "asset": {"version": "2.0", "generator": "microshadow scripts/make_foliage_scene.py"},
        "scene": 0, "scenes": [{"nodes": list(range(len(meshes)))}],
        "nodes": [{"mesh": i} for i in range(len(meshes))],
        "meshes": gmeshes,
        "materials": [mat(0, 0.8), mat(None, 0.35, 0.0, (0.55, 0.52, 0.48, 1)), mat(1, 0.25, 0.9),
                      mat(None, 0.7, 0.0, (0.25, 0.45, 0.15, 1)), mat(2, 0.55, 0.0, (1, 1, 1, 1), alpha=True)],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}, {"source": 2, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": "checker.png"}, {"uri": "stripes.png"}, {"uri": "leaf.png"}],
        "buffers": [{"uri": "foliage.bin", "byteLength": len(blob)}],
        "bufferViews": views, "accessors": accessors,
    }
    with open(os.path.join(out, "foliage.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)

    scene = {
        "meshes": [{"file": "foliage.gltf"}],
        "camera": {"eye": [2.9, 2.4, 3.7], "target": [0.15, 1.0, 0.1], "up": [0, 1, 0], "fov_y": 45,
                   "width": 640, "height": 400},
        "lights": [
            {"shape": "rect", "corner": [-1.6, 3.6, -0.9], "edge_s": [1.0, 0, 0], "edge_t": [0, 0, 1.0], "power": 260},
            {"shape": "disk", "center": [2.8, 3.4, -1.2], "normal": [-0.45, -1, 0.3], "radius": 0.35,
             "power": [120, 95, 70]},
            {"shape": "sphere", "center": [0.9, 2.6, 2.0], "radius": 0.15, "power": [40, 50, 90]},
        ],
        "render": {"samples": 1024},
    }
    with open(os.path.join(out, "foliage.json"), "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    main()
