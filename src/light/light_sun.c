/* The sun (shape "sun"): a disk at infinity, the cone of directions of half-angle alpha (angular diameter
 * 2 alpha) about `direction` (towards the sun), the same for every receiver. Not planar in the scene, so
 * each receiver P samples its own outline: the disk of radius D_P tan(alpha) at P + D_P direction, facing P
 * (ms_light_sun_outline). Every segment then has the same length D_P, chosen from the scene's extent so that
 * its end lies outside the scene (ms_light_sun_place): "no far limit" holds exactly for the scene's
 * occluders, and the near range is 1e-4 D_P (docs/design.md, "Light shapes: the sun").
 *
 * Fields: center = the unit direction towards the sun; corner, edge_s, edge_t = the outline's bounding
 * square at unit distance (the disk of radius tan(alpha) at `direction`, emitting towards -direction);
 * radius = D, the placement distance (0: not placed yet; the frame and the points place it). */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

#define SUN_MAX_DEG 90.0   /* angular diameters in (0, 90] degrees */
#define SUN_REACH_TIMES 4.0 /* D = 4 rho: see ms_light_sun_place */

ms_status ms_light_sun(ms_light *l, ms_vec3 dir, float angular_diameter_deg)
{
    const double len = sqrt((double)dir.x * dir.x + (double)dir.y * dir.y + (double)dir.z * dir.z);
    if (!(len > 0.0) || !isfinite(len) || !(angular_diameter_deg > 0.0f) || !(angular_diameter_deg <= SUN_MAX_DEG))
        return MS_ERR_INVALID;
    const ms_vec3 u = { (float)(dir.x / len), (float)(dir.y / len), (float)(dir.z / len) };
    const float t = (float)tan(0.5 * (double)angular_diameter_deg * M_PI / 180.0);
    if (ms_light_disk(l, u, (ms_vec3){ -u.x, -u.y, -u.z }, t)) return MS_ERR_INVALID;
    l->shape = MS_LIGHT_SUN;
    l->center = u;
    l->radius = 0.0f;
    return MS_OK;
}

/* tan(alpha): half the unit square's edge. */
static double sun_tan(const ms_light *l)
{
    return 0.5 * sqrt((double)l->edge_s.x * l->edge_s.x + (double)l->edge_s.y * l->edge_s.y + (double)l->edge_s.z * l->edge_s.z);
}

void ms_light_sun_place(ms_light *l, const float box[6])
{
    if (l->shape != MS_LIGHT_SUN) return;
    /* rho: the radius of the ball about the scene's origin holding the box. D = 4 rho: a segment of length
     * D (1 - 1e-4) from any P in the ball ends beyond 4 rho (1 - 1e-4) - rho > rho, outside the scene, with
     * room for rounding; the factor (1 + 1e-6) keeps the float D/4 >= rho. Larger D would narrow the hull
     * (more closed-mesh culling) but widen the near range 1e-4 D. */
    double r2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double m = fmax(fabs((double)box[a]), fabs((double)box[3 + a]));
        r2 += m * m;
    }
    double rho = sqrt(r2);
    if (!(rho > 0.0) || !isfinite(rho)) rho = 1.0;   /* no geometry: any distance will do */
    l->radius = (float)(SUN_REACH_TIMES * rho * (1.0 + 1e-6));
}

/* D_P: D for receivers in the placement ball (|P| <= D/4), growing by 2 (|P| - D/4) beyond it (points given
 * to ms_visibility_points outside the scene), so that every segment still ends outside the ball. */
static double sun_distance(const ms_light *l, const float p[3])
{
    const double D = l->radius, pl = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
    const double d = D + 2.0 * fmax(0.0, pl - D / SUN_REACH_TIMES);
    return d > 0.0 ? d : 1.0;   /* not placed and at the origin: the irradiance and LTC do not depend on D */
}

int ms_light_sun_outline(const ms_light *l, const float p[3], ms_light *disk)
{
    const float d = (float)sun_distance(l, p);
    memset(disk, 0, sizeof *disk);
    disk->emission = l->emission;
    disk->shape = MS_LIGHT_DISK;
    /* The unit square scaled by D_P about the receiver: no trigonometry per receiver, and the same directions
     * (to float rounding) from every P. */
    disk->corner = (ms_vec3){ p[0] + d * l->corner.x, p[1] + d * l->corner.y, p[2] + d * l->corner.z };
    disk->edge_s = (ms_vec3){ d * l->edge_s.x, d * l->edge_s.y, d * l->edge_s.z };
    disk->edge_t = (ms_vec3){ d * l->edge_t.x, d * l->edge_t.y, d * l->edge_t.z };
    return 0;
}

