#!/usr/bin/python3
"""Generates the dense-mesh benchmark scenes (issue 29): public scanned statues and a game model on a
ground plane, a GRIDS-like scene of thin bars (after the hierarchical penumbra casting paper's GRIDS) and
a 72K-triangle foliage scene, each as OUT/NAME/NAME.json with its meshes beside it; and an architectural
interior with a big light (Dabrovic's Sponza from the shared scenes, --shared DIR, default ../shared/scenes
beside the repository, referred to in place).

    scripts/make_dense_scenes.py OUT [--assets DIR] [--shared DIR]

The meshes are not part of the repository: DIR holds them as fetched from public repositories: the collection
of common 3D test models (github alecjacobson/common-3d-test-models, data/): nefertiti.obj, ogre.obj,
beast.obj, igea.ply, horse.ply (from horse.zip) and stanford-bunny.obj; dragon.obj (100K triangles) from
github LukeMcCulloch/meshes; buddha.obj, bird.obj and tree_aspen.obj from github nshoang0808/CS373;
armadillo.obj (50K triangles) from github rohan-sawhney/mesh-saliency. Missing ones are skipped with a
message; the generated scenes (grids, foliage) need nothing. Each mesh is rewritten as a Y-up OBJ standing on y = 0 (its own
reader here, so the benchmark does not depend on the loader it measures), with a ground quad four times
its footprint, a pinhole camera at a three-quarter view and a rect light of a third of its height
above and to the side: a penumbra on the ground and self-shadowing on the statue.
"""
import json
import os
import struct
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# name: (file, up axis of the file (0 x, 1 y, 2 z), sign of up, what it is)
ASSETS = {
    "nefertiti": ("nefertiti.obj", 2, 1, "scanned bust, 100K triangles"),
    "horse": ("horse.ply", 2, 1, "scanned statue, 97K triangles"),
    "ogre": ("ogre.obj", 1, 1, "game character, 124K triangles"),
    "igea": ("igea.ply", 1, 1, "scanned head, 269K triangles in triangle strips"),
    "beast": ("beast.obj", 1, 1, "game model, 32K quads (65K triangles)"),
    "bunny": ("stanford-bunny.obj", 1, 1, "scanned statue, 69K triangles"),
    "dragon": ("dragon.obj", 1, 1, "scanned statue, 100K triangles"),
    "buddha": ("buddha.obj", 1, 1, "scanned statue, 113K triangles"),
    "armadillo": ("armadillo.obj", 1, 1, "scanned statue, 50K triangles"),
    "bird": ("bird.obj", 2, 1, "game model, 61K triangles"),
    "aspen": ("tree_aspen.obj", 1, 1, "tree with leaf cards, open surfaces"),
}


def read_obj(path):
    verts, faces = [], []
    with open(path, "r", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                idx = []
                for tok in line.split()[1:]:
                    i = int(tok.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                for k in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
    return np.array(verts, np.float64), np.array(faces, np.int64)


PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
             "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
             "double": "d", "float64": "d"}


def read_ply(path):
    """Binary little-endian PLY: vertex x, y, z (other properties skipped), faces (fans) or tristrips
    (-1 restarts a strip; every other triangle of a strip is flipped to keep the winding)."""
    data = open(path, "rb").read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        raise ValueError(path + ": only binary little-endian PLY is read here")
    elements = []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    pos = end
    verts, faces = None, []
    for name, count, props in elements:
        if name == "vertex":
            fmt = "<" + "".join(PLY_TYPES[p[0]] for p in props)
            size = struct.calcsize(fmt)
            names = [p[-1] for p in props]
            ix, iy, iz = names.index("x"), names.index("y"), names.index("z")
            rows = np.frombuffer(data, np.dtype([(n, fmt[1 + k]) for k, n in enumerate(names)]), count, pos)
            verts = np.stack([rows[names[ix]], rows[names[iy]], rows[names[iz]]], 1).astype(np.float64)
            pos += size * count
        elif name in ("face", "tristrips"):
            (kind, ctype, itype, _), = props
            cf, it = "<" + PLY_TYPES[ctype], "<" + PLY_TYPES[itype]
            cs, isz = struct.calcsize(cf), struct.calcsize(it)
            for _ in range(count):
                (n,) = struct.unpack_from(cf, data, pos)
                pos += cs
                idx = np.frombuffer(data, np.dtype(it), n, pos).astype(np.int64)
                pos += n * isz
                if name == "face":
                    for k in range(1, n - 1):
                        faces.append((idx[0], idx[k], idx[k + 1]))
                else:
                    strip = []
                    for i in list(idx) + [-1]:
                        if i < 0:
                            for k in range(len(strip) - 2):
                                a, b, c = strip[k], strip[k + 1], strip[k + 2]
                                if a != b and b != c and a != c:
                                    faces.append((a, b, c) if k % 2 == 0 else (b, a, c))
                            strip = []
                        else:
                            strip.append(i)
        else:
            raise ValueError(path + ": element " + name + " is not read here")
    return verts, np.array(faces, np.int64)


def write_obj(path, verts, faces):
    with open(path, "w") as f:
        f.write("".join("v %.7g %.7g %.7g\n" % tuple(v) for v in verts))
        f.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in faces))


