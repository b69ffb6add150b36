"""microshadow from Python: exact soft shadows from a parallelogram area light, on the CPU.

A thin ctypes layer over the shared library (libmicroshadow.so); numpy arrays in and out.

    import microshadow as ms
    scene = ms.load("scene.json")                       # or ms.default_scene()
    V, S = ms.visibility_points(scene, positions, normals)   # (n, 3) float arrays -> (n,) V and S

render() gives a frame's arrays, bake() a lightmap's. The library is found through the environment
variable MICROSHADOW_LIBRARY (a path to libmicroshadow.so), then in the installed tree this package is
part of (cmake --install puts it in PREFIX/LIBDIR/python3/dist-packages), then the system's library path.
"""
import ctypes
import ctypes.util
import os

import numpy as np

__all__ = ["Error", "Scene", "Accel", "load", "default_scene", "visibility_points", "render", "bake",
           "method_names", "light_irradiance"]

MAX_UV_SETS = 4
MAX_COUNTERS = 24
NO_TRIANGLE = 0xFFFFFFFF


class Error(RuntimeError):
    """A failed call: .status is the library's ms_status code (0 ok, 1 invalid, 2 memory, 3 cancelled,
    4 method, 5 i/o; -1 for the frame and scene functions, which return only pass/fail)."""

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


class _Vec3(ctypes.Structure):
    _fields_ = [("x", _f), ("y", _f), ("z", _f)]


class _Camera(ctypes.Structure):
    _fields_ = [("eye", _Vec3), ("target", _Vec3), ("up", _Vec3), ("fov_y", _f), ("width", ctypes.c_int),
                ("height", ctypes.c_int), ("type", ctypes.c_int), ("fov", _f), ("ortho_height", _f)]


class _Light(ctypes.Structure):
    _fields_ = [("corner", _Vec3), ("edge_s", _Vec3), ("edge_t", _Vec3), ("emission", _Vec3), ("shape", ctypes.c_int),
                ("texture", ctypes.POINTER(_f)), ("texture_width", ctypes.c_int), ("texture_height", ctypes.c_int),
                ("center", _Vec3), ("radius", _f)]


class _Scene(ctypes.Structure):
    _fields_ = [("tri", ctypes.POINTER(_f)), ("n_tris", ctypes.c_size_t), ("camera", _Camera), ("light", _Light),
                ("samples", ctypes.c_int), ("load_s", ctypes.c_double),
                ("tri_mesh", ctypes.POINTER(ctypes.c_uint32)), ("tri_uv", ctypes.POINTER(_f) * MAX_UV_SETS),
                ("n_meshes", ctypes.c_size_t), ("procedural_type", ctypes.c_int), ("procedural_seed", ctypes.c_uint32),
                # surfaces (materials, shading normals, textures): read by the library only
                ("materials", _p), ("n_materials", ctypes.c_size_t), ("tri_material", ctypes.POINTER(ctypes.c_uint32)),
                ("tri_normal", ctypes.POINTER(_f)), ("textures", _p), ("n_textures", ctypes.c_size_t),
                ("lights", ctypes.POINTER(_Light)), ("n_lights", ctypes.c_size_t), ("tri_tangent", ctypes.POINTER(_f))]


class _Stats(ctypes.Structure):
    _fields_ = [("triangles", ctypes.c_size_t)] + \
        [(n, ctypes.c_double) for n in ("load_s", "build_s", "setup_s", "primary_s", "shadow_s", "total_s")] + \
        [(n, ctypes.c_int) for n in ("samples", "threads", "width", "height", "samples_per_pixel")] + \
        [(n, ctypes.c_char_p) for n in ("method", "pattern", "kernel_isa", "traversal_isa")] + \
        [(n, ctypes.c_uint64) for n in ("visible_pixels", "shadow_rays", "penumbra_pixels")] + \
        [("shadow_factor_s", ctypes.c_double), ("filter_s", ctypes.c_double), ("n_counters", ctypes.c_int),
         ("counter_name", ctypes.c_char_p * MAX_COUNTERS), ("counter", ctypes.c_uint64 * MAX_COUNTERS),
         ("shadow_cpu_s", ctypes.c_double), ("primary", ctypes.c_char_p)] + \
        [(n, ctypes.c_uint64) for n in ("primary_setups", "primary_edge_evals", "primary_nodes")]


class _Frame(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int), ("height", ctypes.c_int), ("vis", ctypes.POINTER(_f)),
                ("shadow", ctypes.POINTER(_f)), ("front", ctypes.POINTER(ctypes.c_uint16)),
                ("rgb", ctypes.POINTER(_f)), ("exposure", _f), ("stats", _Stats),
                ("shadow_spec", ctypes.POINTER(_f)), ("n_lights", ctypes.c_int)]


