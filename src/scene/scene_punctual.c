/* glTF KHR_lights_punctual lights as area lights (scene file "lights_from_punctual", docs/lights.md): a point
 * light becomes a sphere light, a spot light a disk light facing the spot's direction, each of radius
 * extras.radius or the scene file's "punctual_radius"; a directional light becomes a sun (towards the node's
 * +Z, the light travelling along its -Z) of angular diameter extras.angular_diameter_deg, else the Sun's
 * 0.53 degrees. Intensities follow the extension's units: a point or spot's intensity I (candela) is the
 * on-axis intensity of the area light, so its radiance is L = I / (pi r^2) (a sphere of radiance L, and a
 * disk seen face on, have intensity L pi r^2); a directional light's intensity E (lux) is the illuminance
 * at normal incidence, so its radiance is L = E / (pi sin^2 alpha), alpha half the angular diameter (the
 * sun's exact normal irradiance is pi L sin^2 alpha). */
#include "microshadow.h"
#include "scene_internal.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ms_scene_punctual_lights(const ms_punctual *p, size_t n, const double origin[3], double default_radius, size_t room,
                             const char *path, void (*warn)(const char *line), ms_light **out, size_t *n_out, char *err,
                             size_t errlen)
{
    *out = NULL;
    *n_out = 0;
    if (!n) return 0;
    ms_light *L = calloc(n, sizeof *L);
    if (!L) { snprintf(err, errlen, "%s: out of memory for the punctual lights", path); return -1; }
    size_t k = 0, spots = 0;
    for (size_t i = 0; i < n; i++) {
        if (p[i].type == MS_PUNCTUAL_DIRECTIONAL) {
            const double deg = p[i].angular_deg != 0.0f ? (double)p[i].angular_deg : 0.53;
            ms_light *l = &L[k];
            if (ms_light_sun(l, (ms_vec3){ (float)-p[i].dir[0], (float)-p[i].dir[1], (float)-p[i].dir[2] }, (float)deg)) {
                free(L);
                snprintf(err, errlen, "%s: KHR_lights_punctual light %zu: extras.angular_diameter_deg %g is not in (0, 90]",
                         path, i, deg);
                return -1;
            }
            const double sa = sin(0.5 * deg * M_PI / 180.0), k_rad = (double)p[i].intensity / (M_PI * sa * sa);
            l->emission = (ms_vec3){ (float)(p[i].color[0] * k_rad), (float)(p[i].color[1] * k_rad), (float)(p[i].color[2] * k_rad) };
            k++;
            continue;
        }
        const double r = p[i].radius > 0.0f ? (double)p[i].radius : default_radius;
        float c[3];
        ms_scene_frame_point(p[i].pos, origin, c);
        ms_light *l = &L[k];
        int bad;
        if (p[i].type == MS_PUNCTUAL_POINT) {
            bad = ms_light_sphere(l, (ms_vec3){ c[0], c[1], c[2] }, (float)r);
        } else {
            spots++;
            bad = ms_light_disk(l, (ms_vec3){ c[0], c[1], c[2] },
                                (ms_vec3){ (float)p[i].dir[0], (float)p[i].dir[1], (float)p[i].dir[2] }, (float)r);
        }
        if (bad) {
            free(L);
            snprintf(err, errlen, "%s: KHR_lights_punctual light %zu: radius %g or its direction is not usable", path, i, r);
            return -1;
        }
        const double k_rad = (double)p[i].intensity / (M_PI * r * r);
        l->emission = (ms_vec3){ (float)(p[i].color[0] * k_rad), (float)(p[i].color[1] * k_rad), (float)(p[i].color[2] * k_rad) };
        k++;
    }
    char line[320];
    if (spots) {
        snprintf(line, sizeof line, "%.120s: %zu KHR_lights_punctual spot light%s made disk light%s: the cone is not "
                 "modelled (a disk emits over its whole front hemisphere, Lambertian)", path, spots, spots > 1 ? "s" : "", spots > 1 ? "s" : "");
        warn(line);
    }
    if (k > room) {
        free(L);
        snprintf(err, errlen, "%s: %zu KHR_lights_punctual lights, more than the %zu a frame can still hold (%d in all): "
                 "set \"lights_from_punctual\": false and name the lights in the scene file", path, k, room, MS_MAX_LIGHTS);
        return -1;
    }
    if (!k) { free(L); return 0; }
    *out = L;
    *n_out = k;
    return 0;
}
