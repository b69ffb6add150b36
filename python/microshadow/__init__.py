"""microshadow from Python: exact soft shadows from area lights (rect, disk, sphere, many at once), on the CPU.

A thin ctypes layer over the shared library (libmicroshadow.so); numpy arrays in and out.

    import microshadow as ms
    scene = ms.load("scene.json")                       # or ms.default_scene()
    V, S = ms.visibility_points(scene, positions, normals)   # (n, 3) float arrays -> (n,) V and S

render() gives a frame's arrays, bake() a lightmap's. The library is found through the environment
variable MICROSHADOW_LIBRARY (a path to libmicroshadow.so), then in the installed tree this package is
part of (cmake --install puts it in PREFIX/LIBDIR/python3/dist-packages), then the system's library path.
"""
import ctypes
import os

import numpy as np

from ._bindings import (__version__, _lib, _layout, _mirror, _Stats, _Abi, _ABI, MAX_COUNTERS, MAX_UV_SETS,
                        NO_TRIANGLE, NO_MATERIAL, MAX_LIGHTS, Error, _f, _p, _size, _sig, _Vec3, _Camera, _Light,
                        _Material, _Scene, _Frame, _LoadOptions, _PROGRESS_CANCEL, _RenderOptions, _Points,
                        _PointsOptions, _Lightmap, _BakeOptions, _scene_load, _scene_default, _scene_free,
                        _scene_validate, _accel_build, _accel_free, _accel_lights, _vis_points, _render,
                        _frame_free, _method_names, _irradiance, _light_disk, _light_sphere, _light_triangle,
                        _light_sun, _nearest, _bake, _lightmap_free)

__all__ = ["Error", "Scene", "Accel", "load", "default_scene", "visibility_points", "render", "bake",
           "method_names", "light_irradiance", "set_warning_handler", "scene_from_arrays", "default_camera", "__version__"]


_PATTERNS = {"grid": 0, "stratified": 1, "interleaved": 2}
_ISAS = {"auto": 0, "scalar": 1, "avx2": 2, "avx512": 3}
_SHADINGS = {"standard": 0, "diffuse": 1}
_UV_PACKINGS = {"default": 0, "islands": 1, "regions": 2}
_SHAPES = {"rect": 0, "disk": 1, "sphere": 2, "triangle": 3, "sun": 4}
_SHAPE_NAMES = {v: k for k, v in _SHAPES.items()}
# A light dict's keys per shape: required, then optional.
_LIGHT_KEYS = {"rect": (("corner", "edge_s", "edge_t"), ("shape", "emission", "texture")),
               "disk": (("center", "normal", "radius"), ("shape", "emission", "texture")),
               "ellipse": (("corner", "edge_s", "edge_t"), ("shape", "emission", "texture")),
               "sphere": (("center", "radius"), ("shape", "emission")),
               "triangle": (("vertices",), ("shape", "emission")),
               "sun": (("direction",), ("shape", "emission", "angular_diameter_deg"))}


def _errbuf():
    return ctypes.create_string_buffer(1024)


def _suggest(word, names):
    arr = (ctypes.c_char_p * (len(names) + 1))(*[n.encode() for n in names], None)
    best = _nearest(str(word).encode(), arr, None)
    return best.decode() if best else None


def _choice(arg, value, table):
    """table[value], or a ValueError naming the argument, the choices and the nearest one."""
    if isinstance(value, str) and value in table:
        return table[value]
    names = list(table)
    raise ValueError("%s: %r is not one of %s (did you mean %r?)" % (arg, value, ", ".join(names),
                                                                     _suggest(value, names)))


def _array(arg, a, cols, kind, n=None):
    """a as a C-contiguous array of shape (n, cols) (cols None: (n,)), of float32 (kind "float", from any
    real number type) or uint32 (kind "index", from integer types only); ValueError naming the argument
    and the shape it needs otherwise: no silent reshaping, truncation or wrap-around."""
    want = "(n,)" if cols is None else "(n, %d)" % cols
    if n is not None:
        want = want.replace("n", str(n))
    arr = np.asarray(a)
    if arr.dtype == object or arr.dtype.kind not in ("f", "i", "u"):
        raise ValueError("%s: expected a numeric array of shape %s, got dtype %s" % (arg, want, arr.dtype))
    shape_ok = arr.ndim == 1 if cols is None else (arr.ndim == 2 and arr.shape[1] == cols)
    if not shape_ok or (n is not None and arr.shape[0] != n):
        raise ValueError("%s: expected shape %s, got %s" % (arg, want, tuple(arr.shape)))
    if kind == "index":
        if arr.dtype.kind == "f":
            raise ValueError("%s: expected integers (shape %s), got dtype %s" % (arg, want, arr.dtype))
        if arr.size and (arr.min() < 0 or arr.max() > 0xFFFFFFFF):
            raise ValueError("%s: values must lie in [0, 2**32)" % arg)
        return np.ascontiguousarray(arr, dtype=np.uint32)
    return np.ascontiguousarray(arr, dtype=np.float32)


