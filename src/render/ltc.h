/* Unshadowed GGX specular from an area light (any shape: ms_light_shape) by linearly transformed cosines (Heitz, Dupuy, Hill
 * and Neubelt 2016, with their fitted table, third_party/ltc). */
#ifndef MS_LTC_H
#define MS_LTC_H
#include "microshadow.h"

/* The integral over the light's solid angle of f_GGX(v, l) max(n.l, 0) (no Fresnel), per unit emitted
 * radiance, at point p with unit normal n, unit view direction v (towards the eye) and perceptual
 * roughness r. 0 behind the light's emitting side or when v is below n's plane.
 *
 * Exact: the polygon integral of the transformed clamped cosine (the edge sum of Lambert's formula after
 * clipping to the horizon, like ms_light_irradiance). Approximated: the BRDF lobe by the fitted LTC (the
 * fit's error; tests/test_shading.c measures it against numerical integration), bilinearly interpolated
 * between the 64 x 64 fitted (roughness, sqrt(1 - cos theta_v)) entries; the LTC has unit integral and
 * is scaled by the fitted directional albedo of the BRDF; a disk (and a sphere's outline disk seen from
 * p) by the regular 32-gon of the same area. */
float ms_ltc_ggx(const ms_light *l, const float p[3], const float n[3], const float v[3], float roughness);

#endif
