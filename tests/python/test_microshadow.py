"""The Python module against independent answers: the Quad (a 20x20 ground, a 4x4 occluder at y = 2
and a 2x2 light at y = 6, all parallel), where the visible fraction of the light at a ground point is
the light's area outside the occluder's projection onto the light plane, computed here in numpy; frames
and lightmaps through the module; errors, cancellation and dtype handling."""
import ctypes
import json
import os
import sys
import tempfile
import unittest

import numpy as np

import microshadow as ms

OBJ = """v -10 0 -10
v 10 0 -10
v 10 0 10
v -10 0 10
v -2 2 -2
v 2 2 -2
v 2 2 2
v -2 2 2
f 1 4 3
f 1 3 2
f 5 8 7
f 5 7 6
"""
JSON = """{"meshes": [{"file": "quad.obj"}],
 "camera": {"eye": [0, 10, 12], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 48, "height": 48},
 "light": {"corner": [-1, 6, -1], "edge_s": [2, 0, 0], "edge_t": [0, 0, 2], "emission": [1, 1, 1]}}"""


def visible_fraction(p):
    """Exact visible fraction of the light [-1,1]^2 at y = 6 from ground point p (y = 0): the occluder
    [-2,2]^2 at y = 2 projects from p onto the light plane as a square scaled by 6/2 about p."""
    px, pz = p[..., 0], p[..., 2]
    lo_x, hi_x = px + 3.0 * (-2.0 - px), px + 3.0 * (2.0 - px)
    lo_z, hi_z = pz + 3.0 * (-2.0 - pz), pz + 3.0 * (2.0 - pz)
    ox = np.clip(np.minimum(hi_x, 1.0) - np.maximum(lo_x, -1.0), 0.0, None)
    oz = np.clip(np.minimum(hi_z, 1.0) - np.maximum(lo_z, -1.0), 0.0, None)
    return 1.0 - ox * oz / 4.0


class QuadTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(cls.dir.name, "quad.obj"), "w") as f:
            f.write(OBJ)
        path = os.path.join(cls.dir.name, "quad.json")
        with open(path, "w") as f:
            f.write(JSON)
        cls.scene = ms.load(path)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def ground_points(self, n, seed=1):
        rng = np.random.default_rng(seed)
        p = np.zeros((n, 3))
        p[:, 0] = rng.uniform(-6, 6, n)
        p[:, 2] = rng.uniform(-6, 6, n)
        return p, np.tile([0.0, 1.0, 0.0], (n, 1))

    def test_visibility_points_analytic(self):
        pos, nor = self.ground_points(400)
        truth = visible_fraction(pos)
        acc = ms.Accel(self.scene)
        for method in ("scanline", "raytrace"):
            V, S = ms.visibility_points(acc, pos, nor, method=method, samples=1024)
            self.assertEqual(V.dtype, np.float32)
            self.assertEqual(V.shape, (400,))
            err = np.abs(V - truth)
            # a rotated 32x32 lattice against straight shadow edges: about a sample per edge crossing the light
            print(f"{method}: |V - exact| max {err.max():.4f} mean {err.mean():.5f}", file=sys.stderr)
            self.assertLess(err.max(), 0.015, method)
            self.assertLess(err.mean(), 0.001, method)
            # exact where the light is wholly visible or wholly hidden
            self.assertTrue(np.all(V[truth == 1.0] == 1.0))
            self.assertTrue(np.all(V[truth == 0.0] == 0.0))
            self.assertTrue(np.all(S[truth == 1.0] == 1.0))
            self.assertGreater(np.count_nonzero((truth > 0) & (truth < 1)), 40)
        # each point's ground triangle given (0: z > x, 1: below the diagonal): nothing changes on a plane
        tri = np.where(pos[:, 2] > pos[:, 0], 0, 1).astype(np.uint32)
        V2, _ = ms.visibility_points(acc, pos, nor, triangles=tri)
        V1, _ = ms.visibility_points(acc, pos, nor)
        np.testing.assert_array_equal(V1, V2)

    def test_keys_and_order(self):
        pos, nor = self.ground_points(300, seed=2)
        keys = np.stack([np.arange(300), np.full(300, 7)], axis=1)
        V, S = ms.visibility_points(self.scene, pos, nor, keys=keys)
        perm = np.random.default_rng(3).permutation(300)
        Vp, Sp = ms.visibility_points(self.scene, pos[perm], nor[perm], keys=keys[perm])
        np.testing.assert_array_equal(V[perm], Vp)
        np.testing.assert_array_equal(S[perm], Sp)

    def test_light_per_call(self):
        pos, nor = self.ground_points(50, seed=4)
        light = self.scene.light
        light["corner"] = (-1.0, 6.0, 30.0)    # far off to the side: nothing in between
        V, _ = ms.visibility_points(self.scene, pos, nor, light=light)
        self.assertTrue(np.all(V == 1.0))

    def test_errors(self):
        pos, nor = self.ground_points(3)
        pos[1, 0] = np.nan
        with self.assertRaises(ms.Error) as cm:
            ms.visibility_points(self.scene, pos, nor)
        self.assertEqual(cm.exception.status, 1)
        self.assertIn("point 1: position", str(cm.exception))
        with self.assertRaises(ms.Error) as cm:
            ms.visibility_points(self.scene, *self.ground_points(3), method="nonesuch")
        self.assertEqual(cm.exception.status, 4)
        with self.assertRaises(ValueError):
            ms.visibility_points(self.scene, np.zeros((3, 3)), np.zeros((2, 3)))
        with self.assertRaises(ms.Error) as cm:
            ms.load(os.path.join(self.dir.name, "missing.json"))
        self.assertIn("missing.json", str(cm.exception))

    def test_cancel(self):
        pos, nor = self.ground_points(2000)
        seen = []
        with self.assertRaises(ms.Error) as cm:
            ms.visibility_points(self.scene, pos, nor, threads=1, progress=lambda f: seen.append(f) or True)
        self.assertEqual(cm.exception.status, 3)
        self.assertEqual(len(seen), 1)
        seen.clear()
        ms.visibility_points(self.scene, pos, nor, progress=lambda f: seen.append(f) and False)
        self.assertEqual(seen[-1], 1.0)

    def test_memory_budget(self):
        sc = ms.default_scene()
        # over the budget: status 6 and the one line naming need, budget and what would fit; within it: runs
        with self.assertRaises(ms.Error) as cm:
            ms.render(sc, samples=256, width=4096, height=4096, max_memory=16 << 20)
        self.assertEqual(cm.exception.status, 6)
        self.assertIn("but the memory budget is 16.0 MiB", str(cm.exception))
        self.assertIn("would fit", str(cm.exception))
        f = ms.render(sc, samples=256, width=64, height=64, max_memory=16 << 20)
        self.assertLessEqual(f["stats"]["memory_need"], 16 << 20)
        self.assertEqual(f["stats"]["memory_budget"], 16 << 20)
        with self.assertRaises(ms.Error) as cm:
            ms.bake(sc, size=4096, uv=None, samples=256, max_memory=8 << 20)
        self.assertEqual(cm.exception.status, 6)
        with self.assertRaises(ValueError):
            ms.render(sc, max_memory=-1)

    def test_render(self):
        a = ms.render(self.scene, method="scanline", samples=256)
        b = ms.render(self.scene, method="raytrace", samples=256)
        self.assertEqual(a["vis"].shape, (48, 48))
        self.assertEqual(a["rgb"].shape, (48, 48, 3))
        hit = a["vis"] >= 0
        np.testing.assert_array_equal(hit, b["vis"] >= 0)
        self.assertGreater(hit.sum(), 48 * 48 // 2)
        # methods agree sample for sample but for ties: at most one sample in 256 apart
        self.assertLessEqual(np.abs(a["vis"] - b["vis"]).max() * 256, 1.0 + 1e-3)
        self.assertEqual(a["stats"]["method"], "scanline")
        self.assertEqual(a["stats"]["primary"], "bvh")
        # the primary option and its stats fields (the struct tails): the 3D rasterizers and the
        # consistent BVH caster agree bit for bit
        r = ms.render(self.scene, method="scanline", samples=256, primary="3dr-full")
        q = ms.render(self.scene, method="scanline", samples=256, primary="bvh", consistent_primary=True)
        self.assertEqual(r["stats"]["primary"], "3dr-full")
        self.assertGreater(r["stats"]["primary_setups"], 0)
        self.assertGreater(r["stats"]["primary_edge_evals"], 0)
        self.assertGreater(q["stats"]["primary_nodes"], 0)
        np.testing.assert_array_equal(r["vis"], q["vis"])
        self.assertIn("raytrace", ms.method_names())
        # the interleaved pattern: N/16 samples per pixel, filtered; the stats' layout matches the C struct
        c = ms.render(self.scene, method="raytrace", samples=256, pattern="interleaved")
        self.assertEqual(c["stats"]["pattern"], "interleaved")
        self.assertEqual(c["stats"]["samples"], 256)
        self.assertEqual(c["stats"]["samples_per_pixel"], 16)
        self.assertGreater(c["stats"]["filter_s"], 0.0)
        self.assertLessEqual(int(c["front"].max()), 16)
        np.testing.assert_array_equal(hit, c["vis"] >= 0)
        self.assertEqual(b["stats"]["samples_per_pixel"], 256)
        self.assertEqual(b["stats"]["filter_s"], 0.0)
        # shading (the struct's last field): without materials the grey Lambertian is the same picture both ways
        d = ms.render(self.scene, method="raytrace", samples=256, shading="diffuse")
        np.testing.assert_array_equal(d["rgb"], b["rgb"])
        with self.assertRaises(ValueError):
            ms.render(self.scene, shading="glossy")

    def test_camera_types(self):
        # the mirrored ms_camera: a fisheye of 180 degrees (MS_CAMERA_FISHEYE = 2) on the same eye: no ray
        # outside the inscribed circle (V = -1, black), the centre sees the ground
        cam = self.scene._s.camera
        saved = (cam.type, cam.fov)
        try:
            cam.type, cam.fov = 2, 180.0
            f = ms.render(self.scene, method="raytrace", samples=256)
            yy, xx = np.mgrid[0:48, 0:48] + 0.5
            outside = np.hypot(xx - 24, yy - 24) > 24
            self.assertTrue(np.all(f["vis"][outside] == -1))
            self.assertTrue(np.all(f["rgb"][outside] == 0))
            self.assertGreaterEqual(f["vis"][24, 24], 0)
        finally:
            cam.type, cam.fov = saved

    def test_bake(self):
        lm = ms.bake(self.scene, size=64, uv=None, samples=256)
        self.assertEqual(lm["irradiance"].shape, (64, 64, 3))
        self.assertEqual(lm["unwrapped_triangles"], 4)
        on = lm["triangle"] != ms.NO_TRIANGLE
        self.assertEqual(on.sum(), lm["texels"])
        ground = on & (lm["position"][..., 1] == 0.0) & (lm["normal"][..., 1] > 0)
        self.assertGreater(ground.sum(), 500)
        p = lm["position"][ground]
        truth = visible_fraction(p)
        E = lm["irradiance"][ground][:, 1]
        light = self.scene.light
        E0 = np.array([ms.light_irradiance(light, q, (0.0, 1.0, 0.0)) for q in p])
        lit, dark = truth == 1.0, truth == 0.0
        self.assertGreater(lit.sum(), 100)
        self.assertGreater(dark.sum(), 10)
        np.testing.assert_allclose(E[lit], E0[lit], rtol=1e-6)     # S = 1 exactly where all is visible
        self.assertTrue(np.all(E[dark] == 0.0))
        self.assertLess(np.abs(lm["vis"][ground] - truth).max(), 0.1)

    def test_bake_pages(self):
        # a texel density the Quad's 20 m ground and its occluder do not fit on one 64x64 page at: two pages,
        # stacked in the arrays; the ground's irradiance is exact where the analytic visible fraction is 1 or 0
        lm = ms.bake(self.scene, size=64, uv=None, samples=256, texel_density=10.0)
        self.assertEqual(lm["pages"], 2)
        self.assertEqual(lm["irradiance"].shape, (128, 64, 3))
        self.assertEqual(len(lm["page_fill"]), 2)
        self.assertTrue(all(0.0 < f <= 1.0 for f in lm["page_fill"]))
        self.assertEqual(set(lm["page"].tolist()), {0, 1})
        on = lm["triangle"] != ms.NO_TRIANGLE
        rows = np.nonzero(on)[0]
        self.assertTrue(np.all(lm["page"][lm["triangle"][on]] == rows // 64))   # each texel on its triangle's page
        ground = on & (lm["position"][..., 1] == 0.0) & (lm["normal"][..., 1] > 0)
        truth = visible_fraction(lm["position"][ground])
        E = lm["irradiance"][ground][:, 1]
        self.assertTrue(np.all(E[truth == 0.0] == 0.0))
        self.assertGreater((truth == 1.0).sum(), 100)
        self.assertEqual(lm["object_uv_set"], [-1])


LIGHTS = {"rect": {"shape": "rect", "corner": [-1, 6, -1], "edge_s": [2, 0, 0], "edge_t": [0, 0, 2],
                   "emission": [1, 0.5, 0.25]},
          "disk": {"shape": "disk", "center": [0, 6, 0], "normal": [0, -1, 0], "radius": 1.0, "emission": [0.5, 1, 1]},
          "sphere": {"shape": "sphere", "center": [0, 6, 0], "radius": 0.5, "emission": [2, 2, 2]}}


def scene_json(lights):
    return json.dumps({"meshes": [{"file": "quad.obj"}],
                       "camera": {"eye": [0, 10, 12], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60,
                                  "width": 32, "height": 32},
                       "lights": lights, "render": {"samples": 256}})


class LightsTest(unittest.TestCase):
    """Every light shape and several lights in and out: each light's V and S in a many-light frame or bake
    equal those of a scene with that light alone, bit for bit; disk and sphere against the Quad's
    analytic umbra and fully lit regions; a light dict read from a scene gives the same answers as the
    scene's own light."""

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(cls.dir.name, "quad.obj"), "w") as f:
            f.write(OBJ)
        cls.scenes = {}
        for name, lights in [("all", list(LIGHTS.values()))] + [(k, [v]) for k, v in LIGHTS.items()]:
            path = os.path.join(cls.dir.name, name + ".json")
            with open(path, "w") as f:
                f.write(scene_json(lights))
            cls.scenes[name] = ms.load(path)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_triangle_light(self):
        # a triangle from a scene file comes out with its vertices, and goes back in as the same light
        tri = {"shape": "triangle", "vertices": [[-1, 6, -1], [1, 6, -1], [-1, 6, 1]], "emission": [1, 2, 3]}
        path = os.path.join(self.dir.name, "triangle.json")
        with open(path, "w") as f:
            f.write(scene_json([tri]))
        got = ms.load(path).lights[0]
        self.assertEqual(got["shape"], "triangle")
        np.testing.assert_array_equal(np.asarray(got["vertices"], float), np.asarray(tri["vertices"], float))
        np.testing.assert_array_equal(np.asarray(got["emission"], float), np.asarray(tri["emission"], float))
        L, _ = ms._light_struct(got)
        self.assertEqual(ms._light_dict(L)["vertices"], got["vertices"])

    def test_lights_out(self):
        got = self.scenes["all"].lights
        self.assertEqual([l["shape"] for l in got], ["rect", "disk", "sphere"])
        for l, want in zip(got, LIGHTS.values()):
            for k, v in want.items():
                if k != "shape":
                    np.testing.assert_allclose(np.asarray(l[k], float), np.asarray(v, float), rtol=0, atol=1e-6, err_msg=k)
        self.assertEqual(self.scenes["all"].light["shape"], "rect")

    def test_frame_per_light(self):
        many = ms.render(self.scenes["all"], method="raytrace", samples=256)
        self.assertEqual(len(many["lights"]), 3)
        np.testing.assert_array_equal(many["vis"], many["lights"][0]["vis"])
        for i, name in enumerate(LIGHTS):
            one = ms.render(self.scenes[name], method="raytrace", samples=256)
            self.assertEqual(len(one["lights"]), 1)
            for k in ("vis", "shadow", "front"):
                np.testing.assert_array_equal(many["lights"][i][k], one[k], err_msg=name + " " + k)
            self.assertGreater(np.count_nonzero((one["vis"] > 0) & (one["vis"] < 1)), 10, name)

    def ground(self, n=600):
        rng = np.random.default_rng(9)
        p = np.zeros((n, 3))
        p[:, 0], p[:, 2] = rng.uniform(-6, 6, n), rng.uniform(-6, 6, n)
        return p, np.tile([0.0, 1.0, 0.0], (n, 1))

    def test_points_every_shape(self):
        pos, nor = self.ground()
        acc = ms.Accel(self.scenes["all"])
        self.assertEqual(acc.n_lights, 3)
        V_all, S_all = ms.visibility_points(acc, pos, nor, light="all")
        self.assertEqual(V_all.shape, (3, len(pos)))
        # The rays from ground point p to the light form a convex cone; the occluder is the square [-2,2]^2
        # at y = 2. The light is wholly hidden where the cone's section with y = 2 lies inside the square,
        # and wholly visible where the section lies beyond one of the square's edge lines. The section is
        # the hull of the light's points projected from p onto y = 2: the disk's rim, and for the sphere
        # points all over its surface (its outline seen from p is among them), with a margin for sampling.
        u = np.linspace(0, 2 * np.pi, 720, endpoint=False)
        rim = np.stack([np.cos(u), np.zeros_like(u), np.sin(u)], 1) + [0, 6, 0]        # disk: radius 1 at y = 6
        k = np.arange(4000) + 0.5
        th, ph = np.arccos(1 - 2 * k / 4000), np.pi * (1 + 5 ** 0.5) * k
        ball = 0.5 * np.stack([np.sin(th) * np.cos(ph), np.cos(th), np.sin(th) * np.sin(ph)], 1) + [0, 6, 0]
        rect = np.array([[x, 6, z] for x in np.linspace(-1, 1, 41) for z in (-1, 1)] +
                        [[x, 6, z] for z in np.linspace(-1, 1, 41) for x in (-1, 1)])
        outline = {"rect": rect, "disk": rim, "sphere": ball}
        for i, name in enumerate(LIGHTS):
            q = outline[name]
            t = 2.0 / q[None, :, 1]                                          # from p (y = 0) to y = 2
            proj = pos[:, None, [0, 2]] + t[..., None] * (q[None, :, [0, 2]] - pos[:, None, [0, 2]])
            inside = np.all(np.abs(proj) <= 2.0 - 0.02, axis=(1, 2))
            clear = np.any(np.all(proj > 2.02, axis=1) | np.all(proj < -2.02, axis=1), axis=1)
            self.assertGreater(inside.sum(), 5, name)
            self.assertGreater(clear.sum(), 100, name)
            V = V_all[i]
            self.assertTrue(np.all(V[inside] == 0.0), name)
            self.assertTrue(np.all(V[clear] == 1.0), name)
            # the same light by index, by the dict the scene gives back, and from a scene holding it alone
            Vi, Si = ms.visibility_points(acc, pos, nor, light=i)
            Vd, Sd = ms.visibility_points(acc, pos, nor, light=self.scenes["all"].lights[i])
            V1, S1 = ms.visibility_points(self.scenes[name], pos, nor)
            for a, b in ((Vi, V), (Vd, V), (V1, V), (Si, S_all[i]), (Sd, S_all[i]), (S1, S_all[i])):
                np.testing.assert_array_equal(a, b, err_msg=name)

    def test_sun(self):
        # a sun straight overhead over the ground under the square [-2,2]^2 at y = 2: the cone of directions
        # (half-angle 4 degrees) from ground point p meets y = 2 in a disk of radius 2 tan(4 deg) about p; wholly
        # hidden when that disk lies inside the square, wholly visible when it lies outside
        pos, nor = self.ground()
        sun = {"shape": "sun", "direction": (0, 1, 0), "angular_diameter_deg": 8.0, "emission": (2, 2, 2)}
        acc = ms.Accel(self.scenes["all"])
        V, S = ms.visibility_points(acc, pos, nor, light=sun)
        r = 2 * np.tan(np.radians(4.0))
        d = np.max(np.abs(pos[:, [0, 2]]), axis=1)
        inside, clear = d < 2 - r - 0.01, d > 2 + r + 0.01
        self.assertGreater(inside.sum(), 5)
        self.assertGreater(clear.sum(), 100)
        self.assertTrue(np.all(V[inside] == 0.0))
        self.assertTrue(np.all(V[clear] == 1.0))
        Vr, Sr = ms.visibility_points(acc, pos, nor, light=sun, method="raytrace")
        np.testing.assert_array_equal(V, Vr)
        # the dict round trip, and the irradiance of a disk at infinity: pi L sin^2(alpha) cos(theta)
        L, _ = ms._light_struct(sun)
        back = ms._light_dict(L)
        self.assertEqual(back["shape"], "sun")
        self.assertAlmostEqual(back["angular_diameter_deg"], 8.0, places=4)
        np.testing.assert_allclose(back["direction"], (0, 1, 0), atol=1e-7)
        e = ms.light_irradiance(sun, (0, 0, 0), (0, 1, 0))
        self.assertAlmostEqual(e / (np.pi * np.sin(np.radians(4.0)) ** 2), 1.0, places=5)
        with self.assertRaises(ValueError):
            ms.visibility_points(acc, pos, nor, light={"shape": "sun", "direction": (0, 0, 0)})

    def test_bake_per_light(self):
        many = ms.bake(self.scenes["all"], size=32, uv=None, samples=256, method="raytrace")
        self.assertEqual(len(many["lights"]), 3)
        for i, name in enumerate(LIGHTS):
            one = ms.bake(self.scenes[name], size=32, uv=None, samples=256, method="raytrace")
            for k in ("vis", "shadow", "front"):
                np.testing.assert_array_equal(many["lights"][i][k], one[k], err_msg=name + " " + k)

    def test_render_progress(self):
        seen = []
        ms.render(self.scenes["rect"], samples=256, progress=seen.append)
        self.assertGreater(len(seen), 1)
        self.assertEqual(seen[-1], 1.0)
        self.assertTrue(all(a <= b for a, b in zip(seen, seen[1:])))
        # cancelled at the first report: status 3, and no frame
        seen.clear()
        with self.assertRaises(ms.Error) as cm:
            ms.render(self.scenes["all"], samples=256, threads=1, progress=lambda f: seen.append(f) or True)
        self.assertEqual(cm.exception.status, 3)
        self.assertEqual(len(seen), 1)


class StrictTest(unittest.TestCase):
    """Wrong shapes, dtypes, names and keys are ValueErrors that name the argument and what it needs; the
    struct mirrors are checked against the library's own layout."""

    @classmethod
    def setUpClass(cls):
        cls.scene = ms.default_scene()

    def err(self, fn, *needles):
        with self.assertRaises(ValueError) as cm:
            fn()
        for n in needles:
            self.assertIn(n, str(cm.exception))

    def test_arguments(self):
        pos, nor = np.zeros((4, 3)), np.tile([0.0, 1.0, 0.0], (4, 1))
        vp = lambda **kw: ms.visibility_points(self.scene, **{"positions": pos, "normals": nor, **kw})  # noqa: E731
        self.err(lambda: vp(positions=np.zeros((6, 2))), "positions", "(n, 3)", "(6, 2)")
        self.err(lambda: vp(positions=np.zeros(12)), "positions", "(n, 3)")
        self.err(lambda: vp(normals=np.zeros((3, 3))), "normals", "(4, 3)")
        self.err(lambda: vp(positions=np.array([["a", "b", "c"]] * 4)), "positions", "numeric")
        self.err(lambda: vp(triangles=np.zeros(4)), "triangles", "integers")
        self.err(lambda: vp(triangles=np.zeros(3, np.int64)), "triangles", "(4,)")
        self.err(lambda: vp(keys=-np.ones((4, 2), np.int64)), "keys", "[0, 2**32)")
        self.err(lambda: vp(pattern="gird"), "pattern", "'gird'", "did you mean 'grid'")
        self.err(lambda: vp(isa="avx"), "isa", "did you mean")
        self.err(lambda: vp(light=7), "light", "7", "1 lights")
        self.err(lambda: vp(light={"shape": "disk", "center": [0, 5, 0], "radius": 1}), "disk", "'normal'")
        self.err(lambda: vp(light={"shape": "rect", "corner": [0, 5, 0], "edge_s": [1, 0, 0], "edge_t": [0, 0, 1],
                                   "colour": [1, 1, 1]}), "'colour'", "did you mean 'corner'")
        self.err(lambda: vp(light={"shape": "tube"}), "light['shape']", "'tube'")
        self.err(lambda: vp(light={"shape": "sphere", "center": [0, 5, 0], "radius": -1}), "radius > 0")
        self.err(lambda: vp(light={"shape": "rect", "corner": [0, 5, np.nan], "edge_s": [1, 0, 0],
                                   "edge_t": [0, 0, 1]}), "light['corner']", "finite")
        self.err(lambda: ms.render(self.scene, pattern="Grid"), "pattern", "did you mean 'grid'")
        self.err(lambda: ms.bake(self.scene, uv=7), "uv", "[0, 4)")
        self.err(lambda: ms.render("scene.json"), "scene", "expected a Scene")
        # integer positions are numbers: converted, not refused
        V, _ = vp(positions=np.zeros((4, 3), np.int32))
        self.assertEqual(V.shape, (4,))

    def test_layout_checked(self):
        # the mirrors follow the library's ms_layout; a mirror that disagrees fails loudly
        with self.assertRaises(ImportError) as cm:
            ms._mirror("ms_vec3", [("x", ctypes.c_double)])
        self.assertIn("ms_vec3.x", str(cm.exception))
        with self.assertRaises(ImportError):
            ms._mirror("ms_vec3", [("w", ctypes.c_float)])
        with self.assertRaises(ImportError):
            ms._mirror("ms_no_such_struct", [])
        for mirror, cname in ((ms._Scene, "ms_scene"), (ms._Frame, "ms_frame"), (ms._RenderOptions, "ms_render_options"),
                              (ms._Stats, "ms_stats"), (ms._Lightmap, "ms_lightmap")):
            size = ctypes.c_size_t()
            self.assertEqual(ms._layout(cname.encode(), None, None, ctypes.byref(size)), 0)
            self.assertEqual(ctypes.sizeof(mirror), size.value, cname)

    def test_outside_paths(self):
        # an OBJ whose mtllib leads out of its folder: refused, unless allowed
        with tempfile.TemporaryDirectory() as d:
            os.mkdir(os.path.join(d, "asset"))
            with open(os.path.join(d, "outside.mtl"), "w") as f:
                f.write("newmtl m\nKd 1 0 0\n")
            with open(os.path.join(d, "asset", "m.obj"), "w") as f:
                f.write("mtllib ../outside.mtl\nusemtl m\n" + OBJ)
            path = os.path.join(d, "asset", "s.json")
            with open(path, "w") as f:
                f.write(JSON.replace("quad.obj", "m.obj"))
            with self.assertRaises(ms.Error) as cm:
                ms.load(path)
            self.assertIn("../outside.mtl", str(cm.exception))
            self.assertEqual(ms.load(path, allow_outside_paths=True).n_triangles, 4)

    def test_antialias(self):
        # aa=4: each pixel is the 2x2 pixels of the frame twice as large, averaged over those that hit
        big = ms.render(self.scene, method="scanline", samples=256, width=96, height=96)
        aa = ms.render(self.scene, method="scanline", samples=256, width=48, height=48, aa=4)
        self.assertEqual(aa["vis"].shape, (48, 48))
        v = big["vis"].reshape(48, 2, 48, 2).transpose(0, 2, 1, 3).reshape(48, 48, 4)
        hits = (v >= 0).sum(axis=2)
        mean = np.where(hits > 0, np.where(v >= 0, v, 0).sum(axis=2) / np.maximum(hits, 1), -1)
        np.testing.assert_allclose(aa["vis"], mean, atol=1e-6)
        self.assertTrue(((hits > 0) & (hits < 4)).any())   # some pixels straddle a silhouette
        with self.assertRaises(ValueError) as cm:
            ms.render(self.scene, aa=3)
        self.assertIn("aa", str(cm.exception))

    def test_abi_checked(self):
        # the module hands the library its mirrors' sizes with every call; a stale table is refused by name
        bad = ms._Abi.from_buffer_copy(ms._ABI)
        bad.frame += 8
        fn = ms._lib.ms_render_abi
        fn.restype = ctypes.c_int
        opt, fr, err = ms._RenderOptions(), ms._Frame(), ctypes.create_string_buffer(512)
        rc = fn(ctypes.byref(bad), ctypes.byref(self.scene._s), ctypes.byref(opt), ctypes.byref(fr), err, len(err))
        self.assertEqual(rc, 1)
        self.assertIn("ms_frame", err.value.decode())
        self.assertEqual(ms._ABI.render_options, ctypes.sizeof(ms._RenderOptions))

    def test_version(self):
        self.assertRegex(ms.__version__, r"^\d+\.\d+\.\d+$")


class BuiltSceneTest(unittest.TestCase):
    """scene_from_arrays (what the Blender add-on hands over) against the same scene loaded from its file:
    frames and bakes bit for bit; materials against the diffuse shading's formula; the ellipse light's
    irradiance against a numerical integral over its area; bad input refused with the culprit named."""

    CAMERA = {"eye": [0, 10, 12], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 32, "height": 32}

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(cls.dir.name, "quad.obj"), "w") as f:
            f.write(OBJ)
        path = os.path.join(cls.dir.name, "all.json")
        with open(path, "w") as f:
            f.write(scene_json(list(LIGHTS.values())))
        cls.loaded = ms.load(path)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def built(self, **kw):
        return ms.scene_from_arrays(self.loaded.triangles, self.loaded.lights, camera=self.CAMERA, **kw)

    def test_bake_islands(self):
        # a ground (UVs: the unit square) and an object of four 0.5 x 0.5 quads whose UVs are 0.2 x 0.2 squares in
        # the corners of the unit square: by default (their layouts overlap, so they are not kept as they are) each
        # quad moves whole as an island, at one texel density, and the page fills far more than with one region
        # per object (uv_packing="regions")
        tri, uv, obj = [], [], []
        def quad(x0, z0, w, y, u0, v0, uw, o):
            p = [[x0, y, z0 + w], [x0 + w, y, z0 + w], [x0 + w, y, z0], [x0, y, z0]]
            t = [[u0, v0], [u0 + uw, v0], [u0 + uw, v0 + uw], [u0, v0 + uw]]
            for a, b, c in ((0, 1, 2), (0, 2, 3)):
                tri.append([p[a], p[b], p[c]])
                uv.append([t[a], t[b], t[c]])
                obj.append(o)
        quad(-1, -1, 2, 0, 0, 0, 1, 0)
        for (x, z), (u, v) in zip([(-0.9, -0.9), (0.3, -0.9), (-0.9, 0.3), (0.3, 0.3)], [(0, 0), (0.75, 0), (0, 0.75), (0.75, 0.75)]):
            quad(x, z, 0.5, 0.3, u, v, 0.2, 1)
        sc = ms.scene_from_arrays(np.array(tri), [LIGHTS["rect"]], camera=self.CAMERA, uvs=[np.array(uv)],
                                  objects=np.array(obj))
        whole = ms.bake(sc, size=256, uv=0, samples=256, uv_packing="regions")
        isl = ms.bake(sc, size=256, uv=0, samples=256)
        forced = ms.bake(sc, size=256, uv=0, samples=256, uv_packing="islands")
        np.testing.assert_array_equal(isl["uv"], forced["uv"])
        with self.assertRaises(ValueError):
            ms.bake(sc, size=256, uv=0, samples=256, uv_packing="island")
        self.assertGreater(isl["page_fill"][0], 2 * whole["page_fill"][0])
        src, got = np.array(uv, np.float64), isl["uv"].astype(np.float64) * 256
        density = []
        for q in range(5):   # the ground's island, then the four quads: texels per world unit of each
            a = (got[2 * q, 1] - got[2 * q, 0]) / (src[2 * q, 1] - src[2 * q, 0])[0]
            off = got[2 * q: 2 * q + 2] - a[0] * src[2 * q: 2 * q + 2]
            np.testing.assert_allclose(off - off[0, 0], 0, atol=1e-2)   # both triangles, every corner: one move
            density.append(a[0] / (2.0 if q == 0 else 2.5))
        # one density, but for xatlas stretching each chart's extent up to whole texels (its packer aligns chart
        # edges with texel centres): every island's side within one texel of the least density's
        world = np.array([2.0, 0.5, 0.5, 0.5, 0.5])
        spans = np.array(density) * world
        np.testing.assert_array_less(spans - min(density) * world, 1.0 + 1e-6)

    def test_same_as_loaded(self):
        a = ms.render(self.loaded, samples=256)
        b = ms.render(self.built(), samples=256)
        for k in ("vis", "shadow", "rgb"):
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)
        for la, lb in zip(a["lights"], b["lights"]):
            np.testing.assert_array_equal(la["shadow"], lb["shadow"])
        self.assertGreater(float((a["shadow"] > 0).mean()), 0.2)
        la, lb = ms.bake(self.loaded, size=64, uv=None, samples=256), ms.bake(self.built(), size=64, uv=None, samples=256)
        np.testing.assert_array_equal(la["irradiance"], lb["irradiance"])
        np.testing.assert_array_equal(la["uv"], lb["uv"])

    def test_materials_and_normals(self):
        # diffuse shading is base colour x E x S / pi: against the default grey (albedo 0.8) the ratio per
        # channel is the base colour over 0.8 wherever the grey is lit
        grey = ms.render(self.built(), samples=256, shading="diffuse")["rgb"]
        n = self.loaded.n_triangles
        col = ms.render(self.built(materials=[{"base_color": (0.5, 0.25, 1.0, 1.0)}], triangle_materials=np.zeros(n)),
                        samples=256, shading="diffuse")["rgb"]
        lit = grey[..., 0] > 1e-3
        self.assertGreater(int(lit.sum()), 100)
        np.testing.assert_allclose(col[lit] / grey[lit], np.tile([0.5 / 0.8, 0.25 / 0.8, 1.0 / 0.8], (int(lit.sum()), 1)),
                                   rtol=1e-5)
        # shading normals tilted away from the light darken the shading but never the visibility
        tilt = np.tile(np.array([0.0, 0.6, 0.8], np.float32), (n, 3, 1))
        a, b = ms.render(self.built(), samples=256), ms.render(self.built(normals=tilt), samples=256)
        np.testing.assert_array_equal(a["shadow"], b["shadow"])
        self.assertLess(float(b["rgb"].sum()), 0.95 * float(a["rgb"].sum()))

    def test_ellipse_light(self):
        # the ellipse inscribed in a 2 x 1 rectangle at height 3, emitting down: irradiance at a point on the
        # ground against the integral of cos cos / (pi r^2)-weighted radiance over a fine grid of the ellipse
        L = {"shape": "ellipse", "corner": [-1, 3, -0.5], "edge_s": [2, 0, 0], "edge_t": [0, 0, 1]}
        p, nrm = np.array([0.7, 0.0, 0.4]), np.array([0.0, 1.0, 0.0])
        g = (np.arange(2000) + 0.5) / 2000
        s, t = np.meshgrid(g, g, indexing="ij")
        inside = (2 * s - 1) ** 2 + (2 * t - 1) ** 2 < 1
        q = np.stack([-1 + 2 * s, np.full_like(s, 3.0), -0.5 + t], -1)[inside]
        d = q - p
        r2 = (d * d).sum(-1)
        cos_r, cos_l = d[:, 1] / np.sqrt(r2), d[:, 1] / np.sqrt(r2)
        want = float((cos_r * cos_l / r2).sum() * (2.0 * 1.0 / (2000 * 2000)))
        got = ms.light_irradiance(L, p, nrm)
        self.assertAlmostEqual(got / want, 1.0, delta=0.01)
        self.assertEqual(set(ms.scene_from_arrays(self.loaded.triangles, [L]).light), {"shape", "emission", "corner",
                                                                                    "edge_s", "edge_t"})

    def test_warning_handler(self):
        # the library's warnings (here an unknown key of a scene file) reach the handler, one line each, and
        # no longer once it is removed
        got = []
        path = os.path.join(self.dir.name, "unknown_key.json")
        with open(path, "w") as f:
            f.write(scene_json([LIGHTS["rect"]]).replace('"meshes"', '"colour": 1, "meshes"'))
        ms.set_warning_handler(got.append)
        try:
            ms.load(path)
        finally:
            ms.set_warning_handler(None)
        self.assertEqual(len(got), 1, got)
        self.assertIn("colour", got[0])
        ms.load(path)
        self.assertEqual(len(got), 1)

    def test_refused(self):
        tri = self.loaded.triangles
        with self.assertRaisesRegex(ms.Error, "lights\\[1\\].*zero area"):
            ms.scene_from_arrays(tri, [LIGHTS["rect"], {"corner": [0, 6, 0], "edge_s": [0, 0, 0], "edge_t": [1, 0, 0]}])
        with self.assertRaisesRegex(ValueError, "objects"):
            ms.scene_from_arrays(tri, [LIGHTS["rect"]], objects=np.zeros(len(tri) + 1))
        with self.assertRaisesRegex(ValueError, "lights"):
            ms.scene_from_arrays(tri, [])
        bad = tri.copy()
        bad[0, 0, 0] = np.nan
        with self.assertRaises(ms.Error):
            ms.scene_from_arrays(bad, [LIGHTS["rect"]])


if __name__ == "__main__":
    print("python", sys.version.split()[0], "numpy", np.__version__, "library", ms._lib._name)
    unittest.main(verbosity=2)
