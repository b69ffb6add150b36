#include "pattern.h"
#include "vec.h"

uint32_t ms_hash3(uint32_t a, uint32_t b, uint32_t c)
{
    /* Jenkins' final mix over three words followed by a murmur3 finaliser: cheap and well spread. */
    uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
    h ^= h >> 16; h *= 0x85EBCA6Bu;
    h ^= h >> 13; h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
}

int ms_samples_to_k(int samples)
{
    switch (samples) {
    case 256: return 16;
    case 1024: return 32;
    case 4096: return 64;
    default: return 0;
    }
}

void ms_grid_for_pixel(const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed, ms_grid *g)
{
    const float S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z };
    const float T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    const float P[3] = { l->corner.x, l->corner.y, l->corner.z };
    uint32_t h = ms_hash3(px, py, seed);
    float u = ms_hash_unit(h), v = ms_hash_unit(ms_hash3(h, 0x51ED270Bu, seed));
    float kf = (float)k, k2 = kf * kf;
    /* s_ij = (i + (k-1-j+u)/k)/k, t_ij = (j + (i+v)/k)/k, written as p0 + i ds + j dt. */
    float a = ((kf - 1.0f) + u) / k2, b = v / k2;
    for (int c = 0; c < 3; c++) {
        g->p0[c] = P[c] + a * S[c] + b * T[c];
        g->ds[c] = S[c] / kf + T[c] / k2;
        g->dt[c] = T[c] / kf - S[c] / k2;
    }
    g->k = k;
}

void ms_pattern_points_range(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                             int first, int count, float *xyz)
{
    if (p == MS_PATTERN_GRID) {
        ms_grid g;
        ms_grid_for_pixel(l, k, px, py, seed, &g);
        for (int n = first; n < first + count; n++) {
            const int i = n % k, j = n / k;
            float *o = xyz + 3 * (n - first);
            for (int c = 0; c < 3; c++) o[c] = g.p0[c] + (float)i * g.ds[c] + (float)j * g.dt[c];
        }
        return;
    }
    const float S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z };
    const float T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    const float P[3] = { l->corner.x, l->corner.y, l->corner.z };
    uint32_t hp = ms_hash3(px, py, seed ^ 0xA511E9B3u);
    float inv = 1.0f / (float)k;
    for (int n = first; n < first + count; n++) {
        const int i = n % k, j = n / k;
        uint32_t h = ms_hash3(hp, (uint32_t)n, seed);
        float s = ((float)i + ms_hash_unit(h)) * inv;
        float t = ((float)j + ms_hash_unit(ms_hash3(h, 0x68E31DA4u, 1u))) * inv;
        float *o = xyz + 3 * (n - first);
        for (int c = 0; c < 3; c++) o[c] = P[c] + s * S[c] + t * T[c];
    }
}

void ms_pattern_points(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                       float *xyz)
{
    ms_pattern_points_range(p, l, k, px, py, seed, 0, k * k, xyz);
}
