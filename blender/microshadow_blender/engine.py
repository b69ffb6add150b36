"""microshadow as a Blender render engine: the active camera's frame (soft shadows from every light, the
materials' base colour, metallic and roughness) into the render result, and V and S of each light as
render passes.

The Combined pass holds radiance in Blender's scene-linear units, not multiplied by microshadow's automatic
exposure: Blender's colour management (its view transform and Exposure) then shows it as it shows Cycles'
render of the same lights, which is what an artist comparing the two expects. The frame's own exposure is
reported in the render's stats line.
"""
import bpy
import numpy as np

from . import job, library, properties, scene_from_blender


def light_pass_names(scene):
    """The Blender lights the frame gets V and S passes for, before rendering (the compositor asks for them):
    every light object shown in renders. An emissive mesh's triangles are lights without passes."""
    names = []
    for ob in scene.objects:
        if ob.type == "LIGHT" and not ob.hide_render:
            names.append(ob.name)
    return names


class MicroshadowRenderEngine(bpy.types.RenderEngine):
    bl_idname = "MICROSHADOW"
    bl_label = "microshadow"
    bl_use_preview = False
    bl_use_postprocess = True

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name in light_pass_names(scene):
            self.register_pass(scene, renderlayer, "V " + name, 1, "X", "VALUE")
            self.register_pass(scene, renderlayer, "S " + name, 1, "X", "VALUE")

    def render(self, depsgraph):
        scene = depsgraph.scene
        r = scene.render
        width, height = int(r.resolution_x * r.resolution_percentage / 100), int(r.resolution_y * r.resolution_percentage / 100)
        try:
            frame, names = self._frame(depsgraph, scene, width, height)
        except Exception as e:  # one line in Blender's report, never an exception through Blender
            self.report({"ERROR"}, str(e).splitlines()[0] if str(e) else type(e).__name__)
            return
        if frame is None:
            return
        for name in filter(None, names):
            self.add_pass("V " + name, 1, "X")
            self.add_pass("S " + name, 1, "X")
        result = self.begin_result(0, 0, width, height)
        layer = result.layers[0]
        rgba = np.ones((height, width, 4), np.float32)
        rgba[..., :3] = frame["rgb"]
        # microshadow's row 0 is the top of the image, Blender's the bottom
        layer.passes["Combined"].rect = rgba[::-1].reshape(-1, 4)
        for name, lt in zip(names, frame["lights"]):
            if name is None:
                continue
            for key, plane in (("V ", lt["vis"]), ("S ", lt["shadow"])):
                p = layer.passes.find_by_name(key + name, "")
                if p is not None:
                    p.rect = np.maximum(plane, 0.0)[::-1].reshape(-1, 1)
        self.end_result(result)
        st = frame["stats"]
        self.update_stats("microshadow", "%s, %d light samples, %.2f s, exposure %.3g" %
                          (st["method"], st["samples"], st["total_s"], frame["exposure"]))

    def _frame(self, depsgraph, scene, width, height):
        prefs = properties.preferences(bpy.context)
        ms = library.module(prefs.library if prefs else "")
        st = scene.microshadow
        if scene.camera is None:
            raise scene_from_blender.SceneError("the scene has no active camera")
        got = scene_from_blender.collect(depsgraph, ms, camera=scene.camera, width=width, height=height)
        for w in got.warnings:
            self.report({"WARNING"}, w)
        arrays, names = got.arrays, got.light_names
        sc = ms.scene_from_arrays(**arrays)
        self.update_stats("microshadow", "rendering %d triangles, %d lights" % (len(arrays["triangles"]),
                                                                                len(arrays["lights"])))
        run = job.Job(ms, ms.render, scene=sc, method=properties.method_value(st.method), samples=int(st.samples),
                      width=width, height=height, threads=st.threads or scene.render.threads, aa=int(st.aa),
                      shading=st.shading)
        while not run.wait(0.05):
            self.update_progress(run.fraction)
            if self.test_break():
                run.cancel = True
        for w in run.warnings:
            self.report({"WARNING"}, "microshadow: " + w)
        if run.error is not None:
            if isinstance(run.error, ms.Error) and run.error.status == 3:
                return None, names
            raise run.error
        return run.result, names
