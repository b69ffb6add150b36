"""microshadow's Blender add-on against Cycles on a glTF asset opened in Blender, both sides in one run:

    blender -b --factory-startup --python bench/blender/vs_cycles.py -- ASSET.gltf OUT_DIR [THREADS]

The asset is imported with Blender's glTF importer and set on a ground under one rectangular area light; every
material is replaced by one white diffuse material on both sides (the comparison is of light and shadow, not
of the materials each engine reads). Direct light only (Cycles: max bounces 0, no denoising, its default
pixel filter; microshadow: diffuse shading, 4 primary samples per pixel).

Frame: microshadow at 256 and 1024 light samples, Cycles at 16, 64, 256 and 1024 samples per pixel, each
against its own converged image (microshadow 4096 light samples; Cycles 4096 samples per pixel): the error is
the RMS difference over the mean of the reference. The speed-up at equal error takes the Cycles time at the
sample count whose error equals microshadow's (Monte Carlo error falling as 1 / sqrt(samples) between the
measured counts).

Bake of the ground (its own UVs; the helmet's shadow on it): microshadow's bake at 256 and 1024 light samples
against Cycles' bake of Diffuse Direct (lighting only) at 16, 64, 256 and 1024 samples, errors against the
4096-sample bakes on each side, over the texels both bake. Writes OUT_DIR/vs_cycles.json and prints a table.
"""
import json
import math
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "blender")))
import microshadow_blender as addon  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:]
ASSET, OUT = ARGS[0], ARGS[1]
THREADS = int(ARGS[2]) if len(ARGS) > 2 else 2
W, H, BAKE = 480, 270, 512
os.makedirs(OUT, exist_ok=True)


def setup():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    if not hasattr(np, "bool"):  # Debian's Blender 3.4 glTF importer uses np.bool, which numpy 1.24 removed
        np.bool = bool
    bpy.ops.import_scene.gltf(filepath=ASSET)
    asset = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    lo = np.min([np.array(o.matrix_world) @ np.append(np.array(c), 1) for o in asset for c in o.bound_box], 0)[:3]
    hi = np.max([np.array(o.matrix_world) @ np.append(np.array(c), 1) for o in asset for c in o.bound_box], 0)[:3]
    size = float(np.max(hi - lo))
    centre = (lo + hi) / 2
    bpy.ops.mesh.primitive_plane_add(size=3 * size, location=(centre[0], centre[1], lo[2]))
    ground = bpy.context.active_object
    ground.name = "ground"
    white = bpy.data.materials.new("white")
    white.use_nodes = True
    nt = white.node_tree
    nt.nodes.clear()
    d, o = nt.nodes.new("ShaderNodeBsdfDiffuse"), nt.nodes.new("ShaderNodeOutputMaterial")
    d.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    nt.links.new(d.outputs[0], o.inputs[0])
    for ob in asset + [ground]:
        ob.data.materials.clear()
        ob.data.materials.append(white)
    ld = bpy.data.lights.new("key", "AREA")
    ld.shape, ld.size, ld.size_y, ld.energy = "RECTANGLE", 0.5 * size, 0.3 * size, 40.0 * size * size
    light = bpy.data.objects.new("key", ld)
    bpy.context.scene.collection.objects.link(light)
    light.location = (centre[0] + 0.6 * size, centre[1] - 0.4 * size, hi[2] + 0.8 * size)
    light.rotation_euler = (0.5, 0.35, 0.0)
    cam = bpy.data.cameras.new("cam")
    cam.lens = 35
    camob = bpy.data.objects.new("cam", cam)
    bpy.context.scene.collection.objects.link(camob)
    camob.location = (centre[0] + 1.3 * size, centre[1] - 1.6 * size, centre[2] + 0.9 * size)
    direction = centre - np.array(camob.location)
    camob.rotation_euler = (math.atan2(math.hypot(direction[0], direction[1]), -direction[2]), 0.0,
                            math.atan2(direction[1], direction[0]) - math.pi / 2)
    sc = bpy.context.scene
    sc.camera = camob
    sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = W, H, 100
    sc.render.threads_mode, sc.render.threads = "FIXED", THREADS
    sc.world = bpy.data.worlds.new("black")
    sc.world.color = (0, 0, 0)
    sc.cycles.max_bounces, sc.cycles.use_denoising, sc.cycles.use_adaptive_sampling = 0, False, False
    sc.cycles.device = "CPU"
    sc.microshadow.shading, sc.microshadow.aa, sc.microshadow.threads = "diffuse", "4", THREADS
    fmt = sc.render.image_settings
    fmt.file_format, fmt.color_depth, fmt.exr_codec = "OPEN_EXR", "32", "ZIP"
    return ground, sum(len(o.data.polygons) for o in asset)


def frame(engine, samples):
    sc = bpy.context.scene
    sc.render.engine = engine
    if engine == "CYCLES":
        sc.cycles.samples = samples
    else:
        sc.microshadow.samples = str(samples)
    sc.render.filepath = os.path.join(OUT, "frame_%s_%d.exr" % (engine.lower(), samples))
    t = time.time()
    bpy.ops.render.render(write_still=True)
    dt = time.time() - t
    img = bpy.data.images.load(sc.render.filepath, check_existing=False)
    px = np.array(img.pixels[:], np.float64).reshape(H, W, 4)[..., :3]
    bpy.data.images.remove(img)
    return px, dt


