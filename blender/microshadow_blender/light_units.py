"""Blender lights as microshadow lights: shapes in world space and Blender's units as radiance.

microshadow's lights emit a radiance L (W m^-2 sr^-1) from their shape (microshadow/lights.h). Blender gives
a power or a strength, and Cycles 3.4 turns it into radiance as follows (intern/cycles/scene/light.cpp and
kernel/light/*.h of Blender 3.4: each light's eval_fac); tests/blender/test_addon.py checks each against a
Cycles render of a lit plane:

  Area (square, rectangle, disk, ellipse) of power P over the area A of its shape in world units:
      L = P / (4 A)            eval_fac = 1/4 x 1/area (the "power" is not the emitted flux, pi A L)
  Point and spot of power P and radius r, a sphere (Cycles samples the disk facing the point):
      L = P / (4 pi^2 r^2)     eval_fac = 1/(4 pi) x 1/(pi r^2) (the emitted flux 4 pi^2 r^2 L is P)
  Sun of strength S (W m^-2) and angle theta (the angular diameter): the irradiance S at normal incidence,
  E = pi L sin^2(theta/2) for microshadow's sun (microshadow/lights.h, ms_light_sun):
      L = S / (pi sin^2(theta/2))   (Cycles: eval_fac = 1 / (pi tan^2(theta/2)) over a disk of radius
                                     tan(theta/2) at unit distance sampled by its area: E = S within 0.2%
                                     at 10 degrees, measured)
  Emission shader of strength s and colour c on a mesh (each side a triangle light):
      L = s c

The light's colour multiplies each. Departures, each reported as a warning where it applies: a spot's cone
and blend are not modelled (microshadow's sphere lights emit all round), a sun of angle 0 is given the
smallest angle microshadow takes, and Cycles' "spread" of area lights is taken as 180 degrees.
"""
import math

import numpy as np

# microshadow's sun needs an angular diameter in (0, 90] degrees (ms_light_sun)
MIN_SUN_ANGLE_DEG = 1e-3


class LightError(ValueError):
    """A light microshadow cannot take (zero size, out of range): the message names the light."""


def _col(m, k):
    return np.array([m[0][k], m[1][k], m[2][k]], np.float64)


def convert_light(name, kind, params, matrix_world, warnings):
    """One Blender light as a list of microshadow light dicts (world space).

    kind: 'AREA', 'POINT', 'SPOT' or 'SUN'; params: dict of the light's data, color (3), energy (W for
    area, point and spot; W m^-2 for a sun), and per kind: shape ('SQUARE', 'RECTANGLE', 'DISK', 'ELLIPSE'),
    size, size_y (area); shadow_soft_size (point, spot); angle (sun, radians); spread (area, radians).
    matrix_world: the object's 4 x 4 world matrix (rows). warnings: a list the departures are appended to."""
    M = np.asarray(matrix_world, np.float64)
    color = np.asarray(params["color"], np.float64)
    energy = float(params["energy"])
    pos = M[:3, 3]
    down = -_col(M, 2)  # Blender's lights shine along their local -Z
    if kind == "AREA":
        shape = params.get("shape", "SQUARE")
        sx = float(params["size"])
        sy = sx if shape in ("SQUARE", "DISK") else float(params["size_y"])
        ex, ey = _col(M, 0) * sx, _col(M, 1) * sy
        area = float(np.linalg.norm(np.cross(ex, ey)))
        if not area > 0 or not math.isfinite(area):
            raise LightError("light %r: an area light of zero size (Size %g x %g, or a zero scale); give it a size"
                             % (name, sx, sy))
        if shape in ("DISK", "ELLIPSE"):
            area *= math.pi / 4
        if params.get("spread", math.pi) < math.pi - 1e-6:
            warnings.append("light %r: Cycles' spread of %.0f degrees is not modelled (microshadow's area lights "
                            "emit as Lambertian surfaces, spread 180)" % (name, math.degrees(params["spread"])))
        L = tuple(color * energy / (4.0 * area))
        if shape == "DISK" and abs(np.linalg.norm(ex) - np.linalg.norm(ey)) <= 1e-6 * np.linalg.norm(ex) \
                and abs(ex @ ey) <= 1e-6 * (ex @ ex):
            # a circle: microshadow's disk (its own square about the normal, as the scene file's "disk")
            return [{"shape": "disk", "center": tuple(pos), "normal": tuple(down), "radius": float(np.linalg.norm(ex)) / 2,
                     "emission": L}]
        # corner + s edge_s + t edge_t, emitting towards edge_s x edge_t = -Z (local): edge_s = -X, edge_t = +Y
        d = {"shape": "rect" if shape in ("SQUARE", "RECTANGLE") else "ellipse", "corner": tuple(pos + ex / 2 - ey / 2),
             "edge_s": tuple(-ex), "edge_t": tuple(ey), "emission": L}
        if np.dot(np.cross(-ex, ey), down) < 0:  # a mirroring scale: keep the emitting side the light's -Z
            d["corner"], d["edge_s"] = tuple(pos - ex / 2 - ey / 2), tuple(ex)
        return [d]
    if kind in ("POINT", "SPOT"):
        r = float(params["shadow_soft_size"])
        if not r > 0:
            raise LightError("light %r: a %s light of radius 0; microshadow's lights have an area: give it a "
                             "Radius > 0" % (name, kind.lower()))
        if kind == "SPOT":
            warnings.append("light %r: the spot's cone (%.0f degrees) is not modelled: lit as a point light of the "
                            "same power and radius" % (name, math.degrees(params.get("spot_size", math.pi))))
        L = color * energy / (4.0 * math.pi * math.pi * r * r)
        return [{"shape": "sphere", "center": tuple(pos), "radius": r, "emission": tuple(L)}]
    if kind == "SUN":
        theta = float(params["angle"])
        deg = math.degrees(theta)
        if deg < MIN_SUN_ANGLE_DEG:
            warnings.append("light %r: a sun of angle %g degrees is given %g (microshadow's suns have a size)"
                            % (name, deg, MIN_SUN_ANGLE_DEG))
            deg, theta = MIN_SUN_ANGLE_DEG, math.radians(MIN_SUN_ANGLE_DEG)
        if deg > 90:
            raise LightError("light %r: a sun of angle %.1f degrees; microshadow's suns are at most 90" % (name, deg))
        L = color * energy / (math.pi * math.sin(theta / 2) ** 2)
        return [{"shape": "sun", "direction": tuple(-down), "angular_diameter_deg": deg, "emission": tuple(L)}]
    raise LightError("light %r: %s lights are not supported" % (name, kind))


def emissive_triangles(name, tris, radiance):
    """Triangle lights for an emissive mesh's triangles (n, 3, 3), both sides (Cycles' mesh emission is
    two-sided), each emitting `radiance` (3)."""
    out = []
    for t in np.asarray(tris, np.float64):
        if np.linalg.norm(np.cross(t[1] - t[0], t[2] - t[0])) <= 0:
            continue
        for a, b, c in ((t[0], t[1], t[2]), (t[0], t[2], t[1])):
            out.append({"shape": "triangle", "vertices": (tuple(a), tuple(b), tuple(c)), "emission": tuple(radiance)})
    return out