def _max_memory(v):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 0 <= v < 2 ** 64:
        raise ValueError("max_memory: expected a number of bytes >= 0 (0: the default budget), got %r" % (v,))
    return int(v)


def _vec3(arg, v):
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError("%s: expected 3 finite numbers, got %r" % (arg, v))
    return _Vec3(*[float(x) for x in a])


_WARNING_FN = ctypes.CFUNCTYPE(None, _p, ctypes.c_char_p)
_set_warning_handler = _sig("ms_set_warning_handler", None, _WARNING_FN, _p)
_warning_cb = None


def set_warning_handler(fn):
    """Routes the library's warnings (one line each, without "microshadow: warning: ") to fn(message) instead
    of stderr; None restores stderr. Process-wide, like ms_set_warning_handler; fn may be called from the
    thread of any call into the library."""
    global _warning_cb
    if fn is None:
        _warning_cb = None
        _set_warning_handler(_WARNING_FN(), None)
        return
    cb = _WARNING_FN(lambda user, msg: fn(msg.decode(errors="replace")))
    _set_warning_handler(cb, None)
    _warning_cb = cb  # kept alive while the library holds it


def method_names():
    names, i = [], 0
    arr = _method_names()
    while arr[i]:
        names.append(arr[i].decode())
        i += 1
    return names


def _light_dict(L):
    """A light as a dict: its shape's parameters (rect: corner, edge_s, edge_t; disk: center, normal,
    radius; ellipse, a disk over a parallelogram that is not a square: corner, edge_s, edge_t; sphere:
    center, radius; triangle: vertices; sun: direction towards it, angular_diameter_deg),
    emission, and the texture (h, w, 3) when it has one."""
    v = lambda a: (a.x, a.y, a.z)  # noqa: E731
    shape = _SHAPE_NAMES.get(L.shape, "rect")
    d = {"shape": shape, "emission": v(L.emission)}
    if shape == "rect":
        d.update(corner=v(L.corner), edge_s=v(L.edge_s), edge_t=v(L.edge_t))
    elif shape == "disk":
        c, es, et = (np.array(v(x), np.float64) for x in (L.corner, L.edge_s, L.edge_t))
        m = np.cross(es, et)
        if abs(np.linalg.norm(es) - np.linalg.norm(et)) > 1e-6 * np.linalg.norm(es) or abs(es @ et) > 1e-6 * (es @ es):
            d.update(shape="ellipse", corner=v(L.corner), edge_s=v(L.edge_s), edge_t=v(L.edge_t))
        else:
            d.update(center=tuple(c + (es + et) / 2), normal=tuple(m / np.linalg.norm(m)),
                     radius=float(np.linalg.norm(es) / 2))
    elif shape == "triangle":
        c, es, et = (np.array(v(x), np.float64) for x in (L.corner, L.edge_s, L.edge_t))
        d.update(vertices=(tuple(c), tuple(c + es), tuple(c + et)))
    elif shape == "sun":
        # its square at unit distance has the edge 2 tan(alpha) (ms_light_sun)
        half = np.linalg.norm(np.array(v(L.edge_s), np.float64)) / 2
        d.update(direction=v(L.center), angular_diameter_deg=float(np.degrees(2 * np.arctan(half))))
    else:
        d.update(center=v(L.center), radius=float(L.radius))
    if L.texture and shape not in ("sphere", "triangle", "sun"):
        d["texture"] = np.ctypeslib.as_array(L.texture, shape=(L.texture_height, L.texture_width, 3)).copy()
    return d


