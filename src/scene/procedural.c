/* Procedural scenes (microshadow.h, ms_procedural). "flowers", after the paper's FLOWERS (Laine & Aila
 * 2005, sec. 4: procedural foliage of many small triangles): triangles 0 and 1 are a 40 x 40 ground at
 * y = 0; then plants of 64 triangles each at hashed places in [-16, 16]^2: a stem (two thin triangles,
 * 0.8 to 2.5 high) and 62 small leaves and petals (0.03 to 0.12 across), leaves along the upper stem,
 * petals clustered at its top. Triangle i depends only on (seed, i), so any range can be generated on its
 * own, in parallel, as often as needed. */
#include "microshadow.h"
#include "../light/pattern.h"
#include <math.h>
#include <string.h>

#define PLANT_TRIS 64

static float unit(uint32_t a, uint32_t b, uint32_t c) { return ms_hash_unit(ms_hash3(a, b, c)); }

static void flowers_triangle(uint32_t seed, size_t i, float *t)
{
    if (i < 2) {
        static const float g[2][9] = { { -20, 0, -20, 20, 0, 20, 20, 0, -20 }, { -20, 0, -20, -20, 0, 20, 20, 0, 20 } };
        memcpy(t, g[i], sizeof g[i]);
        return;
    }
    const size_t j = i - 2;
    const uint32_t plant = (uint32_t)(j / PLANT_TRIS), part = (uint32_t)(j % PLANT_TRIS);
    const uint32_t hi = (uint32_t)((uint64_t)(j / PLANT_TRIS) >> 32);
    const uint32_t ps = ms_hash3(seed, plant, hi);
    const float x = -16.0f + 32.0f * unit(ps, 1, 0), z = -16.0f + 32.0f * unit(ps, 2, 0);
    const float h = 0.8f + 1.7f * unit(ps, 3, 0), lean = 0.3f * (unit(ps, 4, 0) - 0.5f);
    const float top[3] = { x + lean * h, h, z + 0.5f * lean * h };
    if (part < 2) {
        /* the stem: a thin quad from the ground to the top */
        const float w = 0.01f;
        const float a[3] = { x - w, 0.0f, z }, b[3] = { x + w, 0.0f, z };
        const float c[3] = { top[0] + w, top[1], top[2] }, d[3] = { top[0] - w, top[1], top[2] };
        const float *v[2][3] = { { a, b, c }, { a, c, d } };
        for (int k = 0; k < 3; k++) memcpy(t + 3 * k, v[part][k], 3 * sizeof(float));
        return;
    }
    const uint32_t hs = ms_hash3(ps, part, seed ^ 0x9E3779B9u);
    const int petal = part >= 40;
    const float along = petal ? 1.0f : 0.35f + 0.6f * unit(hs, 1, 0);
    const float ang = 6.2831853f * unit(hs, 2, 0);
    const float r = petal ? 0.03f + 0.12f * unit(hs, 3, 0) : 0.05f + 0.3f * unit(hs, 3, 0);
    const float base[3] = { x + (top[0] - x) * along + r * cosf(ang), top[1] * along + (petal ? 0.05f * unit(hs, 4, 0) : 0.0f),
                            z + (top[2] - z) * along + r * sinf(ang) };
    const float size = petal ? 0.03f + 0.05f * unit(hs, 5, 0) : 0.05f + 0.07f * unit(hs, 5, 0);
    /* two edges from the base: outwards, and sideways with a hashed tilt */
    const float a1 = ang + 0.6f * (unit(hs, 6, 0) - 0.5f), tilt = unit(hs, 7, 0) - 0.3f;
    const float e1[3] = { size * cosf(a1), size * tilt, size * sinf(a1) };
    const float e2[3] = { -size * 0.5f * sinf(a1), size * (unit(hs, 8, 0) - 0.5f), size * 0.5f * cosf(a1) };
    for (int a = 0; a < 3; a++) {
        t[a] = base[a];
        t[3 + a] = base[a] + e1[a];
        t[6 + a] = base[a] + 0.6f * e1[a] + e2[a];
    }
}

void ms_procedural_triangles(const ms_scene *s, size_t first, size_t count, float *out)
{
    for (size_t i = 0; i < count; i++) flowers_triangle(s->procedural.seed, first + i, out + 9 * i);
}
