"""Panels: the frame's settings under Render Properties when microshadow is the engine, and the bake's in a
panel of its own (Render Properties and the 3D view's sidebar), whatever the engine."""
import bpy


def _draw_common(layout, st):
    layout.prop(st, "samples")
    layout.prop(st, "method")
    layout.prop(st, "threads")


class MICROSHADOW_PT_render(bpy.types.Panel):
    bl_label = "microshadow"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"MICROSHADOW"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        st = context.scene.microshadow
        layout = self.layout
        layout.use_property_split = True
        _draw_common(layout, st)
        layout.prop(st, "aa")
        layout.prop(st, "shading")


class MICROSHADOW_PT_bake(bpy.types.Panel):
    bl_label = "microshadow Bake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        st = context.scene.microshadow
        layout = self.layout
        layout.use_property_split = True
        if context.engine != "MICROSHADOW":
            _draw_common(layout, st)
        layout.prop(st, "bake_uv_source")
        if st.bake_uv_source != "MICROSHADOW":
            layout.prop(st, "bake_uv_map")
            layout.prop(st, "bake_whole_layouts")
        layout.prop(st, "bake_size")
        layout.prop(st, "bake_texel_density")
        layout.prop(st, "bake_padding")
        layout.prop(st, "bake_output")
        layout.operator("microshadow.bake", icon="RENDER_STILL")
        layout.operator("microshadow.export_scene", icon="EXPORT")


class MICROSHADOW_PT_bake_sidebar(bpy.types.Panel):
    bl_label = "microshadow Bake"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "microshadow"
    draw = MICROSHADOW_PT_bake.draw


def _engine_panels():
    """Blender's own panels that serve any engine (dimensions, output, colour management, the lights' and the
    camera's data). Only those whose COMPAT_ENGINES set is their own: some families share one set object
    (all of Cycles' panels do), and adding to it would show the whole family."""
    wanted = {"RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output", "RENDER_PT_color_management",
              "DATA_PT_context_light", "DATA_PT_EEVEE_light", "DATA_PT_spot", "DATA_PT_lens", "DATA_PT_camera",
              "DATA_PT_camera_display", "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface"}
    users = {}
    for name in dir(bpy.types):
        ce = getattr(getattr(bpy.types, name), "COMPAT_ENGINES", None)
        if isinstance(ce, set):
            users.setdefault(id(ce), set()).add(name)
    out = []
    for name in sorted(wanted):
        ce = getattr(getattr(bpy.types, name, None), "COMPAT_ENGINES", None)
        if isinstance(ce, set) and users[id(ce)] <= wanted:
            out.append(getattr(bpy.types, name))
    return out


CLASSES = (MICROSHADOW_PT_render, MICROSHADOW_PT_bake, MICROSHADOW_PT_bake_sidebar)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    for p in _engine_panels():
        p.COMPAT_ENGINES.add("MICROSHADOW")


def unregister():
    for p in _engine_panels():
        p.COMPAT_ENGINES.discard("MICROSHADOW")
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