def _light_struct(light, arg="light"):
    """(ms_light, what must stay alive while it is used) from a light dict (see Scene.lights)."""
    if not isinstance(light, dict):
        raise ValueError("%s: expected a dict (see Scene.lights), got %s" % (arg, type(light).__name__))
    shape = light.get("shape", "rect")
    _choice(arg + "['shape']", shape, _LIGHT_KEYS)
    required, optional = _LIGHT_KEYS[shape]
    ellipse = shape == "ellipse"  # the ellipse inscribed in a parallelogram: a disk (microshadow/lights.h)
    for k in light:
        if k not in required and k not in optional:
            raise ValueError("%s: %r is not a key of a %s light (did you mean %r?)" % (arg, k, shape,
                                                                                  _suggest(k, required + optional)))
    for k in required:
        if k not in light:
            raise ValueError("%s: a %s light needs %r" % (arg, shape, k))
    L, keep = _Light(), None
    L.emission = _vec3(arg + "['emission']", light.get("emission", (1.0, 1.0, 1.0)))
    if shape == "rect":
        L.corner, L.edge_s, L.edge_t = (_vec3(arg + "[%r]" % k, light[k]) for k in required)
    elif ellipse:
        L.corner, L.edge_s, L.edge_t = (_vec3(arg + "[%r]" % k, light[k]) for k in required)
        L.shape = _SHAPES["disk"]
    elif shape == "disk":
        if _light_disk(ctypes.byref(L), _vec3(arg + "['center']", light["center"]),
                       _vec3(arg + "['normal']", light["normal"]), float(light["radius"])) != 0:
            raise ValueError("%s: a disk needs a non-zero normal and a radius > 0" % arg)
    elif shape == "triangle":
        vs = light["vertices"]
        if not isinstance(vs, (list, tuple)) or len(vs) != 3:
            raise ValueError("%s['vertices']: expected 3 points" % arg)
        if _light_triangle(ctypes.byref(L), *(_vec3(arg + "['vertices'][%d]" % i, vs[i]) for i in range(3))) != 0:
            raise ValueError("%s: a triangle needs vertices that are not collinear" % arg)
    elif shape == "sun":
        deg = light.get("angular_diameter_deg", 0.53)
        if _light_sun(ctypes.byref(L), _vec3(arg + "['direction']", light["direction"]), float(deg)) != 0:
            raise ValueError("%s: a sun needs a non-zero direction and an angular diameter in (0, 90] degrees" % arg)
    elif _light_sphere(ctypes.byref(L), _vec3(arg + "['center']", light["center"]), float(light["radius"])) != 0:
        raise ValueError("%s: a sphere needs a radius > 0" % arg)
    if light.get("texture") is not None:
        t = np.asarray(light["texture"])
        if t.ndim != 3 or t.shape[2] != 3 or t.shape[0] < 1 or t.shape[1] < 1 or t.dtype.kind not in ("f", "i", "u"):
            raise ValueError("%s['texture']: expected a numeric array of shape (h, w, 3), got %s %s"
                             % (arg, t.dtype, tuple(t.shape)))
        keep = np.ascontiguousarray(t, dtype=np.float32)
        if not np.all(np.isfinite(keep)) or keep.min() < 0:
            raise ValueError("%s['texture']: texels must be finite and >= 0" % arg)
        L.texture = keep.ctypes.data_as(ctypes.POINTER(_f))
        L.texture_height, L.texture_width = keep.shape[0], keep.shape[1]
    return L, keep


class Scene:
    """A scene (ms_scene), loaded (load, default_scene) or built (scene_from_arrays). .triangles is an (n, 3, 3)
    float32 copy; .lights a list of dicts (the first is also .light). Both are in the scene's frame: world =
    local + .origin (docs/design.md, "The scene's frame"; (0, 0, 0) unless the scene lies far from the origin).
    visibility_points takes world positions."""

    def __init__(self, _s, keep=None):
        self._s = _s
        # a built scene points into these arrays, which it keeps alive; the library frees only what it allocated
        self._keep = keep

    def __del__(self):
        if getattr(self, "_s", None) is not None and getattr(self, "_keep", None) is None:
            _scene_free(ctypes.byref(self._s))
        self._s = None

    @property
    def n_triangles(self):
        return int(self._s.n_tris)

    @property
    def origin(self):
        """The world position of the scene's local frame (a float64 array of 3)."""
        return np.array(list(self._s.origin), dtype=np.float64)

    @property
    def triangles(self):
        n = self.n_triangles
        if n and not self._s.tri:
            raise ValueError("a procedural scene's triangles are generated when rendering, not held")
        return np.ctypeslib.as_array(self._s.tri, shape=(n, 3, 3)).copy() if n else np.zeros((0, 3, 3), np.float32)

    def uv(self, uv_set):
        """(n, 3, 2) UVs of each triangle's vertices in that set (NaN where its mesh lacks it), or None."""
        if not isinstance(uv_set, (int, np.integer)) or not 0 <= uv_set < MAX_UV_SETS:
            raise ValueError("uv_set: expected an integer in [0, %d), got %r" % (MAX_UV_SETS, uv_set))
        p = self._s.tri_uv[uv_set]
        if not p:
            return None
        return np.ctypeslib.as_array(p, shape=(self.n_triangles, 3, 2)).copy()

    @property
    def lights(self):
        if self._s.n_lights:
            return [_light_dict(self._s.lights[i]) for i in range(self._s.n_lights)]
        return [_light_dict(self._s.light)]

    @property
    def light(self):
        return self.lights[0]


