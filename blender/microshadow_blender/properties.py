"""The add-on's settings: per scene (frames and bakes) and the add-on's preferences."""
import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

METHODS = [("AUTO", "Automatic", "microshadow picks the method for the scene (docs/methods.md)"),
           ("scanline", "Scanline", "Bit-parallel scanline micro-rasterization (Woop)"),
           ("raytrace", "Ray tracing", "One shadow ray per light sample (microshadow's BVH)"),
           ("embree", "Embree", "One shadow ray per light sample through Intel Embree"),
           ("mft", "Multi-frusta", "Multi-frusta tracing (Benthin & Wald)"),
           ("hpc", "Penumbra casting", "Hierarchical penumbra casting (Laine & Aila)"),
           ("bounds", "Bounds", "Scanline with per-block bounds"),
           ("hierarchical", "Hierarchical", "Hierarchical micro-rasterization")]
SAMPLES = [("256", "256", "16 x 16 light samples"), ("1024", "1024", "32 x 32 light samples"),
           ("4096", "4096", "64 x 64 light samples")]


def method_value(s):
    return None if s == "AUTO" else s


class MicroshadowSettings(bpy.types.PropertyGroup):
    samples: EnumProperty(name="Light Samples", items=SAMPLES, default="256",
                          description="Samples on each light per pixel or texel (a grid: every method the same)")
    method: EnumProperty(name="Method", items=METHODS, default="AUTO",
                         description="The visibility algorithm; every method gives the same V and S")
    aa: EnumProperty(name="Anti-aliasing", items=[("1", "1", ""), ("4", "4", ""), ("9", "9", ""), ("16", "16", "")],
                     default="4", description="Primary samples per pixel")
    shading: EnumProperty(name="Shading", items=[("standard", "Standard", "Base colour, metallic and roughness (GGX)"),
                                                 ("diffuse", "Diffuse", "Base colour x irradiance x S / pi: what a "
                                                                        "lightmap can show")], default="standard")
    threads: IntProperty(name="Threads", default=0, min=0, description="0: every core")
    bake_size: IntProperty(name="Size", default=1024, min=16, max=8192, description="Lightmap texels per side")
    bake_texel_density: FloatProperty(name="Texel Density", default=0.0, min=0.0, soft_max=1024.0,
                                      description="Texels per world unit over as many pages as it takes (each "
                                                  "page Size x Size); 0: one page at the largest density that fits")
    bake_padding: IntProperty(name="Padding", default=2, min=0, max=64,
                              description="Texels between charts (0: touching; Blender's viewport mipmaps textures)")
    bake_whole_layouts: BoolProperty(name="Whole Layouts", default=False,
                                     description="Move each object's UV layout into the lightmap as one rectangle "
                                                 "(one scale and offset per object) instead of packing its islands "
                                                 "one by one: the islands keep their places, the lightmap fills "
                                                 "far less")
    bake_uv_map: StringProperty(name="UV Map", default="",
                                description="The UV map baked into; empty: each object's active render UV map. "
                                            "Objects without it are charted by microshadow")
    bake_uv_source: EnumProperty(
        name="UVs", default="EXISTING",
        items=[("EXISTING", "UV Map", "The UV map named above (objects without it are charted by microshadow)"),
               ("LIGHTMAP_PACK", "Lightmap Pack", "Blender's Lightmap Pack of the selected objects into the UV map "
                                                  "named above (made when missing)"),
               ("MICROSHADOW", "microshadow unwrap", "microshadow's charts (xatlas) for every object")])
    bake_output: StringProperty(name="Folder", default="//", subtype="DIR_PATH",
                                description="Where the EXR files go (// : beside the .blend)")


class MicroshadowPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__
    library: StringProperty(name="Library", subtype="FILE_PATH", default="",
                            description="Path to libmicroshadow.so (empty: the bundled one or the repository's build)")

    def draw(self, context):
        self.layout.prop(self, "library")


def preferences(context):
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon else None


def register():
    bpy.utils.register_class(MicroshadowSettings)
    bpy.utils.register_class(MicroshadowPreferences)
    bpy.types.Scene.microshadow = PointerProperty(type=MicroshadowSettings)


def unregister():
    del bpy.types.Scene.microshadow
    bpy.utils.unregister_class(MicroshadowPreferences)
    bpy.utils.unregister_class(MicroshadowSettings)
