/* microshadow/lights.h, a part of <microshadow.h>: light shapes and their constructors, emission units, bounds on
 * what a light emits, the unshadowed irradiance. Programs include <microshadow.h>, which includes every part in
 * order; a part relies on the ones before it. */
#ifndef MICROSHADOW_LIGHTS_H
#define MICROSHADOW_LIGHTS_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

/* Light shapes (docs/design.md, "Light shapes"). Every shape is sampled on its parallelogram
 * L(s,t) = corner + s*edge_s + t*edge_t, s,t in [0,1]: the pattern's samples are those of the
 * parallelogram, and the shape masks off the samples outside it by their parameters (s,t):
 *   MS_LIGHT_RECT: the parallelogram itself (every sample; the zero value, so older callers keep it);
 *   MS_LIGHT_DISK: the ellipse inscribed in the parallelogram, (2s-1)^2 + (2t-1)^2 < 1; for a disk of
 *     centre c, unit normal m and radius r the parallelogram is its bounding square (ms_light_disk);
 *   MS_LIGHT_SPHERE: a sphere (center, radius; the parallelogram fields unused). Seen from a receiver P
 *     outside it, its outline is a disk facing P (ms_light_sphere_outline): each receiver is sampled on
 *     its own outline disk, a per-receiver light frame (frames, points and bakes alike); not textured.
 *   MS_LIGHT_TRIANGLE: the triangle corner, corner + edge_s, corner + edge_t: the parameters with s + t < 1
 *     (ms_light_triangle); emits towards cross(edge_s, edge_t); not textured.
 *   MS_LIGHT_SUN: a disk at infinity (ms_light_sun): the cone of directions of angular diameter 2 alpha about
 *     the unit direction `center` (towards the sun), the same from every receiver. Each receiver P is sampled
 *     on its own outline, the disk of radius D tan(alpha) at P + D center facing P, with the disk's mask; D
 *     (`radius`) is set by the renderer from the scene's extent so that every segment ends outside the
 *     scene (no far limit for the scene's occluders; the near range is 1e-4 D): docs/design.md, "The sun";
 *     not textured. */
typedef enum ms_light_shape { MS_LIGHT_RECT = 0, MS_LIGHT_DISK = 1, MS_LIGHT_SPHERE = 2, MS_LIGHT_TRIANGLE = 3, MS_LIGHT_SUN = 4 } ms_light_shape;

/* An area light. It emits radiance `emission` (linear RGB) from the side cross(edge_s, edge_t) points to,
 * from the samples of its shape. Zero-initialised fields past emission keep a uniform parallelogram.
 * A textured light (texture non-NULL) emits emission times the texel at its parameters (s,t): the
 * nearest of texture_width x texture_height linear RGB texels (3 floats each, row 0 at t = 0, column 0
 * at s = 0). Its texels weight the samples in S (docs/design.md: w_i times the texel's luminance) and
 * the shading; V stays the unweighted fraction. The caller owns the texels (ms_scene_free frees a loaded
 * scene's). */
/* Bounds on what a light emits, so that every output stays finite in single precision: a light texture's
 * texels lie in [0, MS_MAX_LIGHT_TEXEL] and a light's radiance (after "power" or "lumens" are divided by
 * pi times its area) in [-MS_MAX_RADIANCE, MS_MAX_RADIANCE] per channel; ms_scene_validate refuses more, and
 * the EXR reader refuses such a texel naming it. Why these suffice: a pixel's radiance is a sum over at most
 * 64 lights of albedo/pi * E * S * t plus a specular term, where the unshadowed irradiance E <= pi L (the
 * projected solid angle of the receiver's hemisphere is pi), S <= 1, the mean texel t <= 1e6 and the
 * specular term (LTC-integrated GGX: directional albedo <= 1) <= L t. So a pixel is at most
 * 64 * 2 * 1e20 * 1e6 = 1.3e28, a baked irradiance at most 64 * pi * 1e26 = 2e28, and S's texel-weighted
 * sums (at most 4096 weights times a luminance <= 1e6, summed in double) stay as far from overflow: ten
 * orders of magnitude below FLT_MAX = 3.4e38, room for the intermediate products. 1e6 is beyond any light
 * profile's useful dynamic range (scale the emission instead); 1e20 is 1e11 times the sun's luminance in
 * nits. What geometry alone can make infinite (the form-factor weight of a receiver touching the light)
 * is caught by the last check before outputs are written (ms_outputs_write, ms_bake, ms_visibility_points). */
#define MS_MAX_LIGHT_TEXEL 1e6f
#define MS_MAX_RADIANCE 1e20f

typedef struct ms_light {
    ms_vec3 corner, edge_s, edge_t;
    ms_vec3 emission;
    ms_light_shape shape;
    const float *texture;
    int texture_width, texture_height;
    ms_vec3 center;      /* MS_LIGHT_SPHERE only (MS_LIGHT_SUN: the unit direction towards the sun) */
    float radius;        /* MS_LIGHT_SPHERE only (MS_LIGHT_SUN: the placement distance D, 0 until rendered) */
} ms_light;

/* Fills l as a sphere light of centre c and radius r (emission left as it is). MS_OK, or MS_ERR_INVALID when r is
 * not > 0. */
