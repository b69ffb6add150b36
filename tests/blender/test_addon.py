"""The Blender add-on (blender/microshadow_blender) in Debian's Blender, headless:

    blender -b --factory-startup --python-exit-code 1 --python test_addon.py -- CLI OUTDIR

against independent answers: Cycles' render of a lit plane for the light units (each light type), the
command line's bake and frame of the scene the add-on exports (texel for texel and pixel for pixel), and
the checks a user meets (a cancelled bake writes nothing, a light of zero size is one clear report).
The scene is built here: a ground, objects with and without a UV map, area lights of every shape, a sun.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "blender")))
import microshadow_blender as addon  # noqa: E402
from microshadow_blender import bake, export, scene_from_blender  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
CLI = ARGS[0] if ARGS else "microshadow"
OUT = ARGS[1] if len(ARGS) > 1 else tempfile.mkdtemp(prefix="ms_blender_")


def run(args):
    """A program of this build (the CLI) or node, without the sanitizer runtime a sanitized build preloads into
    Blender: the CLI links its own, and two ASan runtimes in one process refuse to start."""
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    return subprocess.run(args, capture_output=True, text=True, env=env)


def read_pfm(path):
    """A PFM image (the CLI's --vis and --shadow) as float32 rows from the top."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = (int(x) for x in f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), "<f4" if scale < 0 else ">f4")
    ch = 3 if kind == b"PF" else 1
    return data.reshape(h, w, ch)[::-1].squeeze()  # PFM stores the bottom row first


def files_in(folder):
    out = {}
    for name in os.listdir(folder):
        with open(os.path.join(folder, name), "rb") as f:
            out[name] = f.read()
    return out


def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for coll in (bpy.data.meshes, bpy.data.lights, bpy.data.cameras, bpy.data.materials, bpy.data.images):
        for x in list(coll):
            if x.users == 0 or coll is bpy.data.images:
                coll.remove(x)


def diffuse_material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = tuple(color) + (1.0,)
    o = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(d.outputs[0], o.inputs[0])
    return mat


def add_light(kind, name="L", location=(0.5, 0.3, 2.5), rotation=(0.3, 0.2, 0.0), **data):
    ld = bpy.data.lights.new(name, kind)
    for k, v in data.items():
        setattr(ld, k, v)
    ob = bpy.data.objects.new(name, ld)
    bpy.context.scene.collection.objects.link(ob)
    ob.location, ob.rotation_euler = location, rotation
    return ob


def add_camera(location, rotation, ortho_scale=None, lens=None):
    cam = bpy.data.cameras.new("cam")
    if ortho_scale:
        cam.type, cam.ortho_scale = "ORTHO", ortho_scale
    if lens:
        cam.lens = lens
    ob = bpy.data.objects.new("cam", cam)
    bpy.context.scene.collection.objects.link(ob)
    ob.location, ob.rotation_euler = location, rotation
    bpy.context.scene.camera = ob
    return ob


def build_bake_scene():
    """A ground (its own UV map), a cube (UV map), an ico sphere without a UV map on a plinth, a monkey turned
    (UV map), each kind of area light and a sun."""
    clear_scene()
    sc = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, 0))
    bpy.context.active_object.name = "ground"
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-1.2, 0.4, 0.5))
    bpy.context.active_object.name = "cube"
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.6, location=(1.2, -0.3, 0.8))
    ico = bpy.context.active_object
    ico.name = "ico"
    while ico.data.uv_layers:
        ico.data.uv_layers.remove(ico.data.uv_layers[0])
    bpy.ops.mesh.primitive_monkey_add(size=0.8, location=(0.2, 1.4, 0.6), rotation=(0.2, 0.0, 0.7))
    bpy.context.active_object.name = "monkey"
    bpy.ops.object.shade_smooth()
    add_light("AREA", "square", (0.5, 0.3, 3.0), (0.2, 0.1, 0.0), shape="SQUARE", size=1.0, energy=150)
    add_light("AREA", "rectangle", (-2.0, -1.0, 2.5), (0.4, -0.3, 0.2), shape="RECTANGLE", size=1.2, size_y=0.4,
              energy=120)
    add_light("AREA", "disk", (2.0, 1.5, 2.2), (-0.3, 0.5, 0.0), shape="DISK", size=0.8, energy=100)
    add_light("AREA", "ellipse", (0.0, -2.0, 2.8), (0.5, 0.0, 0.3), shape="ELLIPSE", size=1.4, size_y=0.5, energy=100)
    add_light("SUN", "sun", (0, 0, 5), (0.6, 0.3, 0.0), angle=math.radians(3.0), energy=2.0)
    add_camera((5.0, -6.0, 4.5), (math.radians(60), 0, math.radians(40)))
    sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 96, 64, 100
    st = sc.microshadow
    for k in st.bl_rna.properties.keys():  # each test starts from the defaults
        if k not in ("rna_type", "name"):
            st.property_unset(k)
    st.samples, st.bake_size, st.threads = "256", 256, 2
    for ob in sc.objects:
        ob.select_set(ob.name in ("ground", "cube", "ico", "monkey"))
    bpy.context.view_layer.objects.active = bpy.data.objects["cube"]