def load(path, allow_outside_paths=False):
    """Loads a scene JSON file (meshes relative to it), or an asset alone (a .glb, .gltf, .obj, .ply, .off or
    .stl path: its own lights and camera, else a camera looking at it and one disk light above it; see
    ms_scene_load). Raises Error with the library's message. Files that the meshes name (glTF buffers and
    images, MTL files and maps) must lie inside the folder of the file naming them, unless
    allow_outside_paths (for trusted assets) or the scene file says so."""
    s, err = _Scene(), _errbuf()
    opt = _LoadOptions()
    opt.allow_outside_paths = 1 if allow_outside_paths else 0
    if _scene_load(os.fsencode(path), ctypes.byref(opt), ctypes.byref(s), err, len(err)) != 0:
        raise Error(-1, err.value.decode(errors="replace"))
    return Scene(s)


def default_scene():
    s = _Scene()
    if _scene_default(ctypes.byref(s)) != 0:
        raise Error(2, "out of memory")
    return Scene(s)


_CAMERA_TYPES = {"pinhole": 0, "orthographic": 1, "fisheye": 2, "latlong": 3, "parabolic": 4}


def _camera_struct(camera):
    if not isinstance(camera, dict):
        raise ValueError("camera: expected a dict (eye, target, up, width, height, and fov_y or ortho_height), got %s"
                         % type(camera).__name__)
    keys = ("type", "eye", "target", "up", "fov_y", "width", "height", "fov", "ortho_height")
    for k in camera:
        if k not in keys:
            raise ValueError("camera: %r is not a camera key (did you mean %r?)" % (k, _suggest(k, keys)))
    c = _Camera()
    c.type = _choice("camera['type']", camera.get("type", "pinhole"), _CAMERA_TYPES)
    c.eye, c.target = _vec3("camera['eye']", camera["eye"]), _vec3("camera['target']", camera["target"])
    c.up = _vec3("camera['up']", camera.get("up", (0.0, 0.0, 1.0)))
    c.fov_y, c.fov = float(camera.get("fov_y", 45.0)), float(camera.get("fov", 180.0))
    c.ortho_height = float(camera.get("ortho_height", 0.0))
    c.width, c.height = int(camera.get("width", 640)), int(camera.get("height", 480))
    return c


def default_camera(triangles):
    """A camera dict for a scene given without one (bakes need none; a scene file does): a pinhole looking at
    the triangles' bounding box from above its corner, 640 x 480. Non-finite vertices are left out."""
    v = np.asarray(triangles, np.float64).reshape(-1, 3)
    v = v[np.isfinite(v).all(1)] if np.isfinite(v).any() else np.zeros((1, 3))
    lo, hi = v.min(0), v.max(0)
    c, r = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) + 1e-3
    return {"type": "pinhole", "eye": tuple(c + r), "target": tuple(c), "up": (0.0, 0.0, 1.0), "fov_y": 45.0,
            "width": 640, "height": 480}


