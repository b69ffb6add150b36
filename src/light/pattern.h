/* Light sample patterns shared by every shadow method, so that methods compare sample for sample.
 *
 * grid: a k x k lattice, sample (i,j) = p0 + i*ds + j*dt, an affine image of the integer grid. The
 *   lattice is rotated by atan(1/k) and shifted per pixel (Woop, sec. 6) so that axis-aligned edges give
 *   noise instead of k steps: s_ij = (i + (k-1-j+u)/k)/k, t_ij = (j + (i+v)/k)/k with (u,v) in [0,1)^2
 *   hashed from the pixel and seed. Every sample stays in its own cell (i,j) of the light, and the k^2
 *   samples take k^2 distinct values along each light axis. Being affine, the micro-rasterizer sees
 *   the lattice as integer positions on the plane z = 1 of light space.
 * stratified: sample (i,j) jittered uniformly in cell (i,j), jitter hashed from pixel, sample and seed.
 * interleaved (Benthin & Wald 2009, sec. 4.5, after Keller & Heidrich 2001): N = k*k points in all, the
 *   same over the frame; pixel (x,y) of every 4x4 block gets set s = (x & 3) + 4 (y & 3), the aligned
 *   block of points [s N/16, (s+1) N/16) of a (0,2)-sequence (ms_interleaved_uv), so N/16 per pixel.
 *
 * Sample index is j*k + i for grid and stratified; in an occlusion buffer that is bit i of scanline j. For
 * interleaved it is the point's place in the pixel's set. */
#ifndef MS_PATTERN_H
#define MS_PATTERN_H
#include <stdint.h>
#include "microshadow.h"

typedef struct ms_grid {
    float p0[3], ds[3], dt[3];   /* sample (i,j) = p0 + i*ds + j*dt */
    int k;
} ms_grid;

/* Samples first .. first + count - 1 of grid g (sample n = (n % k, n / k)) as xyz triples: the grid's one
 * definition of its points (ms_pattern_points_range; method mft forms rays from a grid kept per pixel). */
static inline void ms_grid_points(const ms_grid *g, int first, int count, float *xyz)
{
    for (int n = first; n < first + count; n++) {
        const int i = n % g->k, j = n / g->k;
        float *o = xyz + 3 * (n - first);
        for (int c = 0; c < 3; c++) o[c] = g->p0[c] + (float)i * g->ds[c] + (float)j * g->dt[c];
    }
}

uint32_t ms_hash3(uint32_t a, uint32_t b, uint32_t c);
/* A float in [0,1) from a hash. */
static inline float ms_hash_unit(uint32_t h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

void ms_grid_for_pixel(const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed, ms_grid *g);
/* The grid's per-pixel shift (u, v) in [0,1)^2, hashed from the pixel and the seed (the header's s_ij, t_ij). */
void ms_grid_shift(uint32_t px, uint32_t py, uint32_t seed, float *u, float *v);
/* Sample positions of a pattern for one pixel: 3*ms_pattern_spp(p, k) floats (k*k samples in all). */
void ms_pattern_points(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                       float *xyz);
/* Samples first .. first+count-1 of the same (3*count floats): the same floats, for methods that form
 * their rays only where they need them (shadow/mft.c). */
void ms_pattern_points_range(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                             int first, int count, float *xyz);
/* Light shapes (microshadow.h, ms_light_shape): clears in mask (the pixel's samples, bit n = sample n)
 * every sample whose light parameters (s,t) lie off the light's shape; nothing for a parallelogram. Sample by
 * sample; front masks take the grid's disk in vector lanes instead (visibility/disk_mask.h). */
void ms_shape_mask_apply(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                         uint64_t *mask);
/* The same mask from ms_pattern_st's (s,t) and the shape's test (for tests). */
void ms_shape_mask_reference(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                             uint64_t *mask);
/* The light parameters (s,t) of the pixel's samples, 2 * ms_pattern_spp(p, k) floats: the values the
 * shape mask tests (for tests and the textured emission). */
void ms_pattern_st(ms_pattern p, int k, uint32_t px, uint32_t py, uint32_t seed, float *st);
/* k for a sample count N = k*k (16, 64, 256, 1024, 4096), 0 if unsupported. */
int ms_samples_to_k(int samples);
/* Samples per pixel of pattern p at N = k*k: k*k, or k*k/16 for interleaved. */
int ms_pattern_spp(ms_pattern p, int k);
/* Light samples per pixel of pattern p at N samples, 0 when p does not take N: grid 256, 1024, 4096 (the
 * micro-rasterizer's buffers); stratified also 16 and 64; interleaved 256, 1024, 4096 (16, 64, 256 per
 * pixel, so that the ray tracers' 16-ray packets stay full). 0 also for an unknown p. */
int ms_pattern_samples_per_pixel(ms_pattern p, int samples);
/* The interleaved pattern's light parameters as 32-bit fixed point (u / 2^32 in [0,1)): the n = N/16
 * points of set `set` (0..15), point l = sequence point set*n + l, digitally shifted by the seed. */
void ms_interleaved_uv(int samples, int set, uint32_t seed, uint32_t *u, uint32_t *v);
/* The set of pixel (px, py): (px & 3) + 4 (py & 3). */
static inline int ms_interleaved_set(uint32_t px, uint32_t py) { return (int)((px & 3u) + 4u * (py & 3u)); }

#endif
