/* GGX with height-correlated Smith G2 (brdf_ggx.h). */
#include "brdf_ggx.h"
#include "core/vec.h"
#include <math.h>

float ms_ggx_alpha(float roughness)
{
    const float a = roughness * roughness;
    return a > 1e-5f ? a : 1e-5f;
}

/* Smith's Lambda for GGX at cos theta = c: (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2. */
static float lambda(float alpha, float c)
{
    if (c >= 1.0f) return 0.0f;
    const float t2 = (1.0f - c * c) / (c * c);
    return 0.5f * (-1.0f + sqrtf(1.0f + alpha * alpha * t2));
}

float ms_ggx_f_cos(const float n[3], const float v[3], const float l[3], float alpha)
{
    const float nv = v3_dot(n, v), nl = v3_dot(n, l);
    if (!(nv > 0.0f) || !(nl > 0.0f)) return 0.0f;
    float h[3];
    v3_add(h, v, l);
    const float hl = v3_len(h);
    if (!(hl > 0.0f)) return 0.0f;
    const float nh = v3_dot(n, h) / hl;
    const float a2 = alpha * alpha;
    const float d0 = nh * nh * (a2 - 1.0f) + 1.0f;
    const float D = a2 / ((float)M_PI * d0 * d0);
    const float G2 = 1.0f / (1.0f + lambda(alpha, nv) + lambda(alpha, nl));
    return D * G2 / (4.0f * nv);
}
