"""The bake operator: the selected objects' lightmap (irradiance, and each light's shadowmask S) with every
visible mesh as occluder, into float images shown in Blender and written as EXR beside the .blend.

The lightmap's layout is microshadow's (docs/baking.md, "Charts"): each object keeps its UV map's layout in a
region of its own, objects without one are charted by microshadow. The UVs the lightmap was baked into are
written to each baked object as the UV map "microshadow_lightmap", so that the images can be used at once.
Files are written only when the whole bake has succeeded (each to a temporary name first, then renamed):
a cancelled or failed bake leaves no file behind.
"""
import os
import tempfile
import time

import bpy
import numpy as np

from . import job, library, properties, scene_from_blender

LIGHTMAP_UV = scene_from_blender.LIGHTMAP_UV


class Cancelled(Exception):
    pass


def _receivers(context):
    return [ob for ob in context.selected_objects if ob.type in scene_from_blender.GEOMETRY_TYPES]


def lightmap_pack(context, objects, uv_map):
    """Blender's Lightmap Pack of the objects' meshes together into uv_map (made on meshes that lack it), in
    Edit Mode over all of them at once (the active object set to one of them and restored afterwards)."""
    meshes = [ob for ob in objects if ob.type == "MESH"]
    if not meshes:
        return
    for ob in meshes:
        if uv_map not in ob.data.uv_layers:
            ob.data.uv_layers.new(name=uv_map)
        ob.data.uv_layers.active = ob.data.uv_layers[uv_map]
    layer = context.view_layer
    active, selected = layer.objects.active, [ob for ob in layer.objects if ob.select_get()]
    try:
        for ob in selected:
            ob.select_set(False)
        for ob in meshes:
            ob.select_set(True)
        layer.objects.active = meshes[0]
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.uv.lightmap_pack(PREF_CONTEXT="ALL_FACES", PREF_PACK_IN_ONE=True, PREF_NEW_UVLAYER=False)
    finally:
        if context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        for ob in meshes:
            ob.select_set(False)
        for ob in selected:
            ob.select_set(True)
        layer.objects.active = active


def start(context):
    """Collects the scene and starts microshadow's bake on its own thread: (job, collected, ms)."""
    st = context.scene.microshadow
    prefs = properties.preferences(context)
    ms = library.module(prefs.library if prefs else "")
    receivers = _receivers(context)
    if not receivers:
        raise scene_from_blender.SceneError("select the objects to bake (meshes)")
    uv_map = st.bake_uv_map
    if st.bake_uv_source == "LIGHTMAP_PACK":
        uv_map = uv_map or "lightmap"
        lightmap_pack(context, receivers, uv_map)
    depsgraph = context.evaluated_depsgraph_get()
    got = scene_from_blender.collect(depsgraph, ms, uv_map=uv_map, receivers={o.name for o in receivers},
                                     skip_hidden_render=True)
    sc = ms.scene_from_arrays(**got.arrays)
    run = job.Job(ms, ms.bake, scene=sc, size=st.bake_size, uv=None if st.bake_uv_source == "MICROSHADOW" else 0,
                  method=properties.method_value(st.method), samples=int(st.samples), threads=st.threads,
                  padding=st.bake_padding, texel_density=st.bake_texel_density,
                  uv_packing="regions" if st.bake_whole_layouts and st.bake_uv_source != "MICROSHADOW" else "default")
    run.scene = sc
    return run, got, ms


def _image(name, pixels_rgb, size):
    """A float image (replacing one of that name) holding the (size, size, 3) rows of a lightmap page: its row 0
    is the top (glTF's v = 0, microshadow/bake.h), Blender's the bottom."""
    img = bpy.data.images.get(name)
    if img is not None and (img.size[0] != size or img.size[1] != size or not img.is_float):
        bpy.data.images.remove(img)
        img = None
    if img is None:
        img = bpy.data.images.new(name, size, size, alpha=False, float_buffer=True)
    rgba = np.ones((size, size, 4), np.float32)
    rgba[..., :3] = np.nan_to_num(pixels_rgb, nan=0.0)[::-1]
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    return img


def finish(context, run, got, ms):
    """Turns a finished bake into images, UVs and files; returns the summary line."""
    if run.error is not None:
        if isinstance(run.error, ms.Error) and run.error.status == 3:
            raise Cancelled()
        raise run.error
    st = context.scene.microshadow
    lm = run.result
    size, pages = st.bake_size, lm["pages"]
    images = [("microshadow_irradiance", lm["irradiance"])]
    for name, lt in zip(got.light_names, lm["lights"]):
        if name is not None:
            s = np.maximum(lt["shadow"], 0.0)
            images.append(("microshadow_shadowmask_" + name, np.repeat(s[..., None], 3, -1)))
    # page p is rows p * size .. of every plane (microshadow/bake.h), its images named with ".p" after the first
    # as the CLI's files are (lightmap.exr, lightmap.1.exr, ...)
    made = [_image(n + ("" if p == 0 else ".%d" % p), rows[p * size:(p + 1) * size], size)
            for n, rows in images for p in range(pages)]
    skipped = _write_uvs(got, lm["uv"], lm["page"])
    folder = bpy.path.abspath(st.bake_output)
    written = []
    if bpy.data.filepath or not st.bake_output.startswith("//"):
        written = _save_all(made, folder, context.scene)
    summary = "microshadow: baked %d objects into %d x %d%s, %d texels on triangles, %.1f s" % (
        sum(1 for o in got.objects if _is_receiver(got, o)), size, size, " x %d pages" % pages if pages > 1 else "",
        lm["texels"], time.time() - run.started)
    if written:
        summary += "; wrote %s" % ", ".join(os.path.basename(p) for p in written)
    else:
        summary += "; save the .blend (or choose a folder) to write the EXR files"
    return summary, skipped