MS_API ms_status ms_light_sphere(ms_light *l, ms_vec3 c, float r);
/* The outline of sphere light l seen from p: the disk where the cone of tangents from p touches the sphere,
 * centre c + (p - c) r^2/d^2, radius r sqrt(d^2 - r^2)/d (d = |p - c|), facing p, as a disk light
 * (ms_light_disk) with l's emission. Every ray from p to this disk meets the sphere first at its near side,
 * and the disk subtends the sphere's solid angle. MS_OK, or MS_ERR_INVALID when p is not outside the sphere. */
MS_API ms_status ms_light_sphere_outline(const ms_light *l, const float p[3], ms_light *disk);

/* Luminance of the texel at (s,t) of a textured light (0.2126 R + 0.7152 G + 0.0722 B), and its colour
 * into rgb when rgb is not NULL; 1 (and white) for an untextured light. */
MS_API float ms_light_texel(const ms_light *l, float s, float t, float *rgb);

/* Fills l as a disk light of centre c, normal m (emitting towards m; need not be unit length, not zero)
 * and radius r: its bounding square, edges 2r along two unit vectors perpendicular to m chosen from m
 * alone, and shape MS_LIGHT_DISK; emission is left as it is. MS_OK, or MS_ERR_INVALID when m is zero or r not
 * > 0. */
MS_API ms_status ms_light_disk(ms_light *l, ms_vec3 c, ms_vec3 m, float r);

/* Fills l as a triangle light of vertices a, b, c (corner a, edges b - a and c - a, shape MS_LIGHT_TRIANGLE),
 * emitting towards cross(b - a, c - a); emission is left as it is. MS_OK, or MS_ERR_INVALID when the vertices are
 * collinear. */
MS_API ms_status ms_light_triangle(ms_light *l, ms_vec3 a, ms_vec3 b, ms_vec3 c);

/* Fills l as a sun (MS_LIGHT_SUN): a disk at infinity in unit direction dir from the scene (towards the sun;
 * need not be unit length, not zero) of angular diameter angular_diameter_deg in (0, 90] degrees (the Sun's:
 * 0.53). Its parallelogram is the outline's bounding square at unit distance (the disk of radius
 * tan(alpha) at dir, emitting towards -dir), center the unit dir, radius 0 (the renderer places it);
 * emission, its radiance, is left as it is (irradiance at normal incidence E = pi L sin^2 alpha).
 * MS_OK, or MS_ERR_INVALID when dir is zero or the diameter out of range. */
MS_API ms_status ms_light_sun(ms_light *l, ms_vec3 dir, float angular_diameter_deg);

/* 1 if light parameters (s,t) lie on the light's shape (see ms_light_shape), 0 if not. */
MS_API int ms_light_shape_contains(ms_light_shape shape, float s, float t);

/* The emitting area of the light's shape (|edge_s x edge_t|, times pi/4 for a disk, 1/2 for a triangle; 4 pi r^2 for a sphere;
 * sin^2 alpha for a sun, so that watts and lumens convert to radiance from W m^-2 and lux at normal incidence). */
MS_API float ms_light_area(const ms_light *l);

/* Units of a light's emission in a scene file (docs/design.md, "Units"). The renderer works in radiance;
 * the others are converted by the shape's emitting area A, every light emitting as a one-sided
 * Lambertian surface (Drobot, GPU Pro 5, "physically based area lights": flux = pi * A * radiance):
 *   MS_UNITS_RADIANCE: emission is radiance (W sr^-1 m^-2 or the scene's own linear unit);
 *   MS_UNITS_WATTS: radiant flux Phi in W per channel, radiance = Phi / (pi A);
 *   MS_UNITS_LUMENS: luminous flux in lm per channel, luminance = Phi_v / (pi A) in cd m^-2 (nits);
 *     the renderer's radiance unit is then the nit (no 683 lm/W: the image stays photometric). */
typedef enum ms_light_units { MS_UNITS_RADIANCE = 0, MS_UNITS_WATTS = 1, MS_UNITS_LUMENS = 2 } ms_light_units;
/* The radiance of light l (its shape and edges set) emitting `amount` in `units`. */
MS_API ms_vec3 ms_light_radiance_from(const ms_light *l, ms_vec3 amount, ms_light_units units);


/* Unshadowed irradiance at point p with unit normal n from the light, per unit emitted radiance.
 * Parallelogram: exact (polygon form factor, light clipped to the receiver's hemisphere). Disk over a
 * square (a circle, as ms_light_disk makes): exact closed form (the disk's vector irradiance from the
 * parallel and perpendicular differential-element form factors) when the whole disk is above the
 * receiver's plane; across the horizon, and for an ellipse, the polygon formula on a clipped 256-gon of
 * the same area (an approximation; error measured in tests/test_lights.c). Sphere: exact, pi (r/d)^2
 * cos theta wholly above the horizon, Snyder's closed form across it (as in Lagarde & de Rousiers,
 * "Moving Frostbite to PBR", 2014); 0 at points inside the sphere. Sun: the same cone, exact, pi sin^2 alpha
 * cos theta wholly above the horizon (theta from the sun's direction), Snyder's form across it; the same at
 * every p. */
MS_API float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3]);

#endif
