/* The front mask's disk (receiver.c, ms_front_mask): the grid pattern's samples off the disk inscribed in the
 * light's parallelogram, tested in vector lanes, one source compiled per ISA (disk_mask_impl.h):
 * disk_mask_scalar.c (portable), disk_mask_avx2.c, disk_mask_avx512.c. A disk, a sphere's outline and a sun's
 * take it for every receiver, where it cost more than the shadow traversal itself (docs/lights.md). */
#ifndef MS_DISK_MASK_H
#define MS_DISK_MASK_H
#include <stdint.h>

/* Clears in mask (the pixel's k x k samples, bit j k + i = sample (i, j)) every grid sample off the disk, for
 * the grid's per-pixel shift (u, v) (ms_grid_shift): the disk's test (light_disk.c) on the (s, t) of
 * ms_pattern_st, sample for sample, so that every instance clears what ms_shape_mask_apply clears. */
void ms_grid_disk_mask_scalar(int k, float u, float v, uint64_t *mask);
void ms_grid_disk_mask_avx2(int k, float u, float v, uint64_t *mask);
void ms_grid_disk_mask_avx512(int k, float u, float v, uint64_t *mask);

#endif