def _write_uvs(got, uv, page):
    """The lightmap UVs onto each baked object's mesh, and the page its texels are on as the object's custom
    property microshadow_lightmap_page (its images are those with ".<page>" after the name, none for page 0)."""
    skipped = []
    for o in got.objects:
        ob = o.original
        if ob is None or ob.type != "MESH" or not o.same_topology or not _is_receiver(got, o):
            if ob is not None and _is_receiver(got, o) and not o.same_topology:
                skipped.append(o.name)
            continue
        me = ob.data
        layer = me.uv_layers.get(LIGHTMAP_UV) or me.uv_layers.new(name=LIGHTMAP_UV, do_init=False)
        if layer is None:  # a mesh holds at most 8 UV maps
            skipped.append(o.name)
            continue
        per_loop = np.zeros((len(me.loops), 2), np.float32)
        per_loop[o.loops.ravel()] = scene_from_blender.flip_v(uv[o.first:o.first + o.count]).reshape(-1, 2)
        layer.data.foreach_set("uv", per_loop.ravel())
        ob["microshadow_lightmap_page"] = int(page[o.first]) if len(page) else 0
    return skipped


def _is_receiver(got, o):
    scale = got.arrays["lightmap_scale"]
    i = got.objects.index(o)
    return scale is None or scale[i] > 0


def _save_all(images, folder, scene):
    """All or nothing: each image to a temporary file in the folder, then every one renamed. Written through
    the scene's output settings set to 32-bit float EXR with lossless ZIP (and restored): Image.save keeps
    the image's own EXR settings, which may round (half floats, a lossy codec)."""
    os.makedirs(folder, exist_ok=True)
    fmt = scene.render.image_settings
    kept = {k: getattr(fmt, k) for k in ("file_format", "color_depth", "exr_codec", "color_mode")}
    tmp = []
    try:
        fmt.file_format = "OPEN_EXR"
        fmt.color_mode, fmt.color_depth, fmt.exr_codec = "RGB", "32", "ZIP"
        for img in images:
            fd, path = tempfile.mkstemp(prefix=".%s." % img.name, suffix=".exr", dir=folder)
            os.close(fd)
            tmp.append(path)
            img.save_render(path, scene=scene)
        final = []
        for img, path in zip(images, tmp):
            dst = os.path.join(folder, img.name + ".exr")
            os.replace(path, dst)
            final.append(dst)
        tmp = []
        for img, dst in zip(images, final):  # the images now show their files (saved with the .blend by path)
            img.filepath_raw = dst
            img.source = "FILE"
        return final
    finally:
        for k, v in kept.items():
            setattr(fmt, k, v)
        for p in tmp:
            if os.path.exists(p):
                os.remove(p)


class MICROSHADOW_OT_bake(bpy.types.Operator):
    """Bake the selected objects' lightmap and shadowmasks with microshadow (Esc cancels)"""
    bl_idname = "microshadow.bake"
    bl_label = "Bake Lightmap"
    bl_options = {"REGISTER"}

    _timer = None

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def _report_error(self, e):
        self.report({"ERROR"}, str(e).splitlines()[0] if str(e) else type(e).__name__)

    def execute(self, context):
        """Synchronous (scripts, background mode): the same steps as the modal bake without the event loop."""
        try:
            self._run, self._got, self._ms = start(context)
        except Exception as e:
            self._report_error(e)
            return {"CANCELLED"}
        self._run.wait()
        return self._finish(context)

    def _finish(self, context):
        for w in self._got.warnings + self._run.warnings:
            self.report({"WARNING"}, w if w.startswith("microshadow") else "microshadow: " + w)
        try:
            summary, skipped = finish(context, self._run, self._got, self._ms)
        except Cancelled:
            self.report({"WARNING"}, "microshadow: bake cancelled; nothing written")
            return {"CANCELLED"}
        except Exception as e:
            self._report_error(e)
            return {"CANCELLED"}
        if skipped:
            self.report({"WARNING"}, "microshadow: the lightmap UVs of %s were not written back (modifiers change "
                                     "the topology, or no room for a UV map)" % ", ".join(skipped))
        self.report({"INFO"}, summary)
        return {"FINISHED"}

    def invoke(self, context, event):
        try:
            self._run, self._got, self._ms = start(context)
        except Exception as e:
            self._report_error(e)
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._run.cancel = True
        if event.type != "TIMER" and not self._run.cancel:
            return {"PASS_THROUGH"}
        wm = context.window_manager
        wm.progress_update(int(100 * self._run.fraction))
        if context.area:
            context.area.header_text_set("microshadow: baking %d%% (Esc to cancel)" % int(100 * self._run.fraction))
        if not self._run.done():
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.area:
            context.area.header_text_set(None)
        return self._finish(context)