def scene_from_arrays(triangles, lights, camera=None, normals=None, uvs=None, objects=None, materials=None,
                      triangle_materials=None, lightmap_scale=None, samples=0):
    """A Scene built from arrays, in world coordinates (what a host application such as Blender hands over
    without writing files; ms_scene in microshadow/scene.h).

    triangles: (n, 3, 3) vertex positions; lights: a list of light dicts (as Scene.lights), at least one; camera: a dict of
    eye, target, up, width, height and fov_y (degrees; "type": "pinhole") or ortho_height ("type":
    "orthographic"); normals: (n, 3, 3) shading normals of the vertices (NaN rows: the triangle's own);
    uvs: a list of up to 4 UV sets, each (n, 3, 2) or None (NaN where a triangle has none); objects: (n,) the
    object of each triangle, 0 .. m-1 (a bake gives each object its own region of the lightmap when UVs
    overlap; default: one object); materials: a list of dicts with base_color (linear RGBA), metallic and
    roughness (glTF metallic-roughness; missing keys: glTF's defaults), triangle_materials: (n,) an index into
    it or NO_MATERIAL (the default grey); lightmap_scale: (m,) each object's texel density weight in bakes
    (0: not baked, still an occluder); samples: the scene's light samples per pixel (0: the library's default).
    The scene is checked (ms_scene_validate): a degenerate light or a non-finite vertex is an Error naming it."""
    tri = _array("triangles", np.asarray(triangles, np.float32).reshape(-1, 9), 9, "float")
    n = tri.shape[0]
    if n == 0:
        raise ValueError("triangles: expected at least one triangle")
    keep = [tri]
    s = _Scene()
    s.tri, s.n_tris = tri.ctypes.data_as(ctypes.POINTER(_f)), n
    if not isinstance(lights, (list, tuple)) or not lights:
        raise ValueError("lights: expected a non-empty list of light dicts")
    if len(lights) > MAX_LIGHTS:
        raise ValueError("lights: at most %d lights, got %d" % (MAX_LIGHTS, len(lights)))
    Ls = (_Light * len(lights))()
    for i, d in enumerate(lights):
        Ls[i], k = _light_struct(d, "lights[%d]" % i)
        keep.append(k)
    keep.append(Ls)
    s.lights, s.n_lights, s.light = ctypes.cast(Ls, ctypes.POINTER(_Light)), len(lights), Ls[0]
    if camera is not None:
        s.camera = _camera_struct(camera)
    else:  # bakes need none
        s.camera = _camera_struct(default_camera(tri))
    s.samples = int(samples)
    if normals is not None:
        nor = _array("normals", np.asarray(normals, np.float32).reshape(-1, 9), 9, "float", n)
        keep.append(nor)
        s.tri_normal = nor.ctypes.data_as(ctypes.POINTER(_f))
    if uvs is not None:
        if not isinstance(uvs, (list, tuple)) or len(uvs) > MAX_UV_SETS:
            raise ValueError("uvs: expected a list of at most %d UV sets" % MAX_UV_SETS)
        for k, u in enumerate(uvs):
            if u is None:
                continue
            a = np.ascontiguousarray(np.asarray(u, np.float32).reshape(-1, 6))
            if a.shape[0] != n:
                raise ValueError("uvs[%d]: expected (%d, 3, 2), got %d triangles" % (k, n, a.shape[0]))
            keep.append(a)
            s.tri_uv[k] = a.ctypes.data_as(ctypes.POINTER(_f))
    obj = np.zeros(n, np.uint32) if objects is None else np.ascontiguousarray(objects, dtype=np.uint32)
    if obj.shape != (n,):
        raise ValueError("objects: expected (%d,), got %s" % (n, obj.shape))
    m = int(obj.max()) + 1
    keep.append(obj)
    s.tri_object = s.tri_mesh = obj.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
    s.n_objects = s.n_meshes = m
    if lightmap_scale is not None:
        sc = np.ascontiguousarray(lightmap_scale, dtype=np.float32)
        if sc.shape != (m,) or not np.all(np.isfinite(sc)) or sc.min() < 0:
            raise ValueError("lightmap_scale: expected (%d,) finite weights >= 0, one per object" % m)
        keep.append(sc)
        s.mesh_lightmap_scale = sc.ctypes.data_as(ctypes.POINTER(_f))
    if materials:
        M = (_Material * len(materials))()
        for i, d in enumerate(materials):
            bc = d.get("base_color", (1.0, 1.0, 1.0, 1.0))
            if len(bc) == 3:
                bc = tuple(bc) + (1.0,)
            M[i].base_color[:] = [float(x) for x in bc]
            M[i].metallic, M[i].roughness = float(d.get("metallic", 1.0)), float(d.get("roughness", 1.0))
            M[i].base_color_texture = M[i].alpha_texture = -1
        keep.append(M)
        s.materials, s.n_materials = ctypes.cast(M, ctypes.POINTER(_Material)), len(materials)
        tm = np.full(n, NO_MATERIAL, np.uint32) if triangle_materials is None else \
            np.ascontiguousarray(triangle_materials, dtype=np.uint32)
        if tm.shape != (n,) or np.any((tm >= len(materials)) & (tm != NO_MATERIAL)):
            raise ValueError("triangle_materials: expected (%d,) indices into materials or NO_MATERIAL" % n)
        keep.append(tm)
        s.tri_material = tm.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
    err = _errbuf()
    if _scene_validate(ctypes.byref(s), b"scene_from_arrays", err, len(err)) != 0:
        raise Error(1, err.value.decode(errors="replace"))
    return Scene(s, keep)


