#!/usr/bin/env python3
"""Scenes far from the origin (issue 33): translate a scene and its meshes by (d, d/2, -d) and time every
method on it, by one or two microshadow binaries.

  scripts/far_origin.py translate SCENE.json D OUT_DIR
      writes OUT_DIR/<name>.json: OBJ meshes rewritten with their `v` lines moved by (d, d/2, -d) in double
      and printed with full digits (repr: the shortest text that reads back as the same double), other
      meshes given a `transform.translate` (composed with their own); the camera's eye and target, the
      lights' corners and centres moved alike. d = 0 goes through the same rewriting.

  scripts/far_origin.py bench SCENE.json [--offsets 0,1e4,1e5,1e6] [--bin NAME=PATH ...] [--methods ...]
      [--size 128] [--samples 256] [--threads 2] [--timeout 120] [--repeat 1] [--work DIR]
      renders each method at each offset by each binary (interleaved: every binary's run of a method and
      offset follows the other's, so that load on a shared machine falls on both alike), and prints a
      Markdown table of shadow seconds (the --stats shadow_s; '> T s' when stopped by the timeout) and the
      pixels whose V differs from the same binary's offset-0 image (and from raytrace's at that offset).
      The translated scenes go to --work (default: a temporary folder); nothing is written to the repo.
"""
import argparse, json, os, shutil, struct, subprocess, sys, tempfile

METHODS = ["scanline", "bounds", "hierarchical", "raytrace", "mft", "hpc", "hpc-scanline", "embree"]


def shift(d):
    return (d, d / 2.0, -d)


def translate_obj(src, dst, off):
    with open(src, "r", errors="surrogateescape") as f, open(dst, "w", errors="surrogateescape") as g:
        for line in f:
            t = line.split()
            if t and t[0] == "v" and len(t) >= 4:
                w = float(t[4]) if len(t) in (5, 8) else 1.0   # homogeneous: x/w moved; colours (ignored) dropped
                xyz = [float(t[1 + i]) / w + off[i] for i in range(3)]
                g.write("v %r %r %r\n" % (xyz[0], xyz[1], xyz[2]))
            else:
                g.write(line)


def move(p, off):
    return [float(p[i]) + off[i] for i in range(3)]


def translate(scene_path, d, out_dir):
    off = shift(d)
    os.makedirs(out_dir, exist_ok=True)
    with open(scene_path) as f:
        sc = json.load(f)
    base = os.path.dirname(os.path.abspath(scene_path))
    name = os.path.splitext(os.path.basename(scene_path))[0]
    for i, m in enumerate(sc.get("meshes", [])):
        src = m["file"] if os.path.isabs(m["file"]) else os.path.join(base, m["file"])
        if src.lower().endswith(".obj") and "transform" not in m:
            dst = os.path.join(out_dir, "%s.%d.obj" % (name, i))
            translate_obj(src, dst, off)
            m["file"] = os.path.basename(dst)
        else:
            m["file"] = os.path.abspath(src)
            t = m.setdefault("transform", {})
            if "matrix" in t:
                for k in range(3):
                    t["matrix"][12 + k] = float(t["matrix"][12 + k]) + off[k]
            else:
                t["translate"] = move(t.get("translate", [0, 0, 0]), off)
    cam = sc["camera"]
    cam["eye"] = move(cam["eye"], off)
    cam["target"] = move(cam["target"], off)
    lights = sc["lights"] if "lights" in sc else [sc["light"]]
    for l in lights:
        for k in ("corner", "center"):
            if k in l:
                l[k] = move(l[k], off)
        if isinstance(l.get("texture"), str) and not os.path.isabs(l["texture"]):
            l["texture"] = os.path.join(base, l["texture"])
    sc["allow_outside_paths"] = True
    dst = os.path.join(out_dir, name + ".json")
    with open(dst, "w") as f:
        json.dump(sc, f, indent=1)   # json writes repr(float): full digits
    return dst


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = w * h * (3 if kind == b"PF" else 1)
        data = struct.unpack(("<" if scale < 0 else ">") + "%df" % n, f.read(4 * n))
    return data


def differing(a, b, tol=0.0):
    """Pixels whose V or S differ (a, b: (V, S) pairs), as "V/S" counts."""
    if a is None or b is None:
        return None
    nv = sum(1 for x, y in zip(a[0], b[0]) if abs(x - y) > tol)
    ns = sum(1 for x, y in zip(a[1], b[1]) if abs(x - y) > tol)
    return "%d/%d" % (nv, ns)


