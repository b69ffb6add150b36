"""The ctypes layer of the microshadow package: the shared library found and loaded, its structs mirrored where
the library says they are (ms_layout), its entry points typed, and the ABI table handed to its checked ones."""
import ctypes
import ctypes.util
import os

MAX_UV_SETS = 4
MAX_COUNTERS = 64
NO_TRIANGLE = 0xFFFFFFFF
NO_MATERIAL = 0xFFFFFFFF
MAX_LIGHTS = 64


class Error(RuntimeError):
    """A failed call: .status is the library's ms_status code (0 ok, 1 invalid, 2 memory, 3 cancelled,
    4 method, 5 i/o, 6 over the memory budget; -1 for the other failures of the frame and scene functions)."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status



def _find_library():
    env = os.environ.get("MICROSHADOW_LIBRARY")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    # installed as PREFIX/LIBDIR/python3/dist-packages/microshadow: the library is PREFIX/LIBDIR
    for rel in ("../../..", "../../../.."):
        cand = os.path.normpath(os.path.join(here, rel, "libmicroshadow.so"))
        if os.path.exists(cand):
            return cand
    found = ctypes.util.find_library("microshadow")
    if not found:
        raise ImportError("microshadow: libmicroshadow.so not found (set MICROSHADOW_LIBRARY)")
    return found


_lib = ctypes.CDLL(_find_library())

_f = ctypes.c_float
_p = ctypes.c_void_p
_size = ctypes.c_size_t


def _sig(name, res, *args):
    fn = getattr(_lib, name)
    fn.restype = res
    fn.argtypes = list(args)
    return fn


_layout = _sig("ms_layout", ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(_size), ctypes.POINTER(_size))


def _mirror(cname, fields):
    """A ctypes mirror of the C struct `cname` holding `fields` (name, ctype) where the library says they
    are (ms_layout): each field at its offset, bytes the module does not use as padding, the struct's size
    as compiled. A library whose layout does not fit (a field missing or of another size) fails the import
    here, with the struct and field named, instead of corrupting memory later."""
    off, size = _size(), _size()
    if _layout(cname.encode(), None, None, ctypes.byref(size)) != 0:
        raise ImportError("microshadow: the library does not describe struct %s (an older library?)" % cname)
    total = size.value
    placed = []
    for name, ctype in fields:
        if _layout(cname.encode(), name.encode(), ctypes.byref(off), ctypes.byref(size)) != 0:
            raise ImportError("microshadow: the library's %s has no field %s" % (cname, name))
        if size.value != ctypes.sizeof(ctype):
            raise ImportError("microshadow: %s.%s is %d bytes in the library, %d here" % (cname, name, size.value,
                                                                                        ctypes.sizeof(ctype)))
        placed.append((off.value, name, ctype))
    placed.sort(key=lambda t: t[0])
    out, pos = [], 0
    for offset, name, ctype in placed:
        if offset < pos:
            raise ImportError("microshadow: %s.%s overlaps the field before it" % (cname, name))
        if offset > pos:
            out.append(("_pad%d" % pos, ctypes.c_ubyte * (offset - pos)))
        out.append((name, ctype))
        pos = offset + ctypes.sizeof(ctype)
    if total > pos:
        out.append(("_pad%d" % pos, ctypes.c_ubyte * (total - pos)))
    cls = type(cname, (ctypes.Structure,), {"_fields_": out})
    # ctypes aligns members by their types as C does; check that it put each one where C has it
    for offset, name, _ in placed:
        if getattr(cls, name).offset != offset:
            raise ImportError("microshadow: %s.%s lands at %d here, %d in the library" % (cname, name,
                                                                                        getattr(cls, name).offset, offset))
    if ctypes.sizeof(cls) != total:
        raise ImportError("microshadow: %s is %d bytes here, %d in the library" % (cname, ctypes.sizeof(cls), total))
    return cls


_Vec3 = _mirror("ms_vec3", [("x", _f), ("y", _f), ("z", _f)])
_Camera = _mirror("ms_camera", [("eye", _Vec3), ("target", _Vec3), ("up", _Vec3), ("fov_y", _f),
                                ("width", ctypes.c_int), ("height", ctypes.c_int), ("type", ctypes.c_int), ("fov", _f),
                                ("ortho_height", _f)])
_Light = _mirror("ms_light", [("corner", _Vec3), ("edge_s", _Vec3), ("edge_t", _Vec3), ("emission", _Vec3),
                              ("shape", ctypes.c_int), ("texture", ctypes.POINTER(_f)), ("texture_width", ctypes.c_int),
                              ("texture_height", ctypes.c_int), ("center", _Vec3), ("radius", _f)])
_Material = _mirror("ms_material", [("base_color", _f * 4), ("metallic", _f), ("roughness", _f),
                                    ("base_color_texture", ctypes.c_int32), ("alpha_texture", ctypes.c_int32),
                                    ("emissive", _f * 3)])
_Scene = _mirror("ms_scene", [("tri", ctypes.POINTER(_f)), ("n_tris", _size), ("camera", _Camera), ("light", _Light),
                              ("samples", ctypes.c_int), ("load_s", ctypes.c_double),
                              ("tri_mesh", ctypes.POINTER(ctypes.c_uint32)), ("tri_uv", ctypes.POINTER(_f) * MAX_UV_SETS),
                              ("n_meshes", _size), ("lights", ctypes.POINTER(_Light)), ("n_lights", _size),
                              ("origin", ctypes.c_double * 3), ("tri_object", ctypes.POINTER(ctypes.c_uint32)),
                              ("n_objects", _size), ("mesh_lightmap_scale", ctypes.POINTER(_f)),
                              ("materials", ctypes.POINTER(_Material)), ("n_materials", _size),
                              ("tri_material", ctypes.POINTER(ctypes.c_uint32)), ("tri_normal", ctypes.POINTER(_f))])
_Stats = _mirror("ms_stats", [("triangles", _size)] +
                 [(n, ctypes.c_double) for n in ("load_s", "build_s", "setup_s", "primary_s", "shadow_s", "total_s")] +
                 [(n, ctypes.c_int) for n in ("samples", "threads", "width", "height", "samples_per_pixel")] +
                 [(n, ctypes.c_char_p) for n in ("method", "pattern", "kernel_isa", "traversal_isa")] +
                 [(n, ctypes.c_uint64) for n in ("visible_pixels", "shadow_rays", "penumbra_pixels")] +
                 [("shadow_factor_s", ctypes.c_double), ("filter_s", ctypes.c_double), ("n_counters", ctypes.c_int),
                  ("counter_name", ctypes.c_char_p * MAX_COUNTERS), ("counter", ctypes.c_uint64 * MAX_COUNTERS),
                  ("shadow_cpu_s", ctypes.c_double), ("primary", ctypes.c_char_p)] +
                 [(n, ctypes.c_uint64) for n in ("primary_setups", "primary_edge_evals", "primary_nodes", "memory_need",
                                                 "memory_budget")])
_Frame = _mirror("ms_frame", [("width", ctypes.c_int), ("height", ctypes.c_int), ("vis", ctypes.POINTER(_f)),
                              ("shadow", ctypes.POINTER(_f)), ("front", ctypes.POINTER(ctypes.c_uint16)),
                              ("rgb", ctypes.POINTER(_f)), ("exposure", _f), ("stats", _Stats),
                              ("shadow_spec", ctypes.POINTER(_f)), ("n_lights", ctypes.c_int)])


_LoadOptions = _mirror("ms_scene_load_options", [("allow_outside_paths", ctypes.c_int)])
_PROGRESS_CANCEL = ctypes.CFUNCTYPE(ctypes.c_int, _p, ctypes.c_double)
_RenderOptions = _mirror("ms_render_options", [
    ("method", ctypes.c_char_p), ("pattern", ctypes.c_int), ("samples", ctypes.c_int), ("width", ctypes.c_int),
    ("height", ctypes.c_int), ("threads", ctypes.c_int), ("seed", ctypes.c_uint32), ("progress", _PROGRESS_CANCEL),
    ("progress_user", _p), ("isa", ctypes.c_int), ("embree_mode", ctypes.c_int), ("embree_filter", ctypes.c_int),
    ("traversal", ctypes.c_int), ("no_filter", ctypes.c_int), ("primary", ctypes.c_char_p),
    ("consistent_primary", ctypes.c_int), ("max_memory", ctypes.c_uint64), ("aa", ctypes.c_int), ("aa_split", ctypes.c_int),
    ("shading", ctypes.c_int)])
_Points = _mirror("ms_points", [("n", _size), ("position", _p), ("normal", _p), ("triangle", _p), ("key", _p)])
_PointsOptions = _mirror("ms_points_options", [
    ("method", ctypes.c_char_p), ("pattern", ctypes.c_int), ("samples", ctypes.c_int), ("threads", ctypes.c_int),
    ("seed", ctypes.c_uint32), ("isa", ctypes.c_int), ("progress", _PROGRESS_CANCEL), ("progress_user", _p),
    ("embree_mode", ctypes.c_int), ("embree_filter", ctypes.c_int), ("max_memory", ctypes.c_uint64)])
_Lightmap = _mirror("ms_lightmap", [
    ("frame", _Frame), ("position", ctypes.POINTER(_f)), ("normal", ctypes.POINTER(_f)),
    ("triangle", ctypes.POINTER(ctypes.c_uint32)), ("uv", ctypes.POINTER(_f)), ("n_tris", _size), ("texels", _size),
    ("unwrapped_tris", _size), ("unwrap_s", ctypes.c_double), ("raster_s", ctypes.c_double),
    ("pages", ctypes.c_int), ("page", ctypes.POINTER(ctypes.c_uint32)), ("page_fill", ctypes.POINTER(ctypes.c_double)),
    ("n_objects", _size), ("object_uv_set", ctypes.POINTER(ctypes.c_int)), ("object_scale_offset", ctypes.POINTER(_f)),
    ("charts", _size), ("uv_cached", ctypes.c_int)])
_BakeOptions = _mirror("ms_bake_options", [("points", _PointsOptions), ("size", ctypes.c_int), ("uv_set", ctypes.c_int),
                                           ("dilate", ctypes.c_int), ("padding", ctypes.c_int), ("texel_density", _f),
                                           ("uv_cache", ctypes.c_char_p), ("uv_packing", ctypes.c_int)])

_ERR = ctypes.c_char_p


class _Abi(ctypes.Structure):
    """ms_abi (microshadow/abi.h, "The ABI check"): the size of each struct as this module mirrors it, handed to the
    library's checked entry points (the *_abi functions) with every call; 0 for a struct the module does not
    mirror (not compared), and no version (the mirrors were checked against the library with ms_layout)."""
    _fields_ = [(n, ctypes.c_uint32) for n in (
        "abi_size", "abi_level", "version_minor", "camera", "light", "procedural", "scene", "texture",
        "texture_sampling", "material", "scene_load_options", "render_options", "stats", "frame", "output", "points",
        "points_options", "bake_options", "lightmap", "bake_gltf_options")]


_ABI = _Abi(abi_size=ctypes.sizeof(_Abi), camera=ctypes.sizeof(_Camera), light=ctypes.sizeof(_Light),
            scene=ctypes.sizeof(_Scene), scene_load_options=ctypes.sizeof(_LoadOptions),
            render_options=ctypes.sizeof(_RenderOptions), stats=ctypes.sizeof(_Stats), frame=ctypes.sizeof(_Frame),
            points=ctypes.sizeof(_Points), points_options=ctypes.sizeof(_PointsOptions),
            bake_options=ctypes.sizeof(_BakeOptions), lightmap=ctypes.sizeof(_Lightmap))


def _checked(name, res, *args):
    """One of the library's checked entry points: its exported form name_abi, given this module's ABI table."""
    fn = _sig(name + "_abi", res, ctypes.POINTER(_Abi), *args)
    return lambda *a: fn(ctypes.byref(_ABI), *a)


_scene_load = _checked("ms_scene_load", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(_LoadOptions),
                       ctypes.POINTER(_Scene), _ERR, _size)
_scene_default = _checked("ms_scene_default", ctypes.c_int, ctypes.POINTER(_Scene))
_scene_free = _sig("ms_scene_free", None, ctypes.POINTER(_Scene))
_scene_validate = _sig("ms_scene_validate", ctypes.c_int, ctypes.POINTER(_Scene), ctypes.c_char_p, _ERR, _size)
_accel_build = _checked("ms_accel_build", ctypes.c_int, ctypes.POINTER(_Scene), ctypes.c_int, ctypes.POINTER(_p), _ERR, _size)
_accel_free = _sig("ms_accel_free", None, _p)
_accel_lights = _sig("ms_accel_lights", ctypes.POINTER(_Light), _p, ctypes.POINTER(_size))
_vis_points = _checked("ms_visibility_points", ctypes.c_int, _p, ctypes.POINTER(_Light), ctypes.POINTER(_Points),
                   ctypes.POINTER(_PointsOptions), _p, _p, _p, ctypes.POINTER(_Stats), _ERR, _size)
_render = _checked("ms_render", ctypes.c_int, ctypes.POINTER(_Scene), ctypes.POINTER(_RenderOptions),
               ctypes.POINTER(_Frame), _ERR, _size)
_frame_free = _sig("ms_frame_free", None, ctypes.POINTER(_Frame))
_method_names = _sig("ms_method_names", ctypes.POINTER(ctypes.c_char_p))
_irradiance = _sig("ms_light_irradiance", _f, ctypes.POINTER(_Light), ctypes.POINTER(_f), ctypes.POINTER(_f))
_light_disk = _sig("ms_light_disk", ctypes.c_int, ctypes.POINTER(_Light), _Vec3, _Vec3, _f)
_light_sphere = _sig("ms_light_sphere", ctypes.c_int, ctypes.POINTER(_Light), _Vec3, _f)
_light_triangle = _sig("ms_light_triangle", ctypes.c_int, ctypes.POINTER(_Light), _Vec3, _Vec3, _Vec3)
_light_sun = _sig("ms_light_sun", ctypes.c_int, ctypes.POINTER(_Light), _Vec3, _f)
_nearest = _sig("ms_nearest_name", ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p), ctypes.POINTER(_size))
_version = _sig("ms_version", ctypes.c_char_p, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int),
                ctypes.POINTER(ctypes.c_int))
_bake = _checked("ms_bake", ctypes.c_int, ctypes.POINTER(_Scene), _p, ctypes.POINTER(_BakeOptions),
             ctypes.POINTER(_Lightmap), _ERR, _size)
_lightmap_free = _sig("ms_lightmap_free", None, ctypes.POINTER(_Lightmap))

__version__ = _version(None, None, None).decode()
