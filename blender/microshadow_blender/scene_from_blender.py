"""The evaluated Blender scene as microshadow's arrays (microshadow.scene_from_arrays): meshes with their
modifiers applied in world space, split normals, one UV map, base colours, lights and the camera.

Every mesh-like object the depsgraph shows (and every instance of one) is an object of its own for the
bake's regions. Only bpy-facing code lives here; the unit conversions are in light_units.py.
"""
import math

import numpy as np

from . import light_units

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}
MAX_LIGHTS = 64
LIGHTMAP_UV = "microshadow_lightmap"   # the UV map a bake writes back (bake.py)


class SceneError(ValueError):
    """What the add-on cannot hand to microshadow (no triangles, no light, a bad light): one line."""


class BlenderObject:
    """Where an object's triangles are in the arrays and how they map back to its mesh's loops."""

    def __init__(self, name, original, first, count, loops, has_uv, same_topology):
        self.name, self.original, self.first, self.count = name, original, first, count
        self.loops = loops                  # (count, 3) loop index of each triangle corner in the evaluated mesh
        self.has_uv = has_uv
        self.same_topology = same_topology  # the evaluated mesh's loops are the original mesh's


def flip_v(uv):
    """Blender's UVs (v upwards) as glTF's (v downwards) and back: the add-on hands microshadow glTF's, so that
    a bake equals the command line's bake of the exported glTF, and the lightmap's row 0 is the top of the
    image (v = 1 in Blender)."""
    out = np.array(uv, np.float32, copy=True)
    out[..., 1] = 1.0 - out[..., 1]
    return out


class Collected:
    """What collect() found: arrays (scene_from_arrays' keyword arguments), objects (a BlenderObject per
    object, in the arrays' order), warnings (lines to report), light_names (the Blender light of each
    microshadow light, None for an emissive mesh's triangles), material_names (of arrays["materials"])."""

    def __init__(self, arrays, objects, warnings, light_names, material_names):
        self.arrays, self.objects, self.warnings, self.light_names = arrays, objects, warnings, light_names
        self.material_names = material_names


def _material_params(mat, warnings):
    """base colour (linear RGBA), metallic, roughness and emission (linear RGB radiance) of a material: its
    Principled BSDF's inputs where the node tree has one, else the viewport colour."""
    base, metallic, roughness, emission = (0.8, 0.8, 0.8, 1.0), 0.0, 0.5, (0.0, 0.0, 0.0)
    if mat is None:
        return base, metallic, roughness, emission
    base, metallic, roughness = tuple(mat.diffuse_color), float(mat.metallic), float(mat.roughness)
    if mat.use_nodes and mat.node_tree:
        for node in mat.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                i = node.inputs
                base = tuple(i["Base Color"].default_value)
                metallic, roughness = float(i["Metallic"].default_value), float(i["Roughness"].default_value)
                if i["Base Color"].is_linked:
                    warnings.append("material %r: its base colour is a texture or node network; microshadow "
                                    "shades with the colour of the socket" % mat.name)
                e = np.array(i["Emission"].default_value[:3]) * float(i["Emission Strength"].default_value)
                emission = tuple(e)
                break
            if node.type == "BSDF_DIFFUSE":
                base, metallic, roughness = tuple(node.inputs["Color"].default_value), 0.0, 1.0
                break
            if node.type == "EMISSION":
                e = np.array(node.inputs["Color"].default_value[:3]) * float(node.inputs["Strength"].default_value)
                emission = tuple(e)
                base = (0.0, 0.0, 0.0, 1.0)
                break
    return base, metallic, roughness, emission


