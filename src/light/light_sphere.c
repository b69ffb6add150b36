/* The sphere light (shape "sphere"): centre and radius; not planar, so each receiver samples the disk
 * outlining the sphere as seen from it (ms_light_sphere_outline); not textured. */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

ms_status ms_light_sphere(ms_light *l, ms_vec3 c, float r)
{
    if (!(r > 0.0f) || !isfinite(r)) return MS_ERR_INVALID;
    l->shape = MS_LIGHT_SPHERE;
    l->center = c;
    l->radius = r;
    /* The parallelogram fields are unused; a square around the sphere keeps them valid (non-zero area). */
    l->corner = (ms_vec3){ c.x - r, c.y, c.z - r };
    l->edge_s = (ms_vec3){ 2.0f * r, 0.0f, 0.0f };
    l->edge_t = (ms_vec3){ 0.0f, 0.0f, 2.0f * r };
    return MS_OK;
}

ms_status ms_light_sphere_outline(const ms_light *l, const float p[3], ms_light *disk)
{
    /* In double: the tangent circle's radius r sqrt(d^2 - r^2)/d loses everything to cancellation in
     * float when the point is close to the sphere. */
    const double c[3] = { l->center.x, l->center.y, l->center.z }, r = l->radius;
    const double w[3] = { p[0] - c[0], p[1] - c[1], p[2] - c[2] };
    const double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (!(d2 > r * r * (1.0 + 1e-6))) return MS_ERR_INVALID;
    const double f = r * r / d2, rr = r * sqrt(d2 - r * r) / sqrt(d2);
    const ms_vec3 cc = { (float)(c[0] + w[0] * f), (float)(c[1] + w[1] * f), (float)(c[2] + w[2] * f) };
    const ms_vec3 m = { (float)w[0], (float)w[1], (float)w[2] };
    memset(disk, 0, sizeof *disk);
    disk->emission = l->emission;
    return ms_light_disk(disk, cc, m, (float)rr);
}

static float sphere_area(const ms_light *l, const ms_light_frame *F)
{
    (void)F;
    return 4.0f * (float)M_PI * l->radius * l->radius;
}

/* A round cone of directions (a sphere, or the sun) of half-angle sigma, its axis at angle theta from the
 * normal: pi sin^2 sigma cos theta when wholly above the horizon (cos^2 theta > sin^2 sigma), else Snyder's
 * exact expression for the part above it (Lagarde & de Rousiers 2014, "illuminanceSphereOrDisk"). */
double ms_light_cone_irradiance(double ct, double s2)
{
    if (ct * ct > s2) return ct > 0.0 ? M_PI * s2 * ct : 0.0;
    const double st = sqrt(fmax(1.0 - ct * ct, 0.0)), x = sqrt(1.0 / s2 - 1.0);
    const double y = -x * ct / st, sty = st * sqrt(fmax(1.0 - y * y, 0.0));
    return fmax((ct * acos(y) - x * sty) * s2 + atan(sty / x), 0.0);
}

/* A sphere of radius r at distance d: the cone of sin^2 sigma = (r/d)^2 towards its centre. */
static double sphere_irradiance(const ms_light *l, const float p[3], const float n[3])
{
    const double w[3] = { (double)l->center.x - p[0], (double)l->center.y - p[1], (double)l->center.z - p[2] };
    const double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], r = l->radius;
    if (!(d2 > r * r)) return 0.0;
    return ms_light_cone_irradiance((w[0] * n[0] + w[1] * n[1] + w[2] * n[2]) / sqrt(d2), r * r / d2);
}

static float sphere_irradiance_f(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3])
{
    (void)F;
    return (float)sphere_irradiance(l, p, n);
}

static int sphere_validate(const ms_light *l, float max_coord, char *msg, size_t n)
{
    const ms_vec3 c = l->center;
    const int centre_ok = isfinite(c.x) && isfinite(c.y) && isfinite(c.z) && fabsf(c.x) <= max_coord &&
                          fabsf(c.y) <= max_coord && fabsf(c.z) <= max_coord;
    if (centre_ok && l->radius > 0.0f && l->radius <= max_coord && !l->texture) return 0;
    snprintf(msg, n, "a sphere needs a finite center and a radius in (0, %g], and no texture", (double)max_coord);
    return -1;
}

static int sphere_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    const double r = v->v[1][0];
    if (!(r > 0) || r > max_coord) { snprintf(msg, n, "radius must be in (0, %g]", (double)max_coord); return -1; }
    ms_light_sphere(l, (ms_vec3){ (float)v->v[0][0], (float)v->v[0][1], (float)v->v[0][2] }, (float)r);
    return 0;
}

/* Centre and radius; the parallelogram fields are unused. */
static int sphere_finite(const ms_light *l)
{
    return isfinite(l->center.x) && isfinite(l->center.y) && isfinite(l->center.z) && isfinite(l->radius) &&
           l->radius > 0.0f;
}

/* The shape table's outline hook (0 or -1) over the API's ms_light_sphere_outline. */
static int sphere_outline(const ms_light *l, const float p[3], ms_light *disk)
{
    return ms_light_sphere_outline(l, p, disk) == MS_OK ? 0 : -1;
}

const ms_light_shape_ops ms_light_sphere_shape = {
    .shape = MS_LIGHT_SPHERE,
    .name = "sphere",
    .textured = 0,
    .area = sphere_area,
    .irradiance = sphere_irradiance_f,
    .outline = sphere_outline,
    .validate = sphere_validate,
    .keys = { { "center", MS_LIGHT_KEY_POINT, 1, 0, 0 }, { "radius", MS_LIGHT_KEY_NUMBER, 1, 0, 0 } },
    .build = sphere_build,
    .finite = sphere_finite,
};