class LightUnitsTest(unittest.TestCase):
    """Blender's light units through the add-on against Cycles: a white diffuse plane seen from above by an
    orthographic camera (below the light), each light alone; the mean of the frames within 2% and the pixels
    correlated (Cycles at 1024 samples per pixel, direct light, no denoising)."""

    CASES = [("square", "AREA", dict(shape="SQUARE", size=1.0, energy=100)),
             ("rectangle", "AREA", dict(shape="RECTANGLE", size=1.5, size_y=0.5, energy=100)),
             ("disk", "AREA", dict(shape="DISK", size=1.2, energy=100)),
             ("ellipse", "AREA", dict(shape="ELLIPSE", size=1.5, size_y=0.6, energy=100)),
             ("point", "POINT", dict(shadow_soft_size=0.1, energy=200)),
             ("sun", "SUN", dict(angle=math.radians(10), energy=3.0))]

    def render(self, engine):
        sc = bpy.context.scene
        sc.render.engine = engine
        if engine == "CYCLES":
            sc.cycles.samples, sc.cycles.use_denoising, sc.cycles.max_bounces = 1024, False, 0
            sc.cycles.use_adaptive_sampling, sc.cycles.device = False, "CPU"
            sc.cycles.filter_width = 0.01  # each pixel sampled at its centre, as microshadow's aa 1 is
        else:
            sc.microshadow.shading, sc.microshadow.aa = "diffuse", "1"
        sc.render.filepath = os.path.join(OUT, "units_%s.exr" % engine)
        sc.render.image_settings.file_format = "OPEN_EXR"
        sc.render.image_settings.color_depth = "32"
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(sc.render.filepath, check_existing=False)
        px = np.array(img.pixels[:], np.float64).reshape(img.size[1], img.size[0], 4)[..., :3]
        bpy.data.images.remove(img)
        return px

    def test_units_match_cycles(self):
        clear_scene()
        sc = bpy.context.scene
        white = diffuse_material("white", (1, 1, 1))
        bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, 0))
        bpy.context.active_object.data.materials.append(white)
        # a small block between the plane and the lights: a shadow for the pixels to correlate on
        bpy.ops.mesh.primitive_cube_add(size=0.25, location=(0.45, -0.1, 0.3))
        bpy.context.active_object.data.materials.append(white)
        add_camera((0.3, -0.2, 1.0), (0, 0, 0), ortho_scale=2.0)
        sc.render.resolution_x = sc.render.resolution_y = 32
        sc.render.resolution_percentage = 100
        sc.world = bpy.data.worlds.new("black")
        sc.world.color = (0, 0, 0)
        for name, kind, data in self.CASES:
            with self.subTest(light=name):
                for ob in [o for o in sc.objects if o.type == "LIGHT"]:
                    bpy.data.objects.remove(ob)
                add_light(kind, name, **data)
                cyc, ms = self.render("CYCLES"), self.render("MICROSHADOW")
                ratio = ms.mean() / cyc.mean()
                corr = np.corrcoef(ms[..., 1].ravel(), cyc[..., 1].ravel())[0, 1]
                print("light units %-9s: microshadow / Cycles %.4f, correlation %.4f" % (name, ratio, corr))
                self.assertGreater(cyc.mean(), 0.05)
                self.assertAlmostEqual(ratio, 1.0, delta=0.02)
                self.assertGreater(corr, 0.95)
        # an emissive mesh (an Emission shader on a quad facing down): its triangles as lights, both sides
        for ob in [o for o in sc.objects if o.type == "LIGHT"]:
            bpy.data.objects.remove(ob)
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.4, 0.2, 2.0), rotation=(math.pi, 0, 0))
        em = bpy.data.materials.new("emit")
        em.use_nodes = True
        nt = em.node_tree
        nt.nodes.clear()
        e, o = nt.nodes.new("ShaderNodeEmission"), nt.nodes.new("ShaderNodeOutputMaterial")
        e.inputs["Strength"].default_value, e.inputs["Color"].default_value = 5.0, (1.0, 0.8, 0.6, 1.0)
        nt.links.new(e.outputs[0], o.inputs[0])
        bpy.context.active_object.data.materials.append(em)
        cyc, ms = self.render("CYCLES"), self.render("MICROSHADOW")
        ratio = ms.mean((0, 1)) / cyc.mean((0, 1))
        print("light units emissive : microshadow / Cycles %s" % np.round(ratio, 4))
        np.testing.assert_allclose(ratio, 1.0, atol=0.02)