def _camera(cam_obj, width, height, warnings):
    cam = cam_obj.data
    M = np.array(cam_obj.matrix_world, np.float64)
    eye, fwd, up = M[:3, 3], -M[:3, 2], M[:3, 1]
    fwd = fwd / np.linalg.norm(fwd)
    d = {"eye": tuple(eye), "target": tuple(eye + fwd), "up": tuple(up / np.linalg.norm(up)),
         "width": int(width), "height": int(height)}
    if abs(cam.shift_x) > 1e-6 or abs(cam.shift_y) > 1e-6:
        warnings.append("camera %r: lens shift is not modelled (rendered unshifted)" % cam_obj.name)
    horizontal = cam.sensor_fit == "HORIZONTAL" or (cam.sensor_fit == "AUTO" and width >= height)
    if cam.type == "ORTHO":
        d["type"] = "orthographic"
        d["ortho_height"] = cam.ortho_scale * (height / width if horizontal else 1.0)
    elif cam.type == "PANO":
        kind = getattr(getattr(cam, "cycles", None), "panorama_type", "EQUIRECTANGULAR")
        if kind == "FISHEYE_EQUIDISTANT":
            d["type"], d["fov"] = "fisheye", math.degrees(cam.cycles.fisheye_fov)
        else:
            if kind != "EQUIRECTANGULAR":
                warnings.append("camera %r: panorama %s is rendered as equirectangular" % (cam_obj.name, kind))
            d["type"] = "latlong"
    else:
        d["type"] = "pinhole"
        if horizontal:
            half_w = cam.sensor_width / (2 * cam.lens)
            d["fov_y"] = math.degrees(2 * math.atan(half_w * height / width))
        else:
            sensor = cam.sensor_width if cam.sensor_fit == "AUTO" else cam.sensor_height
            d["fov_y"] = math.degrees(2 * math.atan(sensor / (2 * cam.lens)))
    return d


def _light_params(light):
    p = {"color": tuple(light.color), "energy": float(light.energy)}
    if light.type == "AREA":
        p.update(shape=light.shape, size=light.size, size_y=light.size_y,
                 spread=float(getattr(light, "spread", math.pi)))
    elif light.type in ("POINT", "SPOT"):
        p["shadow_soft_size"] = light.shadow_soft_size
        if light.type == "SPOT":
            p["spot_size"] = light.spot_size
    elif light.type == "SUN":
        p["angle"] = light.angle
    return p


