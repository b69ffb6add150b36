/* Light sample patterns shared by every shadow method, so that methods compare sample for sample.
 *
 * grid: a k x k lattice, sample (i,j) = p0 + i*ds + j*dt, an affine image of the integer grid. The
 *   lattice is rotated by atan(1/k) and shifted per pixel (Woop, sec. 6) so that axis-aligned edges give
 *   noise instead of k steps: s_ij = (i + (k-1-j+u)/k)/k, t_ij = (j + (i+v)/k)/k with (u,v) in [0,1)^2
 *   hashed from the pixel and seed. Every sample stays in its own cell (i,j) of the light, and the k^2
 *   samples take k^2 distinct values along each light axis. Being affine, the micro-rasterizer sees
 *   the lattice as integer positions on the plane z = 1 of light space.
 * stratified: sample (i,j) jittered uniformly in cell (i,j), jitter hashed from pixel, sample and seed.
 *
 * Sample index is j*k + i; in an occlusion buffer that is bit i of scanline j. */
#ifndef MS_PATTERN_H
#define MS_PATTERN_H
#include <stdint.h>
#include "microshadow.h"

typedef struct ms_grid {
    float p0[3], ds[3], dt[3];   /* sample (i,j) = p0 + i*ds + j*dt */
    int k;
} ms_grid;

uint32_t ms_hash3(uint32_t a, uint32_t b, uint32_t c);
/* A float in [0,1) from a hash. */
static inline float ms_hash_unit(uint32_t h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

void ms_grid_for_pixel(const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed, ms_grid *g);
/* Sample positions (3*k*k floats, index j*k+i) of either pattern for one pixel. */
void ms_pattern_points(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                       float *xyz);
/* Samples first .. first+count-1 of the same (3*count floats): the same floats, for methods that form
 * their rays only where they need them (shadow/mft.c). */
void ms_pattern_points_range(ms_pattern p, const ms_light *l, int k, uint32_t px, uint32_t py, uint32_t seed,
                             int first, int count, float *xyz);
/* k for a sample count (256, 1024, 4096), 0 if unsupported. */
int ms_samples_to_k(int samples);

#endif