def y_up(verts, axis, sign):
    """Rotates so that the file's up axis becomes +y (a proper rotation: the winding is kept)."""
    x, y, z = verts[:, 0], verts[:, 1], verts[:, 2]
    if axis == 1:
        return verts if sign > 0 else np.stack([x, -y, -z], 1)
    if axis == 2:
        return np.stack([x, z, -y], 1) if sign > 0 else np.stack([x, -z, y], 1)
    return np.stack([-y, x, z], 1) if sign > 0 else np.stack([y, -x, z], 1)


def scene_json(meshes, lo, hi, light_scale=1.0 / 3.0, samples=1024):
    """Camera at a three-quarter view of the box [lo, hi] (y up, standing on y = lo[1]); a square rect
    light above and to the side, facing down, of side light_scale times the box's height."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = (lo + hi) / 2
    size = hi - lo
    h = size[1]
    r = float(np.linalg.norm(size)) / 2
    eye = c + np.array([0.9, 0.55, 1.3]) / np.linalg.norm([0.9, 0.55, 1.3]) * r * 2.6
    side = h * light_scale
    lc = c + np.array([-0.7 * r, 1.6 * h, 0.3 * r])
    corner = lc - np.array([side / 2, 0, side / 2])
    f = lambda v: [round(float(x), 6) for x in v]  # noqa: E731
    return {"meshes": [{"file": m} for m in meshes],
            "camera": {"eye": f(eye), "target": f(c), "up": [0, 1, 0], "fov_y": 40, "width": 1024, "height": 1024},
            "light": {"corner": f(corner), "edge_s": [round(side, 6), 0, 0], "edge_t": [0, 0, round(side, 6)]},
            "render": {"samples": samples}}


def ground(path, lo, hi, margin=1.5):
    c = (np.asarray(lo) + np.asarray(hi)) / 2
    e = max(hi[0] - lo[0], hi[2] - lo[2]) * margin + 1e-3
    y = lo[1]
    v = [[c[0] - e, y, c[2] - e], [c[0] + e, y, c[2] - e], [c[0] + e, y, c[2] + e], [c[0] - e, y, c[2] + e]]
    write_obj(path, np.array(v), np.array([[0, 2, 1], [0, 3, 2]]))


def write_scene(out, name, meshes, lo, hi, **kw):
    d = os.path.join(out, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name + ".json"), "w") as f:
        json.dump(scene_json(meshes, lo, hi, **kw), f, indent=1)
    return d


def make_asset(out, assets, name):
    fname, axis, sign, what = ASSETS[name]
    src = os.path.join(assets, fname)
    if not os.path.exists(src):
        print("skipped %s: %s not found (fetch it from the common 3D test models collection)" % (name, src))
        return
    verts, faces = read_ply(src) if fname.endswith(".ply") else read_obj(src)
    verts = y_up(verts, axis, sign)
    verts[:, 1] -= verts[:, 1].min()
    lo, hi = verts.min(0), verts.max(0)
    d = write_scene(out, name, [name + ".obj", "ground.obj"], lo, hi)
    write_obj(os.path.join(d, name + ".obj"), verts, faces)
    ground(os.path.join(d, "ground.obj"), lo, hi)
    print("%s: %d triangles (%s) + ground" % (name, len(faces), what))


def box(verts, faces, lo, hi):
    """An axis-aligned box, outward-facing, closed (12 triangles)."""
    b = len(verts)
    for i in range(8):
        verts.append([hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]])
    for q in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
        faces.append((b + q[0], b + q[1], b + q[2]))
        faces.append((b + q[0], b + q[2], b + q[3]))


def bar(verts, faces, axis, u, y, t, span, segments):
    """A closed square tube of side 2t along x (axis 0) or z (axis 2) at offset u, height y, cut into
    segments along its length (so a bar is many triangles, as in the paper's GRIDS), with its end caps;
    outward-facing, every edge shared by two triangles."""
    b = len(verts)
    ring = [(-t, -t), (t, -t), (t, t), (-t, t)]   # (across, up) around the tube
    for k in range(segments + 1):
        along = -span / 2 + span * k / segments
        for a, h in ring:
            verts.append([along, y + h, u + a] if axis == 0 else [u + a, y + h, along])
    for k in range(segments):
        for j in range(4):
            p0, p1 = b + 4 * k + j, b + 4 * k + (j + 1) % 4
            q0, q1 = p0 + 4, p1 + 4
            faces.append((p0, q0, q1) if axis == 0 else (p0, q1, q0))
            faces.append((p0, q1, p1) if axis == 0 else (p0, p1, q1))
    for base, flip in ((b, axis != 0), (b + 4 * segments, axis == 0)):
        q = [base, base + 1, base + 2, base + 3]
        faces.extend([(q[0], q[2], q[1]), (q[0], q[3], q[2])] if flip else [(q[0], q[1], q[2]), (q[0], q[2], q[3])])


def make_grids(out, n=96, segments=32):
    """GRIDS-like (Laine and Aila 2005: "relatively few triangles, but the penumbra regions are very
    large"; theirs has 73K): three layers of n thin bars, crossing at right angles, over a ground plane
    under a large light; each bar a closed tube of 4 * 2 * segments + 4 triangles."""
    verts, faces = [], []
    span, t = 10.0, 0.015
    for layer, y in enumerate((1.0, 1.5, 2.0)):
        for i in range(n):
            bar(verts, faces, layer % 2 * 2, -span / 2 + (i + 0.5) * span / n, y, t, span, segments)
    lo, hi = np.array([-span / 2, 0, -span / 2]), np.array([span / 2, 2.0, span / 2])
    d = write_scene(out, "grids", ["grids.obj", "ground.obj"], lo, hi)
    # seen from above, under a 3 x 3 light 2.5 above the top layer: penumbrae far wider than the bars'
    # spacing, so most of the ground is in penumbra
    with open(os.path.join(d, "grids.json"), "w") as f:
        json.dump({"meshes": [{"file": "grids.obj"}, {"file": "ground.obj"}],
                   "camera": {"eye": [2.5, 8.5, 7.0], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 45,
                              "width": 1024, "height": 1024},
                   "light": {"corner": [-1.5, 4.5, -1.5], "edge_s": [3, 0, 0], "edge_t": [0, 0, 3]},
                   "render": {"samples": 1024}}, f, indent=1)
    write_obj(os.path.join(d, "grids.obj"), np.array(verts), np.array(faces))
    ground(os.path.join(d, "ground.obj"), lo, hi, margin=0.8)
    print("grids: %d triangles (3 x %d thin bars) + ground" % (len(faces), n))


def make_foliage(out, triangles=72000):
    """Foliage: the procedural FLOWERS generator (the hierarchical penumbra casting paper's scene) at 72K
    triangles: a ground and plants of small leaf triangles, materialised by every method but hpc."""
    d = os.path.join(out, "foliage")
    os.makedirs(d, exist_ok=True)
    # Plants stand in [-16, 16]^2, 0.8 to 2.5 high (src/scene/procedural.c); the camera frames the middle
    # of the field, a 3 x 3 light hangs 8 above it.
    s = {"procedural": {"type": "flowers", "triangles": triangles, "seed": 1},
         "camera": {"eye": [0, 6, 8], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 50, "width": 1024,
                    "height": 1024},
         "light": {"corner": [-1.5, 8, -1.5], "edge_s": [3, 0, 0], "edge_t": [0, 0, 3]},
         "render": {"samples": 1024}}
    with open(os.path.join(d, "foliage.json"), "w") as f:
        json.dump(s, f, indent=1)
    print("foliage: %d procedural triangles" % triangles)


def make_interior(out, shared):
    """An architectural interior with a big light: Dabrovic's Sponza (66K triangles) from the shared scenes
    with the scene file's own big-light set-up (a 6 x 6 light under the roof: nearly every visible pixel in
    penumbra). The mesh is referred to where it lies, not copied."""
    src = os.path.join(shared, "dabrovic-sponza", "dabrovic-sponza-biglight.json")
    if not os.path.exists(src):
        print("interior: %s not found, skipped" % src)
        return
    with open(src) as f:
        s = json.load(f)
    for m in s["meshes"]:
        m["file"] = os.path.abspath(os.path.join(os.path.dirname(src), m["file"]))
    d = os.path.join(out, "sponza-biglight")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "sponza-biglight.json"), "w") as f:
        json.dump(s, f, indent=1)
    print("interior: Dabrovic's Sponza with its big light (%s)" % os.path.normpath(src))


def main(argv):
    if len(argv) < 2 or argv[1].startswith("-"):
        print(__doc__)
        return 2
    out = argv[1]
    assets = argv[argv.index("--assets") + 1] if "--assets" in argv else os.path.join(os.path.dirname(out), "assets")
    for name in ASSETS:
        make_asset(out, assets, name)
    make_grids(out)
    make_foliage(out)
    make_interior(out, argv[argv.index("--shared") + 1] if "--shared" in argv else os.path.join(ROOT, "..", "shared", "scenes"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
