#include "pattern.h"
#include "light_frame.h"
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <string.h>

uint32_t ms_hash3(uint32_t a, uint32_t b, uint32_t c)
{
    /* Jenkins' final mix over three words followed by a murmur3 finaliser: cheap and well spread. */
    uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
    h ^= h >> 16; h *= 0x85EBCA6Bu;
    h ^= h >> 13; h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
}

const char *ms_pattern_name(ms_pattern p)
{
    switch (p) {
    case MS_PATTERN_GRID: return "grid";
    case MS_PATTERN_STRATIFIED: return "stratified";
    case MS_PATTERN_INTERLEAVED: return "interleaved";
    }
    return "unknown";
}

ms_status ms_pattern_from_name(const char *name, ms_pattern *out)
{
    for (int p = MS_PATTERN_GRID; p <= MS_PATTERN_INTERLEAVED; p++)
        if (strcmp(name, ms_pattern_name((ms_pattern)p)) == 0) { *out = (ms_pattern)p; return MS_OK; }
    return MS_ERR_INVALID;
}

int ms_samples_to_k(int samples)
{
    switch (samples) {
    case 16: return 4;
    case 64: return 8;
    case 256: return 16;
    case 1024: return 32;
    case 4096: return 64;
    default: return 0;
    }
}

int ms_pattern_spp(ms_pattern p, int k) { return p == MS_PATTERN_INTERLEAVED ? k * k / 16 : k * k; }

int ms_pattern_samples_per_pixel(ms_pattern p, int samples)
{
    const int k = ms_samples_to_k(samples);
    switch (p) {
    case MS_PATTERN_GRID: return k >= 16 ? k * k : 0;
    case MS_PATTERN_STRATIFIED: return k * k;
    case MS_PATTERN_INTERLEAVED: return k >= 16 ? k * k / 16 : 0;
    }
    return 0;
}

/* The interleaved pattern draws from the 2D Sobol' sequence: x is the van der Corput radical inverse in
 * base 2 (identity generator matrix), y the second Sobol' component (Pascal matrix mod 2). Together they
 * form a (0,2)-sequence in base 2 (Kollig & Keller, "Efficient Multidimensional Sampling", EG 2002, whose
 * VanDerCorput/Sobol2 code this follows): every aligned block of 2^m points, [j 2^m, (j+1) 2^m), is a
 * (0,m,2)-net, i.e. each elementary interval [a 2^-d, (a+1) 2^-d) x [b 2^-(m-d), (b+1) 2^-(m-d)) holds
 * exactly one of its points. So each pixel's set of n = N/16 points is a (0,m,2)-net (n = 2^m) and the 16
 * sets of a 4x4 block together are the first N points, a (0,m+4,2)-net. Departure from the paper, which
 * names Hammersley or Larcher-Pillichshammer points: those are nets but not sequences, so their aligned
 * sub-blocks are not nets (Hammersley's are stripes of the light 1/16 wide). The XOR with a hash of the
 * seed (a digital shift, Kollig & Keller's scrambling argument r) maps elementary intervals onto
 * elementary intervals, so the nets stay nets; the pattern is the same over the whole frame. */
static uint32_t radical_inverse2(uint32_t i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
    i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
    return i;
}

