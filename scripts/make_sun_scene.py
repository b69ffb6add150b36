#!/usr/bin/env python3
"""Writes the sun-lit outdoor scene of docs/lights.md ("The sun") into a directory:

    scripts/make_sun_scene.py OUTDIR     # then: microshadow OUTDIR/sun.json -o sun.png

A ground of 60 x 60 with four square poles 0.3 wide and 2, 5, 9 and 14 high, a rail 0.15 thick on two
posts at height 6, and a plank leaning from the ground up to height 10, lit by the sun (angular diameter
0.53 degrees, 40 degrees above the horizon): the shadows' penumbra widens with the height of what casts
them, d tan(0.53 deg) at distance d from it (0.1 at the 14-high pole's tip). An orthographic view from
above. Also OUTDIR/sun_rect.json: the same scene lit by a rect light instead (the sun's direction, at 40
units, a square of the sun's solid angle), to compare the cost of a sun with a rect on the same scene (docs/lights.md).
Everything is generated: the repository holds this script, not the mesh. Standard library only."""
import json
import math
import os
import sys


def box(verts, faces, lo, hi):
    """A closed box lo..hi, counter-clockwise seen from outside."""
    b = len(verts)
    for i in range(8):
        verts.append(tuple(hi[a] if (i >> a) & 1 else lo[a] for a in range(3)))
    for q in ((0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)):
        faces.append(tuple(b + i for i in q))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_sun_scene.py OUTDIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    v, f = [], []
    v += [(-30, 0, -30), (-30, 0, 30), (30, 0, 30), (30, 0, -30)]
    f.append((0, 1, 2, 3))
    for x, h in ((-9, 2), (-4, 5), (1, 9), (6, 14)):
        box(v, f, (x - 0.15, 0, -0.15), (x + 0.15, h, 0.15))
    box(v, f, (-9.1, 0, 6.9), (-8.9, 6, 7.1))
    box(v, f, (2.9, 0, 6.9), (3.1, 6, 7.1))
    box(v, f, (-9.1, 5.85, 6.925), (3.1, 6.0, 7.075))
    # the plank: 1 wide, from (10, 0, 4) up to (10, 10, 10), 0.1 thick
    b = len(v)
    for (y, z) in ((0.0, 4.0), (10.0, 10.0)):
        for dx in (-0.5, 0.5):
            for dn in (0.0, 0.1):
                n = (0.0, -6.0, 10.0)
                ln = math.hypot(n[1], n[2])
                v.append((10 + dx, y + dn * n[1] / ln, z + dn * n[2] / ln))
    # corners: b + 4 i + 2 j + k: i along the plank, j across, k through
    for q in ((0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)):
        f.append(tuple(b + i for i in q))
    with open(os.path.join(out, "sun.obj"), "w") as o:
        for p in v:
            o.write("v %.6g %.6g %.6g\n" % p)
        for q in f:
            o.write("f " + " ".join(str(i + 1) for i in q) + "\n")
    el, az = math.radians(40.0), math.radians(200.0)
    d = [math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az)]
    camera = {"type": "orthographic", "eye": [7.5, 40, 4], "target": [7.5, 0, 4], "up": [0, 0, -1],
              "ortho_height": 17, "width": 1024, "height": 512}
    scene = {"meshes": [{"file": "sun.obj"}], "camera": camera,
             "light": {"shape": "sun", "direction": [round(c, 6) for c in d], "angular_diameter_deg": 0.53,
                       "lumens": 100000},
             "render": {"samples": 1024, "aa": 4}}
    with open(os.path.join(out, "sun.json"), "w") as o:
        json.dump(scene, o, indent=1)
    # a close-up of the 14-high pole's shadow: its base (left) and its tip (right), 2 x 1 each, side by side in
    # one view would not fit; two views of the same size instead
    tip = [6 + 14 / math.tan(el) * -d[0] / math.hypot(d[0], d[2]), 14 / math.tan(el) * -d[2] / math.hypot(d[0], d[2])]
    for name, (x, z) in (("sun_base.json", (6.6, 0.25)), ("sun_tip.json", (tip[0] - 0.6, tip[1]))):
        zoom = dict(scene, camera=dict(camera, eye=[x, 40, z], target=[x, 0, z], ortho_height=1.0, width=512,
                                       height=256))
        with open(os.path.join(out, name), "w") as o:
            json.dump(zoom, o, indent=1)
    # the rect: at 40 units along the sun's direction, facing the scene, a square of the sun's solid angle
    # (side 40 tan(alpha) sqrt(pi) = 0.33): the same penumbrae to first order
    c = [40 * x for x in d]
    half = 0.5 * 40 * math.tan(math.radians(0.265)) * math.sqrt(math.pi)
    e1 = [-d[2], 0.0, d[0]]
    l1 = math.sqrt(sum(x * x for x in e1))
    e1 = [x / l1 for x in e1]
    e2 = [d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2], d[0] * e1[1] - d[1] * e1[0]]
    # cross(edge_s, edge_t) must point back at the scene (-d): edge_s = e2, edge_t = e1 gives -d
    rect = {"corner": [round(c[a] - half * (e1[a] + e2[a]), 6) for a in range(3)],
            "edge_s": [round(2 * half * e2[a], 6) for a in range(3)],
            "edge_t": [round(2 * half * e1[a], 6) for a in range(3)], "emission": 1000}
    scene["light"] = rect
    with open(os.path.join(out, "sun_rect.json"), "w") as o:
        json.dump(scene, o, indent=1)


if __name__ == "__main__":
    main()
