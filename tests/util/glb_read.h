/* A small binary-glTF reader of the tests' own (independent of the writer in src/render/bake_gltf.c): the
 * header and the two chunks, the JSON parsed by cJSON, float and index accessors read from the binary chunk,
 * embedded PNG images decoded by libpng. */
#ifndef TU_GLB_READ_H
#define TU_GLB_READ_H
#include <cjson/cJSON.h>
#include <stddef.h>
#include <stdint.h>

typedef struct tu_glb {
    unsigned char *file;
    size_t len;
    cJSON *json;
    const unsigned char *bin;
    size_t bin_len;
} tu_glb;

/* 0, or -1 with the reason printed (a bad header, chunk, or JSON). */
int tu_glb_read(const char *path, tu_glb *g);
void tu_glb_free(tu_glb *g);
/* The floats of accessor `acc` (componentType FLOAT, tightly packed): a malloc'ed copy of count * comps
 * values (comps from its type), NULL when it is not such an accessor or leaves its buffer. */
float *tu_glb_floats(const tu_glb *g, int acc, size_t *count, int *comps);
/* Accessor acc as indices (UNSIGNED_INT, SCALAR): a malloc'ed copy, NULL otherwise. */
uint32_t *tu_glb_indices(const tu_glb *g, int acc, size_t *count);
/* The image of texture `tex` (its "source", embedded through a bufferView) decoded to `channels` (3 RGB,
 * 4 RGBA) 8-bit values per pixel, rows top first, without colour conversion; NULL on failure. */
uint8_t *tu_glb_texture(const tu_glb *g, int tex, int channels, int *w, int *h);
/* JSON helpers: item k of array `name` of the root (NULL when absent). */
const cJSON *tu_glb_item(const tu_glb *g, const char *name, int k);

#endif