def bake_cycles(ground, samples):
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.samples = samples
    img = bpy.data.images.get("cycles_bake") or bpy.data.images.new("cycles_bake", BAKE, BAKE, float_buffer=True)
    mat = ground.data.materials[0].copy()
    ground.data.materials[0] = mat
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = img
    mat.node_tree.nodes.active = node
    for ob in sc.objects:
        ob.select_set(ob == ground)
    bpy.context.view_layer.objects.active = ground
    t = time.time()
    bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT"}, margin=0, use_clear=True)
    dt = time.time() - t
    px = np.array(img.pixels[:], np.float64).reshape(BAKE, BAKE, 4)[..., :3]
    mat.node_tree.nodes.remove(node)
    return px, dt


def bake_microshadow(ground, samples):
    from microshadow_blender import bake
    sc = bpy.context.scene
    sc.microshadow.samples, sc.microshadow.bake_size = str(samples), BAKE
    sc.microshadow.bake_uv_source = "EXISTING"
    for ob in sc.objects:
        ob.select_set(ob == ground)
    bpy.context.view_layer.objects.active = ground
    t = time.time()
    run, got, ms = bake.start(bpy.context)
    run.wait()
    dt = time.time() - t
    if run.error:
        raise run.error
    # the ground alone is baked (the asset occludes): each side is compared with its own 4096-sample bake in
    # its own layout, texel for texel
    return run.result, dt


def rel_rms(a, ref, mask=None):
    d = (a - ref) ** 2
    if mask is not None:
        d, ref = d[mask], ref[mask]
    return float(math.sqrt(d.mean()) / max(ref.mean(), 1e-30))


def equal_error_time(errors, times, target):
    """Cycles' time at the error `target`, from the measured (samples, error, time) with error ~ 1/sqrt(s)."""
    pts = sorted(zip(errors, times), key=lambda p: -p[0])
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e1 <= target <= e0:
            # time ~ samples ~ 1 / error^2 between the two
            return t0 * (e0 / target) ** 2 if t0 > 0 else t1
    e, t = pts[-1] if target < pts[-1][0] else pts[0]
    return t * (e / target) ** 2


def main():
    addon.register()
    ground, tris = setup()
    res = {"asset": os.path.basename(ASSET), "triangles": tris, "size": [W, H], "threads": THREADS}
    # frames
    ms_ref, _ = frame("MICROSHADOW", 4096)
    cy_ref, cy_ref_t = frame("CYCLES", 4096)
    res["frame"] = {"microshadow": {}, "cycles": {}, "cycles_4096_s": cy_ref_t}
    for s in (256, 1024):
        px, dt = frame("MICROSHADOW", s)
        res["frame"]["microshadow"][s] = {"s": dt, "error": rel_rms(px, ms_ref)}
    for s in (16, 64, 256, 1024):
        px, dt = frame("CYCLES", s)
        res["frame"]["cycles"][s] = {"s": dt, "error": rel_rms(px, cy_ref)}
    cy = res["frame"]["cycles"]
    for s, m in res["frame"]["microshadow"].items():
        tc = equal_error_time([cy[k]["error"] for k in cy], [cy[k]["s"] for k in cy], max(m["error"], 1e-6))
        m["cycles_s_at_equal_error"], m["speedup"] = tc, tc / m["s"]
    # bakes of the ground
    cb_ref, cb_ref_t = bake_cycles(ground, 4096)
    lm_ref, _ = bake_microshadow(ground, 4096)
    res["bake"] = {"microshadow": {}, "cycles": {}, "cycles_4096_s": cb_ref_t}
    baked = lm_ref["triangle"] != 0xFFFFFFFF
    for s in (256, 1024):
        lm, dt = bake_microshadow(ground, s)
        res["bake"]["microshadow"][s] = {"s": dt, "error": rel_rms(lm["irradiance"], lm_ref["irradiance"], baked)}
    cmask = cb_ref.sum(-1) > 0
    for s in (16, 64, 256, 1024):
        px, dt = bake_cycles(ground, s)
        res["bake"]["cycles"][s] = {"s": dt, "error": rel_rms(px, cb_ref, cmask)}
    cb = res["bake"]["cycles"]
    for s, m in res["bake"]["microshadow"].items():
        tc = equal_error_time([cb[k]["error"] for k in cb], [cb[k]["s"] for k in cb], max(m["error"], 1e-6))
        m["cycles_s_at_equal_error"], m["speedup"] = tc, tc / m["s"]
    with open(os.path.join(OUT, "vs_cycles.json"), "w") as f:
        json.dump(res, f, indent=1)
    for what in ("frame", "bake"):
        print("%s (%s, %d triangles, %d threads)" % (what, res["asset"], tris, THREADS))
        for eng in ("microshadow", "cycles"):
            for s, m in res[what][eng].items():
                extra = ", Cycles at equal error %.1f s: %.0fx" % (m["cycles_s_at_equal_error"], m["speedup"]) \
                    if eng == "microshadow" else ""
                print("  %-11s %5d samples: %7.2f s, error %.4f%s" % (eng, s, m["s"], m["error"], extra))


main()