_PROGRESS = ctypes.CFUNCTYPE(None, _p, ctypes.c_double)
_PROGRESS_CANCEL = ctypes.CFUNCTYPE(ctypes.c_int, _p, ctypes.c_double)


class _RenderOptions(ctypes.Structure):
    _fields_ = [("method", ctypes.c_char_p), ("pattern", ctypes.c_int), ("samples", ctypes.c_int),
                ("width", ctypes.c_int), ("height", ctypes.c_int), ("threads", ctypes.c_int),
                ("seed", ctypes.c_uint32), ("progress", _PROGRESS), ("progress_user", _p), ("isa", ctypes.c_int),
                ("no_occlusion_cull", ctypes.c_int), ("no_child_order", ctypes.c_int),
                ("embree_mode", ctypes.c_int), ("embree_filter", ctypes.c_int),
                ("traversal", ctypes.c_int), ("frustum_shrink", ctypes.c_int), ("no_filter", ctypes.c_int),
                ("primary", ctypes.c_char_p), ("consistent_primary", ctypes.c_int)]


class _Points(ctypes.Structure):
    _fields_ = [("n", ctypes.c_size_t), ("position", _p), ("normal", _p), ("triangle", _p), ("key", _p)]


class _PointsOptions(ctypes.Structure):
    _fields_ = [("method", ctypes.c_char_p), ("pattern", ctypes.c_int), ("samples", ctypes.c_int),
                ("threads", ctypes.c_int), ("seed", ctypes.c_uint32), ("isa", ctypes.c_int),
                ("progress", _PROGRESS_CANCEL), ("progress_user", _p), ("embree_mode", ctypes.c_int),
                ("embree_filter", ctypes.c_int)]


def _sig(name, res, *args):
    fn = getattr(_lib, name)
    fn.restype = res
    fn.argtypes = list(args)
    return fn


_ERR = ctypes.c_char_p
_scene_load = _sig("ms_scene_load", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(_Scene), _ERR, ctypes.c_size_t)
_scene_default = _sig("ms_scene_default", ctypes.c_int, ctypes.POINTER(_Scene))
_scene_free = _sig("ms_scene_free", None, ctypes.POINTER(_Scene))
_accel_build = _sig("ms_accel_build", ctypes.c_int, ctypes.POINTER(_Scene), ctypes.c_int, ctypes.POINTER(_p), _ERR,
                    ctypes.c_size_t)
_accel_free = _sig("ms_accel_free", None, _p)
_vis_points = _sig("ms_visibility_points", ctypes.c_int, _p, ctypes.POINTER(_Light), ctypes.POINTER(_Points),
                   ctypes.POINTER(_PointsOptions), _p, _p, _p, ctypes.POINTER(_Stats), _ERR, ctypes.c_size_t)
_render = _sig("ms_render", ctypes.c_int, ctypes.POINTER(_Scene), ctypes.POINTER(_RenderOptions),
               ctypes.POINTER(_Frame), _ERR, ctypes.c_size_t)
_frame_free = _sig("ms_frame_free", None, ctypes.POINTER(_Frame))
_method_names = _sig("ms_method_names", ctypes.POINTER(ctypes.c_char_p))
_irradiance = _sig("ms_light_irradiance", _f, ctypes.POINTER(_Light), ctypes.POINTER(_f), ctypes.POINTER(_f))

_PATTERNS = {"grid": 0, "stratified": 1, "interleaved": 2}
_ISAS = {"auto": 0, "scalar": 1, "avx2": 2, "avx512": 3}


def _errbuf():
    return ctypes.create_string_buffer(1024)


def method_names():
    names, i = [], 0
    arr = _method_names()
    while arr[i]:
        names.append(arr[i].decode())
        i += 1
    return names


class Scene:
    """A loaded scene (ms_scene). .triangles is an (n, 3, 3) float32 copy; .light a dict."""

    def __init__(self, _s):
        self._s = _s

    def __del__(self):
        if getattr(self, "_s", None) is not None:
            _scene_free(ctypes.byref(self._s))
            self._s = None

    @property
    def n_triangles(self):
        return int(self._s.n_tris)

    @property
    def triangles(self):
        n = self.n_triangles
        return np.ctypeslib.as_array(self._s.tri, shape=(n, 3, 3)).copy() if n else np.zeros((0, 3, 3), np.float32)

    def uv(self, uv_set):
        """(n, 3, 2) UVs of each triangle's vertices in that set (NaN where its mesh lacks it), or None."""
        p = self._s.tri_uv[uv_set]
        if not p:
            return None
        return np.ctypeslib.as_array(p, shape=(self.n_triangles, 3, 2)).copy()

    @property
    def light(self):
        L = self._s.light
        v = lambda a: (a.x, a.y, a.z)  # noqa: E731
        return {"corner": v(L.corner), "edge_s": v(L.edge_s), "edge_t": v(L.edge_t), "emission": v(L.emission)}