class BakeTest(unittest.TestCase):
    """The bake operator against the command line's bake of the scene the add-on exports (scene.json and a glTF
    binary per object, read by the CLI's own parsers): the irradiance and light 0's S texel for texel."""

    def test_bake_equals_cli(self):
        build_bake_scene()
        sc = bpy.context.scene
        folder = os.path.join(OUT, "bake")
        sc.microshadow.bake_output = folder
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        irr = np.array(bpy.data.images["microshadow_irradiance"].pixels[:], np.float32).reshape(256, 256, 4)[..., :3]
        self.assertTrue(os.path.isfile(os.path.join(folder, "microshadow_irradiance.exr")))
        names = ["square", "rectangle", "disk", "ellipse", "sun"]
        for n in names:
            self.assertTrue(os.path.isfile(os.path.join(folder, "microshadow_shadowmask_%s.exr" % n)), n)
        # the lightmap UVs went back onto the meshes
        self.assertIn(bake.LIGHTMAP_UV, bpy.data.objects["ico"].data.uv_layers)
        exported = os.path.join(OUT, "exported")
        self.assertEqual(bpy.ops.microshadow.export_scene(directory=exported), {"FINISHED"})
        # each exported object is valid glTF (the Khronos validator, when scripts/install-deps.sh installed it)
        viewer = os.path.normpath(os.path.join(HERE, "..", "..", "viewer"))
        if os.path.isdir(os.path.join(viewer, "node_modules", "gltf-validator")):
            for name in sorted(f for f in os.listdir(os.path.join(exported, "objects")) if f.endswith(".glb")):
                r = run(["node", os.path.join(viewer, "validate.mjs"), os.path.join(exported, "objects", name),
                                    "--max-warnings", "0"])
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        else:
            print("bake: the glTF validator is not installed (viewer/node_modules): the exported files not validated")
        cli_exr, cli_s = os.path.join(OUT, "cli_bake.exr"), os.path.join(OUT, "cli_s.exr")
        r = run([CLI, "bake", os.path.join(exported, "scene.json"), "--uv", "0", "--size", "256", "--samples",
                            "256", "--padding", "2", "--threads", "2", "--quiet", "-o", cli_exr])
        self.assertEqual(r.returncode, 0, r.stderr)
        img = bpy.data.images.load(cli_exr, check_existing=False)
        # Blender loads the EXR's rows (the lightmap's, from its top) as it shows the add-on's images
        cli = np.array(img.pixels[:], np.float32).reshape(img.size[1], img.size[0], 4)[..., :3]
        peak = float(irr.max())
        self.assertGreater(peak, 0.1)
        diff = np.abs(irr - cli)
        print("bake: add-on against CLI: max |difference| %.3g of a peak %.3g, %d texels differ"
              % (diff.max(), peak, int((diff > 0).any(-1).sum())))
        self.assertLessEqual(float(diff.max()), 1e-6 * peak)
        # light 0's S, bit for bit: the CLI's PFM against the add-on's shadowmask image
        s0 = os.path.join(OUT, "cli_s0.pfm")
        r = run([CLI, "bake", os.path.join(exported, "scene.json"), "--uv", "0", "--size", "256", "--samples",
                            "256", "--padding", "2", "--threads", "2", "--quiet", "-o", cli_exr, "--shadow", s0])
        self.assertEqual(r.returncode, 0, r.stderr)
        mask = np.array(bpy.data.images["microshadow_shadowmask_square"].pixels[:], np.float32).reshape(256, 256, 4)[..., 0]
        s = np.maximum(read_pfm(s0), 0.0)[::-1]  # rows from the bottom as Blender's; -1 (not baked) shown as 0
        self.assertGreater(float((s > 0).mean()), 0.3)
        np.testing.assert_allclose(mask, s, rtol=0, atol=1e-6)

    def test_pages(self):
        """A texel density over several pages, each object's UV map moved whole (Whole Layouts): each page's
        images against the CLI's page files of the exported scene (`--uv-regions`) texel for texel, each object's
        page recorded on it."""
        build_bake_scene()
        sc = bpy.context.scene
        sc.microshadow.bake_texel_density, sc.microshadow.bake_size = 28.0, 256
        sc.microshadow.bake_whole_layouts = True
        self.addCleanup(setattr, sc.microshadow, "bake_whole_layouts", False)
        sc.microshadow.bake_output = os.path.join(OUT, "pages")
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        pages = 1 + max(bpy.data.objects[n]["microshadow_lightmap_page"] for n in ("ground", "cube", "ico", "monkey"))
        self.assertGreaterEqual(pages, 2)
        exported = os.path.join(OUT, "exported_pages")
        self.assertEqual(bpy.ops.microshadow.export_scene(directory=exported), {"FINISHED"})
        out = os.path.join(OUT, "cli_pages.exr")
        r = run([CLI, "bake", os.path.join(exported, "scene.json"), "--uv", "0", "--size", "256",
                            "--texel-density", "28", "--uv-regions", "--samples", "256", "--padding", "2", "--threads", "2",
                            "--quiet",
                            "-o", out])
        self.assertEqual(r.returncode, 0, r.stderr)
        for p in range(pages):
            mine = bpy.data.images["microshadow_irradiance" + ("" if p == 0 else ".%d" % p)]
            img = bpy.data.images.load(out if p == 0 else out[:-4] + ".%d.exr" % p, check_existing=False)
            cli = np.array(img.pixels[:], np.float32).reshape(256, 256, 4)[..., :3]
            got = np.array(mine.pixels[:], np.float32).reshape(256, 256, 4)[..., :3]
            self.assertGreater(float(got.max()), 0.1)
            np.testing.assert_array_equal(got, cli, err_msg="page %d" % p)
        self.assertFalse(os.path.exists(out[:-4] + ".%d.exr" % pages))

    def test_lightmap_pack(self):
        """Blender's Lightmap Pack of the selected objects into one UV map: a layout without overlaps, which
        the bake keeps as it is (the baked UVs are that UV map, loop for loop, within the rounding of turning v
        into glTF's and back), whatever object was active."""
        build_bake_scene()
        sc = bpy.context.scene
        sc.microshadow.bake_uv_source, sc.microshadow.bake_uv_map = "LIGHTMAP_PACK", "lightmap"
        sc.microshadow.bake_output = os.path.join(OUT, "packed")
        bpy.context.view_layer.objects.active = bpy.data.objects["square"]  # a light: not a mesh
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        self.assertEqual(bpy.context.mode, "OBJECT")
        self.assertEqual(bpy.context.view_layer.objects.active.name, "square")
        for name in ("ground", "cube", "ico", "monkey"):
            me = bpy.data.objects[name].data
            a, b = (np.empty(2 * len(me.loops), np.float32) for _ in range(2))
            me.uv_layers["lightmap"].data.foreach_get("uv", a)
            me.uv_layers[bake.LIGHTMAP_UV].data.foreach_get("uv", b)
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-6, err_msg=name)  # v turned twice: 1 - (1 - v)


