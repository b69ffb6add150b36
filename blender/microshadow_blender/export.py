"""The scene as the add-on hands it to microshadow, written for the command line: scene.json (camera, lights in
radiance, render samples, which objects are baked) and one glTF binary per object (its world-space triangles
with their split normals, the baked UV map as TEXCOORD_0, its materials' base colour, metallic and roughness).

Exact: the floats are the add-on's own (float32 buffers), the triangles in the add-on's order (one primitive
per material, as the add-on orders them), the UVs in glTF's convention as the add-on hands them over. Each
file is Y-up as glTF asks, through a root node whose matrix only swaps and negates axes, and scene.json turns
it back into Blender's Z-up frame the same way, so the command line reads the very coordinates the add-on
bakes from: `microshadow bake scene.json --uv 0` gives the add-on's lightmap texel for texel
(tests/blender/test_addon.py), and its `--gltf` output carries the lightmap to an engine.
"""
import json
import os
import re
import struct

import bpy
import numpy as np

from . import library, properties, scene_from_blender

# column-major, as glTF and the scene file's "matrix" take it: Blender's Z-up to glTF's Y-up, (x, y, z) ->
# (x, z, -y), and back, (x, y, z) -> (x, -z, y); entries 0 and +-1 only, so both are exact in floats
Z_UP_TO_Y_UP = [1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1]
Y_UP_TO_Z_UP = [1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1]
NO_MATERIAL = 0xFFFFFFFF


def _safe(name):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)[:60] or "object"


def glb(name, tri, nor, uv, tmat, materials):
    """One object as a glTF binary: tri, nor (n, 3, 3), uv (n, 3, 2) or None, tmat (n,) material of each
    triangle (runs of one material become one primitive each, in order)."""
    chunks, views, accessors, prims, used = [], [], [], [], {}

    def add(arr, kind, minmax=False):
        a = np.ascontiguousarray(arr, np.float32)
        off = sum(len(c) for c in chunks)
        chunks.append(a.tobytes())
        views.append({"buffer": 0, "byteOffset": off, "byteLength": a.nbytes})
        acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": a.shape[0], "type": kind}
        if minmax:
            acc["min"], acc["max"] = [float(x) for x in a.min(0)], [float(x) for x in a.max(0)]
        accessors.append(acc)
        return len(accessors) - 1

    cuts = [0] + [i for i in range(1, len(tmat)) if tmat[i] != tmat[i - 1]] + [len(tmat)]
    for a, b in zip(cuts, cuts[1:]):
        attrs = {"POSITION": add(tri[a:b].reshape(-1, 3), "VEC3", True), "NORMAL": add(nor[a:b].reshape(-1, 3), "VEC3")}
        if uv is not None:
            attrs["TEXCOORD_0"] = add(uv[a:b].reshape(-1, 2), "VEC2")
        prim = {"attributes": attrs, "mode": 4}
        m = int(tmat[a])
        if m != NO_MATERIAL:
            prim["material"] = used.setdefault(m, len(used))
        prims.append(prim)
    mats = [None] * len(used)
    for m, k in used.items():
        d = materials[m]
        mats[k] = {"name": d.get("name", "m%d" % m), "pbrMetallicRoughness": {
            "baseColorFactor": [float(x) for x in d["base_color"]], "metallicFactor": float(d["metallic"]),
            "roughnessFactor": float(d["roughness"])}}
    doc = {"asset": {"version": "2.0", "generator": "microshadow Blender add-on"}, "scene": 0,
           "scenes": [{"nodes": [0]}],
           "nodes": [{"name": "Z-up to Y-up", "matrix": Z_UP_TO_Y_UP, "children": [1]}, {"name": name, "mesh": 0}],
           "meshes": [{"name": name, "primitives": prims}], "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": sum(len(c) for c in chunks)}]}
    if mats:
        doc["materials"] = mats
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary = b"".join(chunks)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(js) + 8 + len(binary)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(js), b"JSON") + js +
            struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def write(collected, folder, samples=256):
    """Writes collected (scene_from_blender.Collected) into folder; returns the scene file's path."""
    a = collected.arrays
    os.makedirs(os.path.join(folder, "objects"), exist_ok=True)
    mats = a["materials"] or []
    names = {i: m for i, m in enumerate(mats)}
    tri, nor, uv = a["triangles"], a["normals"], a["uvs"][0]
    tmat = a["triangle_materials"]
    meshes, used = [], set()
    for k, o in enumerate(collected.objects):
        name = _safe(o.name)
        while name in used:
            name += "_"
        used.add(name)
        rel = "objects/%s.glb" % name
        sl = slice(o.first, o.first + o.count)
        u = uv[sl]
        m = tmat[sl] if tmat is not None else np.full(o.count, NO_MATERIAL, np.uint32)
        with open(os.path.join(folder, rel), "wb") as f:
            f.write(glb(o.name, tri[sl], nor[sl], u if np.isfinite(u).all() else None, m,
                        [dict(v, name=collected.material_names[i]) for i, v in names.items()]))
        entry = {"file": rel, "transform": {"matrix": Y_UP_TO_Z_UP}}
        scale = a.get("lightmap_scale")
        if scale is not None and not scale[k] > 0:
            entry["lightmap"] = False
        meshes.append(entry)
    lights = []
    for L in a["lights"]:
        d = {k: (list(v) if isinstance(v, tuple) else v) for k, v in L.items()}
        if "vertices" in d:
            d["vertices"] = [list(p) for p in d["vertices"]]
        lights.append(d)
    # the lights are the scene file's (an emissive mesh's triangles among them): none from the files' materials
    doc = {"meshes": meshes, "lights": lights, "lights_from_emissive": False, "lights_from_punctual": False,
           "render": {"samples": int(samples)}}
    if "camera" in a:
        doc["camera"] = a["camera"]
    path = os.path.join(folder, "scene.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return path


class MICROSHADOW_OT_export_scene(bpy.types.Operator):
    """Write the scene as microshadow sees it (scene.json and a glTF file per object) for the command line"""
    bl_idname = "microshadow.export_scene"
    bl_label = "Export microshadow Scene"
    directory: bpy.props.StringProperty(subtype="DIR_PATH")
    selected_receivers: bpy.props.BoolProperty(name="Selected objects baked", default=True,
                                               description="Mark only the selected objects as baked")

    def execute(self, context):
        scene = context.scene
        try:
            r = scene.render
            recv = {o.name for o in context.selected_objects} if self.selected_receivers else None
            prefs = properties.preferences(context)
            ms = library.module(prefs.library if prefs else "")
            got = scene_from_blender.collect(
                context.evaluated_depsgraph_get(), ms, uv_map=scene.microshadow.bake_uv_map, receivers=recv,
                camera=scene.camera, width=int(r.resolution_x * r.resolution_percentage / 100),
                height=int(r.resolution_y * r.resolution_percentage / 100), skip_hidden_render=True)
            path = write(got, bpy.path.abspath(self.directory), int(scene.microshadow.samples))
        except Exception as e:
            self.report({"ERROR"}, str(e).splitlines()[0] if str(e) else type(e).__name__)
            return {"CANCELLED"}
        for w in got.warnings:
            self.report({"WARNING"}, w)
        self.report({"INFO"}, "microshadow: wrote %s" % path)
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}