def load(path):
    """Loads a scene JSON file (meshes relative to it). Raises Error with the library's message."""
    s, err = _Scene(), _errbuf()
    if _scene_load(os.fsencode(path), ctypes.byref(s), err, len(err)) != 0:
        raise Error(-1, err.value.decode(errors="replace"))
    return Scene(s)


def default_scene():
    s = _Scene()
    if _scene_default(ctypes.byref(s)) != 0:
        raise Error(2, "out of memory")
    return Scene(s)


class Accel:
    """The scene's acceleration structure, built once for many visibility_points calls."""

    def __init__(self, scene, threads=0):
        self.scene = scene
        self._h = _p()
        err = _errbuf()
        st = _accel_build(ctypes.byref(scene._s), int(threads), ctypes.byref(self._h), err, len(err))
        if st != 0:
            raise Error(st, err.value.decode(errors="replace"))

    def __del__(self):
        if getattr(self, "_h", None):
            _accel_free(self._h)
            self._h = None


def _light_struct(light):
    L = _Light()
    for k in ("corner", "edge_s", "edge_t", "emission"):
        setattr(L, k, _Vec3(*[float(x) for x in light[k]]))
    return L


def _progress_cancel(fn):
    if fn is None:
        return _PROGRESS_CANCEL()
    return _PROGRESS_CANCEL(lambda user, frac: 1 if fn(frac) else 0)


def visibility_points(scene, positions, normals, triangles=None, keys=None, method=None, samples=1024,
                      pattern="grid", seed=0, threads=0, light=None, isa="auto", progress=None,
                      return_front=False):
    """V and S at n points (microshadow.h, "Visibility at any points").

    scene: a Scene or an Accel (reused); positions, normals: (n, 3); triangles: (n,) scene triangle
    each point lies on (never occludes it; NO_TRIANGLE for none); keys: (n, 2) pixel whose sample
    pattern a point uses (default (i, 0)); light: a dict like Scene.light (default the scene's);
    progress: fn(fraction) -> truthy to cancel (Error with status 3). Returns (V, S) float32 arrays,
    and the front counts as a third when return_front."""
    acc = scene if isinstance(scene, Accel) else Accel(scene, threads)
    pos = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    nor = np.ascontiguousarray(normals, dtype=np.float32).reshape(-1, 3)
    if pos.shape != nor.shape:
        raise ValueError("positions and normals must have the same shape (n, 3)")
    n = pos.shape[0]
    tri = None if triangles is None else np.ascontiguousarray(triangles, dtype=np.uint32).reshape(n)
    key = None if keys is None else np.ascontiguousarray(keys, dtype=np.uint32).reshape(n, 2)
    pts = _Points(n, pos.ctypes.data, nor.ctypes.data, None if tri is None else tri.ctypes.data,
                  None if key is None else key.ctypes.data)
    cb = _progress_cancel(progress)
    opt = _PointsOptions(method.encode() if method else None, _PATTERNS[pattern], int(samples), int(threads),
                         int(seed), _ISAS[isa], cb, None, 0, 0)
    V, S = np.empty(n, np.float32), np.empty(n, np.float32)
    F = np.empty(n, np.uint16)
    L = None if light is None else ctypes.byref(_light_struct(light))
    err = _errbuf()
    st = _vis_points(acc._h, L, ctypes.byref(pts), ctypes.byref(opt), V.ctypes.data, S.ctypes.data, F.ctypes.data,
                     None, err, len(err))
    if st != 0:
        raise Error(st, err.value.decode(errors="replace"))
    return (V, S, F) if return_front else (V, S)


def render(scene, method=None, samples=0, width=0, height=0, pattern="grid", seed=0, threads=0, isa="auto",
           primary=None, consistent_primary=False):
    """A frame (ms_render): dict of vis, shadow (H, W) float32 (-1 where the primary ray missed), front
    (H, W) uint16, rgb (H, W, 3) linear radiance, exposure, and stats (a dict). primary: the primary
    visibility method (docs/primary.md; None: the method's pairing)."""
    opt = _RenderOptions()
    opt.method = method.encode() if method else None
    opt.primary = primary.encode() if primary else None
    opt.consistent_primary = 1 if consistent_primary else 0
    opt.pattern = _PATTERNS[pattern]
    opt.samples, opt.width, opt.height, opt.threads, opt.seed = int(samples), int(width), int(height), int(threads), int(seed)
    opt.isa = _ISAS[isa]
    fr, err = _Frame(), _errbuf()
    if _render(ctypes.byref(scene._s), ctypes.byref(opt), ctypes.byref(fr), err, len(err)) != 0:
        raise Error(-1, err.value.decode(errors="replace"))
    try:
        W, H = fr.width, fr.height
        out = {
            "vis": np.ctypeslib.as_array(fr.vis, shape=(H, W)).copy(),
            "shadow": np.ctypeslib.as_array(fr.shadow, shape=(H, W)).copy(),
            "front": np.ctypeslib.as_array(fr.front, shape=(H, W)).copy(),
            "rgb": np.ctypeslib.as_array(fr.rgb, shape=(H, W, 3)).copy(),
            "exposure": float(fr.exposure),
            "stats": _stats_dict(fr.stats),
        }
    finally:
        _frame_free(ctypes.byref(fr))
    return out