class OperatorsTest(unittest.TestCase):
    """What a user meets around the bake and the frame: Esc, a bad light, F12's passes."""

    def test_cancel_writes_nothing(self):
        build_bake_scene()
        sc = bpy.context.scene
        folder = os.path.join(OUT, "cancelled")
        sc.microshadow.bake_output = folder
        sc.microshadow.bake_size, sc.microshadow.samples = 128, "256"
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        before = files_in(folder)
        self.assertEqual(len(before), 6)
        # a bigger re-bake cancelled at its first progress report (as Esc does in the modal operator)
        sc.microshadow.bake_size, sc.microshadow.samples = 1024, "1024"
        run, got, ms = bake.start(bpy.context)
        run.cancel = True
        run.wait()
        with self.assertRaises(bake.Cancelled):
            bake.finish(bpy.context, run, got, ms)
        after = files_in(folder)
        self.assertEqual(after, before)  # no new, half-written or temporary file; the old ones untouched

    def test_beside_the_blend(self):
        """The default folder (//) is the saved .blend's; an unsaved file gets the images and a line saying why
        no file was written."""
        build_bake_scene()
        sc = bpy.context.scene
        sc.microshadow.bake_size = 64
        self.assertEqual(sc.microshadow.bake_output, "//")
        folder = os.path.join(OUT, "saved")
        os.makedirs(folder)
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(folder, "scene.blend"))
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        self.assertTrue(os.path.isfile(os.path.join(folder, "microshadow_irradiance.exr")))
        bpy.ops.wm.read_homefile(use_empty=True)  # unsaved again
        build_bake_scene()
        bpy.context.scene.microshadow.bake_size = 64
        self.assertEqual(bpy.ops.microshadow.bake(), {"FINISHED"})
        self.assertIn("microshadow_irradiance", bpy.data.images)
        self.assertEqual(bpy.data.images["microshadow_irradiance"].source, "GENERATED")

    def test_zero_size_light(self):
        build_bake_scene()
        bpy.data.objects["rectangle"].data.size_y = 0.0
        with self.assertRaisesRegex(scene_from_blender.SceneError, "'rectangle'.*zero size"):
            bake.start(bpy.context)
        with self.assertRaisesRegex(RuntimeError, "'rectangle'.*zero size"):  # the operator's report, one line
            bpy.ops.microshadow.bake()
        bpy.data.objects["rectangle"].data.size_y = 0.4
        bpy.data.objects["disk"].data.type = "POINT"
        bpy.data.objects["disk"].data.shadow_soft_size = 0.0
        with self.assertRaisesRegex(scene_from_blender.SceneError, "'disk'.*radius 0"):
            bake.start(bpy.context)
        # the render engine reports it and returns: Blender goes on
        sc = bpy.context.scene
        sc.render.engine = "MICROSHADOW"
        with self.assertRaisesRegex(RuntimeError, "'disk'.*radius 0"):
            bpy.ops.render.render()

    def test_render_passes(self):
        """F12 with microshadow: each light's V and S passes (what the compositor writes) equal the CLI's
        frame of the exported scene pixel for pixel."""
        build_bake_scene()
        sc = bpy.context.scene
        sc.render.engine = "MICROSHADOW"
        sc.microshadow.aa = "1"
        exported = os.path.join(OUT, "exported_frame")
        self.assertEqual(bpy.ops.microshadow.export_scene(directory=exported), {"FINISHED"})
        sc.use_nodes = True
        tree = sc.node_tree
        tree.nodes.clear()
        rl, comp = tree.nodes.new("CompositorNodeRLayers"), tree.nodes.new("CompositorNodeComposite")
        W, H = sc.render.resolution_x, sc.render.resolution_y
        fmt = sc.render.image_settings
        fmt.file_format, fmt.color_depth, fmt.exr_codec = "OPEN_EXR", "32", "ZIP"
        sc.render.filepath = os.path.join(OUT, "f12.exr")
        for light in ("square", "rectangle", "disk", "ellipse", "sun"):
            for kind in "VS":
                self.assertIn("%s %s" % (kind, light), rl.outputs, "the passes: %s" % [o.name for o in rl.outputs])
        for light in ("square",):  # the CLI's PFM holds light 0
            for kind, flag in (("V", "--vis"), ("S", "--shadow")):
                name = "%s %s" % (kind, light)
                tree.links.new(rl.outputs[name], comp.inputs["Image"])  # the pass is what F12 writes
                bpy.ops.render.render(write_still=True)
                img = bpy.data.images.load(sc.render.filepath, check_existing=False)
                got = np.array(img.pixels[:], np.float32).reshape(H, W, 4)[::-1, :, 0]  # the file's rows from the top
                bpy.data.images.remove(img)
                out = os.path.join(OUT, "cli_%s_%s.exr" % (kind, light))
                pfm = out[:-4] + ".pfm"
                r = run([CLI, os.path.join(exported, "scene.json"), "--aa", "1", "--samples", "256",
                                    "--threads", "2", "--quiet", "-o", os.path.join(OUT, "cli_frame.png"), flag, pfm])
                self.assertEqual(r.returncode, 0, r.stderr)
                want = np.maximum(read_pfm(pfm), 0.0)
                self.assertGreater(float((want > 0).mean()), 0.2)
                np.testing.assert_allclose(got, want, rtol=0, atol=1e-6, err_msg=name)


if __name__ == "__main__":
    shutil.rmtree(OUT, ignore_errors=True)  # this run's files only (the cancel test compares folders)
    os.makedirs(OUT)
    addon.register()
    res = unittest.main(argv=[sys.argv[0]], exit=False, verbosity=2).result
    sys.exit(0 if res.wasSuccessful() else 1)