static uint32_t sobol2(uint32_t i)
{
    uint32_t r = 0;
    for (uint32_t v = UINT32_C(1) << 31; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}

/* The 16 sets are the same over a frame, and every pixel asks for its set several times (front mask,
 * rays, resolve): each thread keeps the sets of the last (samples, seed) it formed. */
static _Thread_local struct {
    int samples;
    uint32_t seed, have;   /* have: one bit per set */
    uint32_t u[16][256], v[16][256];
} interleaved_cache;

void ms_interleaved_uv(int samples, int set, uint32_t seed, uint32_t *u, uint32_t *v)
{
    const uint32_t n = (uint32_t)samples / 16u, base = (uint32_t)set * n;
    if (interleaved_cache.samples != samples || interleaved_cache.seed != seed) {
        interleaved_cache.samples = samples;
        interleaved_cache.seed = seed;
        interleaved_cache.have = 0;
    }
    if (!(interleaved_cache.have >> set & 1u)) {
        const uint32_t su = ms_hash3(seed, 0x1A7E2C3Bu, 0x5EEDu), sv = ms_hash3(seed, 0x0C4F9D21u, 0x5EEDu);
        for (uint32_t l = 0; l < n; l++) {
            interleaved_cache.u[set][l] = radical_inverse2(base + l) ^ su;
            interleaved_cache.v[set][l] = sobol2(base + l) ^ sv;
        }
        interleaved_cache.have |= 1u << set;
    }
    memcpy(u, interleaved_cache.u[set], n * sizeof *u);
    memcpy(v, interleaved_cache.v[set], n * sizeof *v);
}

/* The interleaved sets' points for the last light (its corner and edges), samples and seed, per thread. */
static _Thread_local struct {
    int samples;
    uint32_t seed, have;   /* have: one bit per set */
    float frame[9];
    float xyz[16][3 * 256];
} interleaved_xyz;

/* Light parameters of sample n of the stratified pattern. */
static void stratified_st(int k, uint32_t px, uint32_t py, uint32_t seed, int n, float *s, float *t)
{
    const uint32_t hp = ms_hash3(px, py, seed ^ 0xA511E9B3u);
    const float inv = 1.0f / (float)k;
    const int i = n % k, j = n / k;
    const uint32_t h = ms_hash3(hp, (uint32_t)n, seed);
    *s = ((float)i + ms_hash_unit(h)) * inv;
    *t = ((float)j + ms_hash_unit(ms_hash3(h, 0x68E31DA4u, 1u))) * inv;
}

void ms_grid_for_pixel(const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed, ms_grid *g)
{
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    const float *S = F.edge_s, *T = F.edge_t, *P = F.corner;
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
        ms_grid_points(&g, first, count, xyz);
        return;
    }
    if (p == MS_PATTERN_INTERLEAVED) {
        ms_light_frame F;
        ms_light_frame_of(l, &F);
        const int n = k * k / 16, set = ms_interleaved_set(px, py);
        /* The pixel's n = N/16 points; of them [first, first + count). The set's points are the same for
         * every pixel of the set: kept per thread for the last light, samples and seed (every pixel asks for
         * them for its front mask, its rays and its V and S; forming them was 12% of a frame's CPU time). */
        const int end = first + count < n ? first + count : n;
        if (interleaved_xyz.samples != k * k || interleaved_xyz.seed != seed ||
            memcmp(interleaved_xyz.frame, &F, sizeof(float) * 9) != 0) {
            interleaved_xyz.samples = k * k;
            interleaved_xyz.seed = seed;
            memcpy(interleaved_xyz.frame, &F, sizeof(float) * 9);
            interleaved_xyz.have = 0;
        }
        float *pts = interleaved_xyz.xyz[set];
        if (!(interleaved_xyz.have >> set & 1u)) {
            const float *S = F.edge_s, *T = F.edge_t, *P = F.corner;
            uint32_t u[256], v[256];   /* n <= 4096 / 16 */
            ms_interleaved_uv(k * k, set, seed, u, v);
            for (int i = 0; i < n; i++) {
                /* 24 bits: exact in a float, and far finer than the 2^-12 of the smallest elementary interval */
                const float s = (float)(u[i] >> 8) * (1.0f / 16777216.0f), t = (float)(v[i] >> 8) * (1.0f / 16777216.0f);
                for (int c = 0; c < 3; c++) pts[3 * i + c] = P[c] + s * S[c] + t * T[c];
            }
            interleaved_xyz.have |= 1u << set;
        }
        if (end > first) memcpy(xyz, pts + 3 * first, (size_t)(end - first) * 3 * sizeof *xyz);
        return;
    }
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    const float *S = F.edge_s, *T = F.edge_t, *P = F.corner;
    for (int n = first; n < first + count; n++) {
        float s, t;
        stratified_st(k, px, py, seed, n, &s, &t);
        float *o = xyz + 3 * (n - first);
        for (int c = 0; c < 3; c++) o[c] = P[c] + s * S[c] + t * T[c];
    }
}

