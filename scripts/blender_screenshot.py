"""The picture of Blender's window after a bake for the README (scripts/make_blender_screenshot.sh runs it under
Xvfb): the Stanford bunny (../shared/scenes) on a ground under a rect and a disk light, baked with the add-on,
the lightmap shown on the objects (solid shading with its texture) and in an image editor, the bake panel open.

    blender --factory-startup --python scripts/blender_screenshot.py -- OUT.png SCENES_DIR
"""
import math
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "blender")))
import microshadow_blender as addon  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:]
OUT, SCENES = ARGS[0], ARGS[1]


def build():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    bpy.ops.import_mesh.ply(filepath=os.path.join(SCENES, "stanford-bunny", "bun_zipper.ply"))
    bunny = bpy.context.selected_objects[0]
    bunny.name = "bunny"
    bunny.rotation_euler = (math.pi / 2, 0, 0)
    bunny.scale = (8, 8, 8)
    bunny.location = (0.15, 0, -0.27)
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_plane_add(size=3, location=(0, 0, 0))
    bpy.context.active_object.name = "ground"
    for name, loc, rot, shape, size, energy in (("key", (0.9, -0.7, 1.6), (0.5, 0.45, 0.0), "RECTANGLE", 0.6, 60),
                                               ("fill", (-1.0, -0.4, 1.2), (0.35, -0.7, 0.0), "DISK", 0.5, 25)):
        ld = bpy.data.lights.new(name, "AREA")
        ld.shape, ld.size, ld.size_y, ld.energy = shape, size, 0.3, energy
        ob = bpy.data.objects.new(name, ld)
        bpy.context.scene.collection.objects.link(ob)
        ob.location, ob.rotation_euler = loc, rot
    sc = bpy.context.scene
    sc.microshadow.bake_size, sc.microshadow.samples, sc.microshadow.bake_output = 1024, "256", "//"
    for ob in sc.objects:
        ob.select_set(ob.type == "MESH")
    bpy.context.view_layer.objects.active = bpy.data.objects["bunny"]


def show():
    img = bpy.data.images["microshadow_irradiance"]
    px = np.array(img.pixels[:], np.float32).reshape(-1, 4)
    top = float(np.percentile(px[px[:, :3].max(1) > 0, :3], 99))
    # the solid view and the image editor draw a generated image without the scene's exposure: a copy scaled
    # to 1 at the 99th percentile
    shown = bpy.data.images.new("microshadow_irradiance / p99", img.size[0], img.size[1], float_buffer=True)
    px[:, :3] = np.clip(px[:, :3] / top, 0.0, 1.0)
    shown.pixels.foreach_set(px.ravel())
    for name in ("bunny", "ground"):
        ob = bpy.data.objects[name]
        mat = bpy.data.materials.new("lightmap " + name)
        mat.use_nodes = True
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = shown
        mat.node_tree.nodes.active = tex
        ob.data.materials.clear()
        ob.data.materials.append(mat)
        ob.data.uv_layers.active = ob.data.uv_layers["microshadow_lightmap"]
    sc = bpy.context.scene
    sc.view_settings.view_transform = "Standard"
    sc.render.engine = "MICROSHADOW"
    for ob in sc.objects:
        ob.select_set(False)
    win = bpy.context.window_manager.windows[0]
    screen = win.screen
    view3d = next(a for a in screen.areas if a.type == "VIEW_3D")
    with bpy.context.temp_override(window=win, area=view3d, region=view3d.regions[-1]):
        bpy.ops.screen.area_split(direction="VERTICAL", factor=0.58)
    areas = [a for a in screen.areas if a.type == "VIEW_3D"]
    image_area = max(areas, key=lambda a: a.x)
    image_area.type = "IMAGE_EDITOR"
    image_area.spaces[0].image = bpy.data.images["microshadow_irradiance / p99"]
    bpy.app.timers.register(lambda: fit_image(win, image_area), first_interval=0.5)
    view3d = next(a for a in screen.areas if a.type == "VIEW_3D")
    space = view3d.spaces[0]
    space.shading.type, space.shading.color_type, space.shading.light = "SOLID", "TEXTURE", "FLAT"
    space.show_region_ui = False
    space.overlay.show_floor = False
    r3d = space.region_3d
    r3d.view_rotation = (0.82, 0.42, 0.18, 0.35)
    r3d.view_distance, r3d.view_location = 3.2, (0, 0, 0.2)
    for a in screen.areas:
        if a.type == "PROPERTIES":
            a.spaces[0].context = "RENDER"


def fit_image(win, area):
    region = next(r for r in area.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.image.view_all(fit_view=True)


def shoot():
    win = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=win):
        bpy.ops.screen.screenshot(filepath=OUT)
    bpy.ops.wm.quit_blender()


def start():
    addon.register()
    build()
    bpy.ops.microshadow.bake()
    show()
    bpy.app.timers.register(shoot, first_interval=3.0)


bpy.context.preferences.view.show_splash = False
bpy.app.timers.register(start, first_interval=1.0)