def collect(depsgraph, ms, uv_map="", receivers=None, camera=None, width=0, height=0, skip_hidden_render=False):
    """The scene as a Collected.

    ms: the microshadow module (library.module()). uv_map: the UV map baked into (an object without it gets NaN UVs: microshadow charts it); "" takes each
    object's active render UV map. receivers: names of the objects baked (the rest occlude only); None: all.
    camera: the camera object for frames (None for bakes)."""
    warnings, tris, nors, uvs, objs, mats_of_tri, lights, objects = [], [], [], [], [], [], [], []
    materials, material_index, light_names = [], {}, []
    emissive = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if skip_hidden_render and ob.original.hide_render:
            continue
        if ob.type == "LIGHT":
            try:
                lights += light_units.convert_light(ob.name, ob.data.type, _light_params(ob.data),
                                                    [list(r) for r in inst.matrix_world], warnings)
                light_names.append(ob.name)
            except light_units.LightError as e:
                raise SceneError(str(e))
            continue
        if ob.type not in GEOMETRY_TYPES:
            continue
        mesh = ob.to_mesh()
        if mesh is None:
            continue
        try:
            mesh.calc_loop_triangles()
            n = len(mesh.loop_triangles)
            if n == 0:
                continue
            M = np.array(inst.matrix_world, np.float64)
            co = np.empty(len(mesh.vertices) * 3, np.float32)
            mesh.vertices.foreach_get("co", co)
            co = co.reshape(-1, 3).astype(np.float64) @ M[:3, :3].T + M[:3, 3]
            lt_loops = np.empty(n * 3, np.int32)
            mesh.loop_triangles.foreach_get("loops", lt_loops)
            lt_verts = np.empty(n * 3, np.int32)
            mesh.loop_triangles.foreach_get("vertices", lt_verts)
            mi = np.empty(n, np.int32)
            mesh.loop_triangles.foreach_get("material_index", mi)
            if hasattr(mesh, "calc_normals_split"):
                mesh.calc_normals_split()
            ln = np.empty(len(mesh.loops) * 3, np.float32)
            mesh.loops.foreach_get("normal", ln)
            nm = np.linalg.inv(M[:3, :3]).T
            ln = ln.reshape(-1, 3).astype(np.float64) @ nm.T
            ln /= np.maximum(np.linalg.norm(ln, axis=1, keepdims=True), 1e-30)
            layer = None
            if uv_map:
                layer = mesh.uv_layers.get(uv_map)
            else:  # the active render map, never the lightmap UVs a bake wrote (a re-bake starts as the first did)
                for l in mesh.uv_layers:
                    if l.active_render and l.name != LIGHTMAP_UV:
                        layer = l
            if layer is not None:
                uv = np.empty(len(mesh.loops) * 2, np.float32)
                layer.data.foreach_get("uv", uv)
                uv = uv.reshape(-1, 2)[lt_loops].reshape(n, 3, 2)
                uv = flip_v(uv)
            else:
                uv = np.full((n, 3, 2), np.nan, np.float32)
            slot_mat = []
            for slot in ob.material_slots:
                m = slot.material
                if m is None:
                    slot_mat.append(0xFFFFFFFF)
                    continue
                key = m.name
                if key not in material_index:
                    base, metallic, rough, emission = _material_params(m, warnings)
                    material_index[key] = len(materials)
                    materials.append({"base_color": base, "metallic": metallic, "roughness": rough,
                                      "emission": emission, "name": m.name})
                slot_mat.append(material_index[key])
            tmat = np.array([slot_mat[i] if i < len(slot_mat) else 0xFFFFFFFF for i in mi], np.uint32) \
                if slot_mat else np.full(n, 0xFFFFFFFF, np.uint32)
            # one material after another in the object (stable): the order of the glTF primitives the export
            # writes, so that the command line reads the triangles in this order (and charts them alike)
            order = np.argsort(tmat, kind="stable")
            tmat, lt_loops, lt_verts = tmat[order], lt_loops.reshape(n, 3)[order].ravel(), \
                lt_verts.reshape(n, 3)[order].ravel()
            uv = uv[order]
            t = co[lt_verts].reshape(n, 3, 3)
            for k in np.unique(tmat):
                if k != 0xFFFFFFFF and any(materials[k]["emission"]):
                    emissive.append((ob.name, materials[k]["name"], t[tmat == k], materials[k]["emission"]))
            same = ob.original.type == "MESH" and not inst.is_instance and \
                len(mesh.loops) == len(ob.original.data.loops)
            objects.append(BlenderObject(ob.name, None if inst.is_instance else ob.original, sum(len(x) for x in tris), n,
                                         lt_loops.reshape(n, 3), layer is not None, same))
            tris.append(t.astype(np.float32))
            nors.append(ln[lt_loops].reshape(n, 3, 3).astype(np.float32))
            uvs.append(uv)
            objs.append(np.full(n, len(objects) - 1, np.uint32))
            mats_of_tri.append(tmat)
        finally:
            ob.to_mesh_clear()
    if not tris:
        raise SceneError("the scene has no visible mesh")
    for obname, matname, t, e in emissive:
        more = light_units.emissive_triangles(obname, t, e)
        if len(lights) + len(more) > MAX_LIGHTS:
            raise SceneError("object %r: material %r emits light from %d triangles (%d lights, both sides); microshadow "
                             "takes at most %d lights in all: use an area light instead" %
                             (obname, matname, len(t), len(more), MAX_LIGHTS))
        lights += more
        light_names += [None] * len(more)
    if not lights:
        raise SceneError("the scene has no light microshadow can use (area, point, spot, sun or an emissive mesh)")
    if len(lights) > MAX_LIGHTS:
        raise SceneError("the scene has %d lights; microshadow takes at most %d" % (len(lights), MAX_LIGHTS))
    scale = None
    if receivers is not None:
        # an instance (particles, collection instances) occludes but is never baked: it has no mesh of its own
        scale = np.array([1.0 if o.original is not None and o.name in receivers else 0.0 for o in objects], np.float32)
    arrays = {"triangles": np.concatenate(tris), "normals": np.concatenate(nors), "uvs": [np.concatenate(uvs)],
              "objects": np.concatenate(objs), "lights": lights,
              "materials": [{k: m[k] for k in ("base_color", "metallic", "roughness")} for m in materials] or None,
              "triangle_materials": np.concatenate(mats_of_tri) if materials else None,
              "lightmap_scale": scale}
    if camera is not None:
        arrays["camera"] = _camera(camera, width, height, warnings)
    else:  # bakes need none, the exported scene file one
        arrays["camera"] = ms.default_camera(arrays["triangles"])
    return Collected(arrays, objects, warnings, light_names, [m["name"] for m in materials])
