/* A light's emission: flux to radiance (units) and its texture's texels. */
#include "microshadow.h"
#include <math.h>

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
