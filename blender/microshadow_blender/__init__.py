"""microshadow inside Blender: exact area-light soft shadows, rendered (the "microshadow" render engine)
and baked (lightmaps and shadowmasks of the selected objects), from the scene as Blender evaluates it.

Install: Edit > Preferences > Add-ons > Install... with the zip scripts/make_blender_addon.sh makes (it
bundles the Python module and libmicroshadow.so), or link this folder into Blender's scripts/addons
folder inside a built repository. The manual is docs/blender.md.
"""
bl_info = {
    "name": "microshadow",
    "author": "microshadow developers",
    "version": (0, 12, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine; Render Properties > microshadow Bake; 3D View > Sidebar",
    "description": "Exact soft shadows from area lights: a render engine and a lightmap baker",
    "category": "Render",
}

if "bpy" in locals():  # Blender's "Reload Scripts"
    import importlib
    for _m in (light_units, scene_from_blender, job, library, properties, engine, bake, export, ui):  # noqa: F821
        importlib.reload(_m)

import bpy  # noqa: E402

from . import bake, engine, export, job, library, light_units, properties, scene_from_blender, ui  # noqa: E402,F401


def register():
    properties.register()
    bpy.utils.register_class(engine.MicroshadowRenderEngine)
    bpy.utils.register_class(bake.MICROSHADOW_OT_bake)
    bpy.utils.register_class(export.MICROSHADOW_OT_export_scene)
    ui.register()


def unregister():
    ui.unregister()
    bpy.utils.unregister_class(export.MICROSHADOW_OT_export_scene)
    bpy.utils.unregister_class(bake.MICROSHADOW_OT_bake)
    bpy.utils.unregister_class(engine.MicroshadowRenderEngine)
    properties.unregister()