class Accel:
    """The scene's acceleration structure, built once for many visibility_points calls."""

    def __init__(self, scene, threads=0):
        if not isinstance(scene, Scene):
            raise ValueError("scene: expected a Scene (load() or default_scene()), got %s" % type(scene).__name__)
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

    @property
    def n_lights(self):
        n = _size()
        _accel_lights(self._h, ctypes.byref(n))
        return int(n.value)


def _progress_cancel(fn):
    if fn is None:
        return _PROGRESS_CANCEL()
    return _PROGRESS_CANCEL(lambda user, frac: 1 if fn(frac) else 0)


def visibility_points(scene, positions, normals, triangles=None, keys=None, method=None, samples=1024,
                      pattern="grid", seed=0, threads=0, light=None, isa="auto", progress=None,
                      return_front=False, max_memory=0):
    """V and S at n points (microshadow/points.h, "Visibility at any points").

    scene: a Scene or an Accel (reused); positions, normals: (n, 3); triangles: (n,) scene triangle
    each point lies on (never occludes it; NO_TRIANGLE for none); keys: (n, 2) pixel whose sample
    pattern a point uses (default (i, 0)); light: None (the scene's first), the index of one of the
    scene's lights, "all" (every light: the results get a leading axis, one row per light), or a light
    dict (see Scene.lights: rect, disk or sphere); progress: fn(fraction) -> truthy to cancel (Error
    with status 3). Returns (V, S) float32 arrays, and the front counts as a third when return_front.
    A wrong shape or dtype is a ValueError naming the argument and the shape it needs."""
    acc = scene if isinstance(scene, Accel) else Accel(scene, threads)
    pos = _array("positions", positions, 3, "float")
    n = pos.shape[0]
    nor = _array("normals", normals, 3, "float", n)
    tri = None if triangles is None else _array("triangles", triangles, None, "index", n)
    key = None if keys is None else _array("keys", keys, 2, "index", n)
    if isinstance(light, str) and light == "all":
        rows = [visibility_points(acc, pos, nor, tri, key, method, samples, pattern, seed, threads, i, isa, progress,
                                  return_front) for i in range(acc.n_lights)]
        return tuple(np.stack([r[k] for r in rows]) for k in range(len(rows[0])))
    pts = _Points(n, pos.ctypes.data, nor.ctypes.data, None if tri is None else tri.ctypes.data,
                  None if key is None else key.ctypes.data)
    cb = _progress_cancel(progress)
    opt = _PointsOptions()
    opt.method = method.encode() if method else None
    opt.pattern, opt.isa = _choice("pattern", pattern, _PATTERNS), _choice("isa", isa, _ISAS)
    opt.samples, opt.threads, opt.seed = int(samples), int(threads), int(seed)
    opt.max_memory = _max_memory(max_memory)
    opt.progress = cb
    keep = None
    if light is None:
        L = None
    elif isinstance(light, (int, np.integer)) and not isinstance(light, bool):
        nl = _size()
        arr = _accel_lights(acc._h, ctypes.byref(nl))
        if not 0 <= light < nl.value:
            raise ValueError("light: %d is not the index of one of the scene's %d lights" % (light, nl.value))
        L = ctypes.byref(arr[int(light)])
    else:
        Ls, keep = _light_struct(light)
        L = ctypes.byref(Ls)
    V, S = np.empty(n, np.float32), np.empty(n, np.float32)
    F = np.empty(n, np.uint16)
    err = _errbuf()
    st = _vis_points(acc._h, L, ctypes.byref(pts), ctypes.byref(opt), V.ctypes.data, S.ctypes.data, F.ctypes.data,
                     None, err, len(err))
    del keep
    if st != 0:
        raise Error(st, err.value.decode(errors="replace"))
    return (V, S, F) if return_front else (V, S)


def _planes(ptr, n_lights, h, w, shape=None):
    """n_lights planes of h x w (light l at ptr + l*h*w) as copies."""
    if not ptr:
        return None
    return np.ctypeslib.as_array(ptr, shape=(n_lights, h, w) + (shape or ())).copy()


