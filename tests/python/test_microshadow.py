"""The Python module against independent answers: the Quad (a 20x20 ground, a 4x4 occluder at y = 2
and a 2x2 light at y = 6, all parallel), where the visible fraction of the light at a ground point is
the light's area outside the occluder's projection onto the light plane, computed here in numpy; frames
and lightmaps through the module; errors, cancellation and dtype handling."""
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


if __name__ == "__main__":
    print("python", sys.version.split()[0], "numpy", np.__version__, "library", ms._lib._name)
    unittest.main(verbosity=2)