def _stats_dict(st):
    d = {n: getattr(st, n) for n, _ in _Stats._fields_ if n not in ("counter_name", "counter")}
    for k in ("method", "pattern", "kernel_isa", "traversal_isa", "primary"):
        d[k] = d[k].decode() if d[k] else None
    d["counters"] = {st.counter_name[i].decode(): int(st.counter[i]) for i in range(st.n_counters)}
    return d


def light_irradiance(light, point, normal):
    """Exact unshadowed irradiance per unit emitted radiance at point with unit normal."""
    p = (_f * 3)(*[float(x) for x in point])
    n = (_f * 3)(*[float(x) for x in normal])
    return float(_irradiance(ctypes.byref(_light_struct(light)), p, n))


class _Lightmap(ctypes.Structure):
    _fields_ = [("frame", _Frame), ("position", ctypes.POINTER(_f)), ("normal", ctypes.POINTER(_f)),
                ("triangle", ctypes.POINTER(ctypes.c_uint32)), ("uv", ctypes.POINTER(_f)), ("n_tris", ctypes.c_size_t),
                ("texels", ctypes.c_size_t), ("unwrapped_tris", ctypes.c_size_t), ("unwrap_s", ctypes.c_double),
                ("raster_s", ctypes.c_double)]


class _BakeOptions(ctypes.Structure):
    _fields_ = [("points", _PointsOptions), ("size", ctypes.c_int), ("uv_set", ctypes.c_int), ("dilate", ctypes.c_int),
                ("padding", ctypes.c_int)]


_bake = _sig("ms_bake", ctypes.c_int, ctypes.POINTER(_Scene), _p, ctypes.POINTER(_BakeOptions),
             ctypes.POINTER(_Lightmap), _ERR, ctypes.c_size_t)
_lightmap_free = _sig("ms_lightmap_free", None, ctypes.POINTER(_Lightmap))


def bake(scene, size=1024, uv=1, method=None, samples=1024, pattern="grid", seed=0, threads=0, isa="auto",
         dilate=4, padding=2, accel=None, progress=None):
    """A lightmap (ms_bake): dict of irradiance (size, size, 3), vis and shadow (size, size; -1 where
    nothing reached), front, position and normal (size, size, 3; NaN off the triangles), triangle
    (size, size; NO_TRIANGLE off them), uv (n_triangles, 3, 2) the UVs baked into, and counts and
    timings. uv: the UV set (0..3) or None for xatlas everywhere; dilate 0: none."""
    o = _BakeOptions()
    o.points = _PointsOptions(method.encode() if method else None, _PATTERNS[pattern], int(samples), int(threads),
                              int(seed), _ISAS[isa], _progress_cancel(progress), None, 0, 0)
    o.size = int(size)
    o.uv_set = -1 if uv is None else int(uv)
    o.dilate = -1 if dilate == 0 else int(dilate)
    o.padding = int(padding)
    lm, err = _Lightmap(), _errbuf()
    st = _bake(ctypes.byref(scene._s), accel._h if accel is not None else None, ctypes.byref(o), ctypes.byref(lm),
               err, len(err))
    if st != 0:
        raise Error(st, err.value.decode(errors="replace"))
    try:
        n = lm.frame.width
        a = np.ctypeslib.as_array
        out = {
            "irradiance": a(lm.frame.rgb, shape=(n, n, 3)).copy(),
            "vis": a(lm.frame.vis, shape=(n, n)).copy(),
            "shadow": a(lm.frame.shadow, shape=(n, n)).copy(),
            "front": a(lm.frame.front, shape=(n, n)).copy(),
            "position": a(lm.position, shape=(n, n, 3)).copy(),
            "normal": a(lm.normal, shape=(n, n, 3)).copy(),
            "triangle": a(lm.triangle, shape=(n, n)).copy(),
            "uv": a(lm.uv, shape=(lm.n_tris, 3, 2)).copy() if lm.n_tris else np.zeros((0, 3, 2), np.float32),
            "texels": int(lm.texels),
            "unwrapped_triangles": int(lm.unwrapped_tris),
            "stats": _stats_dict(lm.frame.stats),
        }
    finally:
        _lightmap_free(ctypes.byref(lm))
    return out
