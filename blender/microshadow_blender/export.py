"""The scene as the add-on hands it to microshadow, written for the command line: scene.json (camera, lights in
radiance, render samples, which objects are baked) and one OBJ per object (world-space triangles, the baked
UV map as vt, split normals as vn, base colours in an MTL file).

OBJ rather than glTF: its texture coordinates run upwards as Blender's do (glTF's run downwards), and every
float is written with 9 significant digits, so the CLI reads back the very floats the add-on bakes from:
`microshadow bake scene.json --uv 0` gives the add-on's lightmap (tests/blender/test_addon.py).
"""
import json
import os
import re

import bpy
import numpy as np

from . import scene_from_blender


def _safe(name):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)[:60] or "object"


def _f(x):
    return "%.9g" % x


def write(collected, folder, samples=256):
    """Writes collected (scene_from_blender.Collected) into folder; returns the scene file's path."""
    a = collected.arrays
    os.makedirs(os.path.join(folder, "objects"), exist_ok=True)
    mats = a["materials"] or []
    with open(os.path.join(folder, "objects", "materials.mtl"), "w") as f:
        for i, m in enumerate(mats):
            r, g, b = m["base_color"][:3]
            f.write("newmtl m%d\nKd %s %s %s\nPm %s\nPr %s\n\n" % (i, _f(r), _f(g), _f(b), _f(m["metallic"]),
                                                                 _f(m["roughness"])))
    tri, nor, uv = a["triangles"], a["normals"], a["uvs"][0]
    tmat = a["triangle_materials"]
    meshes, used = [], set()
    for k, o in enumerate(collected.objects):
        name = _safe(o.name)
        while name in used:
            name += "_"
        used.add(name)
        rel = "objects/%s.obj" % name
        sl = slice(o.first, o.first + o.count)
        t, n, u = tri[sl].reshape(-1, 3), nor[sl].reshape(-1, 3), uv[sl].reshape(-1, 2)
        has_uv = bool(np.isfinite(u).all())
        lines = ["mtllib materials.mtl"]
        lines += ["v %s %s %s" % (_f(x), _f(y), _f(z)) for x, y, z in t]
        lines += ["vn %s %s %s" % (_f(x), _f(y), _f(z)) for x, y, z in n]
        if has_uv:
            lines += ["vt %s %s" % (_f(x), _f(y)) for x, y in u]
        current = None
        for i in range(o.count):
            m = None if tmat is None else int(tmat[o.first + i])
            if m is not None and m != 0xFFFFFFFF and m != current:
                lines.append("usemtl m%d" % m)
                current = m
            j = 3 * i + 1
            if has_uv:
                lines.append("f %d/%d/%d %d/%d/%d %d/%d/%d" % (j, j, j, j + 1, j + 1, j + 1, j + 2, j + 2, j + 2))
            else:
                lines.append("f %d//%d %d//%d %d//%d" % (j, j, j + 1, j + 1, j + 2, j + 2))
        with open(os.path.join(folder, rel), "w") as f:
            f.write("\n".join(lines) + "\n")
        entry = {"file": rel}
        scale = a.get("lightmap_scale")
        if scale is not None and not scale[k] > 0:
            entry["lightmap"] = False
        meshes.append(entry)
    doc = {"meshes": meshes, "lights": [{k: (list(v) if isinstance(v, tuple) else v) for k, v in L.items()}
                                        for L in a["lights"]], "render": {"samples": int(samples)}}
    for L in doc["lights"]:
        if "vertices" in L:
            L["vertices"] = [list(p) for p in L["vertices"]]
    if "camera" in a:
        doc["camera"] = a["camera"]
    path = os.path.join(folder, "scene.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return path


class MICROSHADOW_OT_export_scene(bpy.types.Operator):
    """Write the scene as microshadow sees it (scene.json and OBJ files) for the command line"""
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
            got = scene_from_blender.collect(
                context.evaluated_depsgraph_get(), uv_map=scene.microshadow.bake_uv_map, receivers=recv,
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