/* The conversion's "area" (ms_light_radiance_from): sin^2 alpha, so that "power" (W m^-2) and "lumens" (lux)
 * are the irradiance at normal incidence, pi L sin^2 alpha. */
static float sun_area(const ms_light *l, const ms_light_frame *F)
{
    (void)F;
    const double t = sun_tan(l);
    return (float)(t * t / (1.0 + t * t));
}

static float sun_irradiance(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3])
{
    (void)F;
    (void)p;
    const double t = sun_tan(l);
    const double ct = (double)l->center.x * n[0] + (double)l->center.y * n[1] + (double)l->center.z * n[2];
    return (float)ms_light_cone_irradiance(ct, t * t / (1.0 + t * t));
}

/* The points whose hull holds every sample of every receiver in the placement ball: the cube [-rho, rho]^3
 * (rho = D/4, holding the ball) plus the box of the square at distance D. For a receiver outside the ball
 * (sun_distance) the samples lie beyond, but what the hull is for still holds: a segment from P leaves a
 * face F of the scene towards a sample along a direction c of the square, so F's plane has y + D c (y on F,
 * inside the cube) in front of it, a point of this hull (docs/design.md). Not placed: an infinite box, which
 * turns the hull's uses off. */
static int sun_hull(const ms_light *l, float pts[8][3])
{
    const double D = l->radius, rho = D / SUN_REACH_TIMES;
    if (!(D > 0.0)) {
        for (int n = 0; n < 8; n++)
            for (int a = 0; a < 3; a++) pts[n][a] = n >> a & 1 ? INFINITY : -INFINITY;
        return 8;
    }
    const float c[3] = { l->corner.x, l->corner.y, l->corner.z }, s[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z };
    const float t[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
        for (int q = 0; q < 4; q++) {
            const double v = D * ((double)c[a] + (q & 1 ? s[a] : 0.0f) + (q & 2 ? t[a] : 0.0f));
            lo[a] = fmin(lo[a], v);
            hi[a] = fmax(hi[a], v);
        }
        /* widened by a float's rounding of the outline's corners (p + D_P corner in float) */
        const double slack = 1e-6 * (D + rho);
        lo[a] -= rho + slack;
        hi[a] += rho + slack;
    }
    for (int n = 0; n < 8; n++)
        for (int a = 0; a < 3; a++) pts[n][a] = (float)(n >> a & 1 ? hi[a] : lo[a]);
    return 8;
}

static int sun_validate(const ms_light *l, float max_coord, char *msg, size_t n)
{
    const ms_vec3 u = l->center;
    const double len = sqrt((double)u.x * u.x + (double)u.y * u.y + (double)u.z * u.z);
    const double deg = 2.0 * atan(sun_tan(l)) * 180.0 / M_PI;
    if (isfinite(len) && fabs(len - 1.0) < 1e-3 && isfinite(l->radius) && l->radius >= 0.0f && l->radius <= max_coord &&
        deg > 0.0 && deg <= SUN_MAX_DEG + 1e-3 && !l->texture)
        return 0;
    snprintf(msg, n, "a sun needs a unit direction (center), an angular diameter in (0, %g] degrees and no texture "
             "(ms_light_sun)", SUN_MAX_DEG);
    return -1;
}

static int sun_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    (void)max_coord;
    const double deg = v->v[1][0];
    if (!(deg > 0.0) || deg > SUN_MAX_DEG) {
        snprintf(msg, n, "angular_diameter_deg must be in (0, %g]", SUN_MAX_DEG);
        return -1;
    }
    const ms_vec3 d = { (float)v->v[0][0], (float)v->v[0][1], (float)v->v[0][2] };
    if (ms_light_sun(l, d, (float)deg)) { snprintf(msg, n, "direction must not be zero"); return -1; }
    return 0;
}

static int sun_finite(const ms_light *l)
{
    return isfinite(l->center.x) && isfinite(l->center.y) && isfinite(l->center.z) && isfinite(l->radius) &&
           isfinite(l->corner.x) && isfinite(l->corner.y) && isfinite(l->corner.z) && sun_tan(l) > 0.0 &&
           isfinite(sun_tan(l));
}

const ms_light_shape_ops ms_light_sun_shape = {
    .shape = MS_LIGHT_SUN,
    .name = "sun",
    .textured = 0,
    .area = sun_area,
    .irradiance = sun_irradiance,
    .outline = ms_light_sun_outline,
    .hull = sun_hull,
    .validate = sun_validate,
    .keys = { { "direction", MS_LIGHT_KEY_VECTOR, 1, 0, 0 }, { "angular_diameter_deg", MS_LIGHT_KEY_NUMBER, 1, 1, 0.53 } },
    .build = sun_build,
    .finite = sun_finite,
};
