/* Light shapes and units (microshadow.h, docs/design.md "Light shapes", "Units"): a shape is a mask over the
 * parameters (s,t) of the light's parallelogram, so every pattern, every method and the weights stay those
 * of the parallelogram, and a disk costs one more mask per receiver (ms_shape_mask, pattern.c). */
#include "microshadow.h"
#include "core/vec.h"
#include "light_frame.h"
#include <math.h>
#include <string.h>

int ms_light_shape_contains(ms_light_shape shape, float s, float t)
{
    if (shape != MS_LIGHT_DISK) return 1;
    const float x = 2.0f * s - 1.0f, y = 2.0f * t - 1.0f;
    return x * x + y * y < 1.0f;
}

int ms_light_disk(ms_light *l, ms_vec3 c, ms_vec3 m, float r)
{
    float n[3] = { m.x, m.y, m.z };
    const float len = v3_len(n);
    if (!(len > 0.0f) || !(r > 0.0f) || !isfinite(len) || !isfinite(r)) return -1;
    v3_scale(n, n, 1.0f / len);
    /* An orthonormal frame from n alone (Duff et al. 2017, "Building an orthonormal basis, revisited"):
     * continuous except where n.z changes sign, and exact enough that the square is a square. */
    const float sign = copysignf(1.0f, n[2]), a = -1.0f / (sign + n[2]), b = n[0] * n[1] * a;
    float e1[3] = { 1.0f + sign * n[0] * n[0] * a, sign * b, -sign * n[0] };
    float e2[3] = { b, sign + n[1] * n[1] * a, -n[1] };
    /* cross(e1, e2) = n: the square emits towards m. */
    const float d = 2.0f * r;
    l->corner = (ms_vec3){ c.x - r * (e1[0] + e2[0]), c.y - r * (e1[1] + e2[1]), c.z - r * (e1[2] + e2[2]) };
    l->edge_s = (ms_vec3){ d * e1[0], d * e1[1], d * e1[2] };
    l->edge_t = (ms_vec3){ d * e2[0], d * e2[1], d * e2[2] };
    l->shape = MS_LIGHT_DISK;
    return 0;
}

int ms_light_sphere(ms_light *l, ms_vec3 c, float r)
{
    if (!(r > 0.0f) || !isfinite(r)) return -1;
    l->shape = MS_LIGHT_SPHERE;
    l->center = c;
    l->radius = r;
    /* The parallelogram fields are unused; a square around the sphere keeps them valid (non-zero area). */
    l->corner = (ms_vec3){ c.x - r, c.y, c.z - r };
    l->edge_s = (ms_vec3){ 2.0f * r, 0.0f, 0.0f };
    l->edge_t = (ms_vec3){ 0.0f, 0.0f, 2.0f * r };
    return 0;
}

int ms_light_sphere_outline(const ms_light *l, const float p[3], ms_light *disk)
{
    /* In double: the tangent circle's radius r sqrt(d^2 - r^2)/d loses everything to cancellation in
     * float when the point is close to the sphere. */
    const double c[3] = { l->center.x, l->center.y, l->center.z }, r = l->radius;
    const double w[3] = { p[0] - c[0], p[1] - c[1], p[2] - c[2] };
    const double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (!(d2 > r * r * (1.0 + 1e-6))) return -1;
    const double f = r * r / d2, rr = r * sqrt(d2 - r * r) / sqrt(d2);
    const ms_vec3 cc = { (float)(c[0] + w[0] * f), (float)(c[1] + w[1] * f), (float)(c[2] + w[2] * f) };
    const ms_vec3 m = { (float)w[0], (float)w[1], (float)w[2] };
    memset(disk, 0, sizeof *disk);
    disk->emission = l->emission;
    return ms_light_disk(disk, cc, m, (float)rr);
}

float ms_light_area(const ms_light *l)
{
    if (l->shape == MS_LIGHT_SPHERE) return 4.0f * (float)M_PI * l->radius * l->radius;
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    const float a = v3_len(F.normal);
    return l->shape == MS_LIGHT_DISK ? a * (float)(M_PI / 4.0) : a;
}

ms_vec3 ms_light_radiance_from(const ms_light *l, ms_vec3 amount, ms_light_units units)
{
    if (units == MS_UNITS_RADIANCE) return amount;
    /* A one-sided Lambertian emitter of area A and radiance L emits flux pi A L (watts from W sr^-1 m^-2,
     * lumens from cd m^-2); Drobot's chapter converts the artist's lumens to luminance the same way. */
    const float k = 1.0f / ((float)M_PI * ms_light_area(l));
    return (ms_vec3){ amount.x * k, amount.y * k, amount.z * k };
}

float ms_light_texel(const ms_light *l, float s, float t, float *rgb)
{
    if (!l->texture || l->texture_width < 1 || l->texture_height < 1) {
        if (rgb) rgb[0] = rgb[1] = rgb[2] = 1.0f;
        return 1.0f;
    }
    /* nearest texel; parameters at 1 (or rounding past it) fall in the last texel */
    int x = (int)(s * (float)l->texture_width), y = (int)(t * (float)l->texture_height);
    x = x < 0 ? 0 : x >= l->texture_width ? l->texture_width - 1 : x;
    y = y < 0 ? 0 : y >= l->texture_height ? l->texture_height - 1 : y;
    const float *c = l->texture + 3 * ((size_t)y * (size_t)l->texture_width + (size_t)x);
    if (rgb) { rgb[0] = c[0]; rgb[1] = c[1]; rgb[2] = c[2]; }
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}