def render(scene, method=None, samples=0, width=0, height=0, pattern="grid", seed=0, threads=0, isa="auto",
           primary=None, consistent_primary=False, progress=None, max_memory=0, aa=1, aa_split=False, shading="standard"):
    """A frame (ms_render): dict of vis, shadow (H, W) float32 (-1 where the primary ray missed), front
    (H, W) uint16 (all of light 0), rgb (H, W, 3) linear radiance summed over the lights, exposure, stats
    (a dict), and lights: one dict per light of the scene with its vis, shadow, shadow_spec and front
    (H, W). primary: the primary visibility method (docs/primary.md; None: the method's pairing).
    progress: fn(fraction) -> truthy to cancel (Error with status 3). max_memory: the memory budget in bytes
    (0: the library's default); a frame over it is refused before allocating (Error with status 6). aa: primary
    samples per pixel (1, 4, 9 or 16; docs/antialiasing.md), the planes then their box-filtered average per
    pixel; aa_split: the pixel's light samples split among them instead of all for each. shading: "standard" or
    "diffuse" (base colour x E x S / pi alone: what a baked lightmap can show; docs/shading.md)."""
    if not isinstance(scene, Scene):
        raise ValueError("scene: expected a Scene (load() or default_scene()), got %s" % type(scene).__name__)
    opt = _RenderOptions()
    opt.method = method.encode() if method else None
    opt.primary = primary.encode() if primary else None
    opt.consistent_primary = 1 if consistent_primary else 0
    opt.pattern = _choice("pattern", pattern, _PATTERNS)
    opt.samples, opt.width, opt.height, opt.threads, opt.seed = int(samples), int(width), int(height), int(threads), int(seed)
    opt.isa = _choice("isa", isa, _ISAS)
    opt.max_memory = _max_memory(max_memory)
    if isinstance(aa, bool) or not isinstance(aa, int) or aa not in (1, 4, 9, 16):
        raise ValueError("aa: expected 1, 4, 9 or 16 primary samples per pixel, got %r" % (aa,))
    opt.aa, opt.aa_split = aa, 1 if aa_split else 0
    opt.shading = _choice("shading", shading, _SHADINGS)
    cb = _progress_cancel(progress)
    opt.progress = cb
    fr, err = _Frame(), _errbuf()
    rc = _render(ctypes.byref(scene._s), ctypes.byref(opt), ctypes.byref(fr), err, len(err))
    if rc != 0:
        raise Error(rc if rc > 0 else -1, err.value.decode(errors="replace"))
    try:
        W, H, nl = fr.width, fr.height, max(1, fr.n_lights)
        vis, shadow = _planes(fr.vis, nl, H, W), _planes(fr.shadow, nl, H, W)
        front, spec = _planes(fr.front, nl, H, W), _planes(fr.shadow_spec, nl, H, W)
        out = {
            "vis": vis[0], "shadow": shadow[0], "front": front[0],
            "rgb": np.ctypeslib.as_array(fr.rgb, shape=(H, W, 3)).copy(),
            "exposure": float(fr.exposure),
            "stats": _stats_dict(fr.stats),
            "lights": [{"vis": vis[l], "shadow": shadow[l], "front": front[l],
                        "shadow_spec": spec[l] if spec is not None else shadow[l]} for l in range(nl)],
        }
    finally:
        _frame_free(ctypes.byref(fr))
    return out


def _stats_dict(st):
    d = {n: getattr(st, n) for n, _ in st._fields_ if not n.startswith("_pad") and n not in ("counter_name", "counter")}
    for k in ("method", "pattern", "kernel_isa", "traversal_isa", "primary"):
        d[k] = d[k].decode() if d[k] else None
    d["counters"] = {st.counter_name[i].decode(): int(st.counter[i]) for i in range(st.n_counters)}
    return d


def light_irradiance(light, point, normal):
    """Exact unshadowed irradiance per unit emitted radiance at point with unit normal (light: a dict as
    in Scene.lights; a sphere's irradiance through its outline disk seen from point)."""
    p = (_f * 3)(*[float(x) for x in _array("point", [point], 3, "float")[0]])
    n = (_f * 3)(*[float(x) for x in _array("normal", [normal], 3, "float")[0]])
    L, keep = _light_struct(light)
    try:
        return float(_irradiance(ctypes.byref(L), p, n))
    finally:
        del keep