void ms_grid_shift(uint32_t px, uint32_t py, uint32_t seed, float *u, float *v)
{
    uint32_t h = ms_hash3(px, py, seed);
    *u = ms_hash_unit(h);
    *v = ms_hash_unit(ms_hash3(h, 0x51ED270Bu, seed));
}

void ms_shape_mask_reference(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                             uint64_t *mask)
{
    const int spp = ms_pattern_spp(p, k);
    float st[2 * MS_SAMPLES_MAX];
    ms_pattern_st(p, k, px, py, seed, st);
    for (int n = 0; n < spp; n++)
        if (!ms_light_shape_contains(l->shape, st[2 * n], st[2 * n + 1])) mask[n >> 6] &= ~(UINT64_C(1) << (n & 63));
}

void ms_shape_mask_apply(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                         uint64_t *mask)
{
    const ms_light_shape_ops *shape = ms_light_shape_of(l->shape);
    if (!shape || !shape->contains) return;   /* no mask: the whole parallelogram */
    const int spp = ms_pattern_spp(p, k);
    if (p == MS_PATTERN_GRID) {
        /* Its samples one by one, (s, t) as ms_pattern_st forms them (the grid's disk in vector lanes:
         * visibility/disk_mask.h, which front masks use). */
        float u, v;
        ms_grid_shift(px, py, seed, &u, &v);
        const float ik = 1.0f / (float)k;
        for (int j = 0; j < k; j++)
            for (int i = 0; i < k; i++) {
                const float s = ((float)i + ((float)(k - 1 - j) + u) * ik) * ik, t = ((float)j + ((float)i + v) * ik) * ik;
                const int n = j * k + i;
                if (!shape->contains(s, t)) mask[n >> 6] &= ~(UINT64_C(1) << (n & 63));
            }
        return;
    }
    if (p == MS_PATTERN_INTERLEAVED) {
        uint32_t uu[256], vv[256];
        ms_interleaved_uv(k * k, ms_interleaved_set(px, py), seed, uu, vv);
        for (int n = 0; n < spp; n++) {
            const float s = (float)(uu[n] >> 8) * (1.0f / 16777216.0f), t = (float)(vv[n] >> 8) * (1.0f / 16777216.0f);
            if (!ms_light_shape_contains(l->shape, s, t)) mask[n >> 6] &= ~(UINT64_C(1) << (n & 63));
        }
        return;
    }
    for (int n = 0; n < spp; n++) {
        float s, t;
        stratified_st(k, px, py, seed, n, &s, &t);
        if (!ms_light_shape_contains(l->shape, s, t)) mask[n >> 6] &= ~(UINT64_C(1) << (n & 63));
    }
}

void ms_pattern_st(ms_pattern p, int k, uint32_t px, uint32_t py, uint32_t seed, float *st)
{
    const int spp = ms_pattern_spp(p, k);
    if (p == MS_PATTERN_GRID) {
        float u, v;
        ms_grid_shift(px, py, seed, &u, &v);
        const float ik = 1.0f / (float)k;   /* exact: k is a power of two */
        for (int n = 0; n < spp; n++) {
            const int i = n % k, j = n / k;
            st[2 * n] = ((float)i + ((float)(k - 1 - j) + u) * ik) * ik;
            st[2 * n + 1] = ((float)j + ((float)i + v) * ik) * ik;
        }
    } else if (p == MS_PATTERN_INTERLEAVED) {
        uint32_t uu[256], vv[256];
        ms_interleaved_uv(k * k, ms_interleaved_set(px, py), seed, uu, vv);
        for (int n = 0; n < spp; n++) {
            st[2 * n] = (float)(uu[n] >> 8) * (1.0f / 16777216.0f);
            st[2 * n + 1] = (float)(vv[n] >> 8) * (1.0f / 16777216.0f);
        }
    } else {
        for (int n = 0; n < spp; n++) stratified_st(k, px, py, seed, n, &st[2 * n], &st[2 * n + 1]);
    }
}

void ms_pattern_points(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                       float *xyz)
{
    ms_pattern_points_range(p, l, k, px, py, seed, 0, k * k, xyz);
}