def bench(args):
    offsets = [float(x) for x in args.offsets.split(",")]
    bins, only = [], {}
    for spec in args.bin or ["new=build/microshadow"]:
        n, _, p = spec.partition("=")
        p, _, at = p.partition("@")   # NAME=PATH@0,1e4: that binary at those offsets only
        bins.append((n, p))
        only[n] = [float(x) for x in at.split(",")] if at else offsets
    methods = args.methods.split(",") if args.methods else METHODS
    work = args.work or tempfile.mkdtemp(prefix="far-origin-")
    scenes = {d: translate(args.scene, d, os.path.join(work, "d%g" % d)) for d in offsets}
    res = {}   # (bin, method, d) -> (seconds list or None, (V, S))
    # Method by method, each repetition running every offset and binary in turn: runs compared with each
    # other are minutes apart at most, so that a load on a shared machine falls on both alike.
    for m in methods:
        for rep in range(args.repeat):
            for d in offsets:
                for bn, bp in bins:
                    if d not in only[bn]:
                        continue
                    out = os.path.join(work, "%s.%s.%g" % (bn, m, d))
                    cmd = [bp, scenes[d], "--method", m, "--width", str(args.size), "--height", str(args.size),
                           "--samples", str(args.samples), "--threads", str(args.threads), "--quiet",
                           "--vis", out + ".vis.pfm", "--shadow", out + ".shadow.pfm", "--stats", out + ".json"]
                    key = (bn, m, d)
                    secs, vis = res.get(key, ([], None))
                    try:
                        r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=args.timeout)
                        if r.returncode:
                            print("FAILED %s %s %g: %s" % (bn, m, d, r.stderr.decode().strip()), file=sys.stderr)
                            secs.append(float("nan"))
                        else:
                            with open(out + ".json") as f:
                                secs.append(json.load(f)["shadow_s"])
                            vis = (read_pfm(out + ".vis.pfm"), read_pfm(out + ".shadow.pfm"))
                    except subprocess.TimeoutExpired:
                        secs.append(None)
                    res[key] = (secs, vis)
                    print("%s %s d=%g: %s" % (bn, m, d, secs[-1]), file=sys.stderr, flush=True)

    def cell(bn, m, d):
        if (bn, m, d) not in res:
            return "-"
        secs, vis = res[(bn, m, d)]
        if any(s is None for s in secs):
            t = "> %g s" % args.timeout
        else:
            t = " / ".join("%.3g" % s for s in secs) + " s"
        if d != offsets[0] and (bn, m, offsets[0]) in res:
            n0 = differing(vis, res[(bn, m, offsets[0])][1])
            t += " (%s)" % ("-" if n0 is None else n0)
        return t

    print("\nShadow seconds (--stats shadow_s), %dx%d, %d samples, %d threads; in brackets: pixels whose V / S differ "
          "from the same binary's image at offset %g.\n" % (args.size, args.size, args.samples, args.threads, offsets[0]))
    for bn, _ in bins:
        print("**%s**\n" % bn)
        print("| d | " + " | ".join(methods) + " |")
        print("|---" * (len(methods) + 1) + "|")
        for d in only[bn]:
            print("| %g | " % d + " | ".join(cell(bn, m, d) for m in methods) + " |")
        if "raytrace" in methods:
            row = []
            for d in only[bn]:
                ref = res[(bn, "raytrace", d)][1]
                row.append("%g: " % d + ", ".join("%s %s" % (m, differing(res[(bn, m, d)][1], ref)) for m in methods
                                                 if m != "raytrace"))
            print("\nPixels whose V / S differ from raytrace's at the same offset: " + "; ".join(row))
        print()
    if not args.work:
        shutil.rmtree(work)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("translate")
    t.add_argument("scene")
    t.add_argument("d", type=float)
    t.add_argument("out_dir")
    b = sub.add_parser("bench")
    b.add_argument("scene")
    b.add_argument("--offsets", default="0,1e4,1e5,1e6")
    b.add_argument("--bin", action="append", help="NAME=PATH (repeatable; default new=build/microshadow)")
    b.add_argument("--methods", default="")
    b.add_argument("--size", type=int, default=128)
    b.add_argument("--samples", type=int, default=256)
    b.add_argument("--threads", type=int, default=2)
    b.add_argument("--timeout", type=float, default=120)
    b.add_argument("--repeat", type=int, default=1)
    b.add_argument("--work", default="")
    a = ap.parse_args()
    if a.cmd == "translate":
        print(translate(a.scene, a.d, a.out_dir))
    else:
        bench(a)


if __name__ == "__main__":
    main()