def bake(scene, size=1024, uv=1, method=None, samples=1024, pattern="grid", seed=0, threads=0, isa="auto",
         dilate=4, padding=0, accel=None, progress=None, max_memory=0, texel_density=0.0, uv_cache=None,
         uv_packing="default"):
    """A lightmap (ms_bake): dict of irradiance (size, size, 3) summed over the lights, vis and shadow
    (size, size; light 0; -1 where nothing reached), front, position and normal (size, size, 3; NaN off
    the triangles; position in the scene's frame: add scene.origin for world coordinates), triangle (size, size; NO_TRIANGLE off them), uv (n_triangles, 3, 2) the UVs baked
    into, lights: one dict per light with its vis, shadow and front, and counts and timings. uv: the UV
    set (0..3) or None for xatlas everywhere; dilate 0: none; padding: texels between the charts' bilinear
    footprints (0: touching, never sharing a texel; 2 or more for an engine that mipmaps); progress: fn(fraction) -> truthy to cancel
    (Error with status 3). texel_density: texels per world unit on as many pages as it takes (the images
    then hold the pages stacked: (size * pages, size), page p in rows p*size..; "page" the page of each
    triangle, "page_fill" each page's fraction of texel centres on triangles); uv_cache: a UV cache file
    to take the UVs from when it matches (docs/baking.md); uv_packing (ms_bake_options.uv_packing): "default"
    (the file's UVs as they are where they serve, else "islands"), "islands" (each kept layout's islands
    packed one by one) or "regions" (each object's layout moved whole: one scale-offset per object)."""
    if not isinstance(scene, Scene):
        raise ValueError("scene: expected a Scene (load() or default_scene()), got %s" % type(scene).__name__)
    if accel is not None and not isinstance(accel, Accel):
        raise ValueError("accel: expected an Accel of this scene or None, got %s" % type(accel).__name__)
    if uv is not None and (not isinstance(uv, (int, np.integer)) or not 0 <= uv < MAX_UV_SETS):
        raise ValueError("uv: expected a UV set in [0, %d) or None (xatlas), got %r" % (MAX_UV_SETS, uv))
    o = _BakeOptions()
    cb = _progress_cancel(progress)
    o.points.method = method.encode() if method else None
    o.points.pattern, o.points.isa = _choice("pattern", pattern, _PATTERNS), _choice("isa", isa, _ISAS)
    o.points.samples, o.points.threads, o.points.seed = int(samples), int(threads), int(seed)
    o.points.progress = cb
    o.points.max_memory = _max_memory(max_memory)
    o.size = int(size)
    o.uv_set = -1 if uv is None else int(uv)
    o.dilate = -1 if dilate == 0 else int(dilate)
    o.padding = int(padding)
    o.texel_density = float(texel_density)
    o.uv_packing = _choice("uv_packing", uv_packing, _UV_PACKINGS)
    cache = os.fsencode(uv_cache) if uv_cache is not None else None
    o.uv_cache = cache
    lm, err = _Lightmap(), _errbuf()
    st = _bake(ctypes.byref(scene._s), accel._h if accel is not None else None, ctypes.byref(o), ctypes.byref(lm),
               err, len(err))
    if st != 0:
        raise Error(st, err.value.decode(errors="replace"))
    try:
        n, h, nl = lm.frame.width, lm.frame.height, max(1, lm.frame.n_lights)
        a = np.ctypeslib.as_array
        vis, shadow, front = (_planes(p, nl, h, n) for p in (lm.frame.vis, lm.frame.shadow, lm.frame.front))
        out = {
            "irradiance": a(lm.frame.rgb, shape=(h, n, 3)).copy(),
            "vis": vis[0], "shadow": shadow[0], "front": front[0],
            "lights": [{"vis": vis[l], "shadow": shadow[l], "front": front[l]} for l in range(nl)],
            "position": a(lm.position, shape=(h, n, 3)).copy(),
            "normal": a(lm.normal, shape=(h, n, 3)).copy(),
            "triangle": a(lm.triangle, shape=(h, n)).copy(),
            "pages": int(lm.pages),
            "page": a(lm.page, shape=(lm.n_tris,)).copy() if lm.n_tris else np.zeros(0, np.uint32),
            "page_fill": [float(lm.page_fill[p]) for p in range(lm.pages)] if lm.page_fill else [],
            "object_uv_set": [int(lm.object_uv_set[o]) for o in range(lm.n_objects)],
            "charts": int(lm.charts),
            "uv_cached": bool(lm.uv_cached),
            "uv": a(lm.uv, shape=(lm.n_tris, 3, 2)).copy() if lm.n_tris else np.zeros((0, 3, 2), np.float32),
            "texels": int(lm.texels),
            "unwrapped_triangles": int(lm.unwrapped_tris),
            "stats": _stats_dict(lm.frame.stats),
        }
    finally:
        _lightmap_free(ctypes.byref(lm))
    return out
