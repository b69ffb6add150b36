/* A mesh encoded with libdraco's encoder, for tests of the glTF reader's Draco path (draco_encode.cpp: Draco's
 * API is C++). */
#ifndef MS_TEST_DRACO_ENCODE_H
#define MS_TEST_DRACO_ENCODE_H
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif

/* nv points with positions pos (3 floats each) and uv (2 floats each), nt triangles idx (3 each), without
 * quantization (the floats survive exactly), by the edgebreaker (sequential = 0) or the sequential method.
 * Writes at most cap bytes to out; returns their number (0 on failure) and the attributes' Draco unique ids. */
size_t tu_draco_encode(const float *pos, const float *uv, size_t nv, const uint32_t *idx, size_t nt, int sequential,
                       unsigned char *out, size_t cap, uint32_t *pos_id, uint32_t *uv_id);

#ifdef __cplusplus
}
#endif
#endif
