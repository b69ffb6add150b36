/* The unwrap cache (uv_cache.c): a bake's UV layout saved beside its outputs and taken back by a later bake
 * of the same geometry with the same UV options. */
#ifndef MS_UV_CACHE_H
#define MS_UV_CACHE_H
#include "bake_uvs.h"

/* The hash of everything the layout depends on: positions, objects, meshes and their lightmap scales, every
 * UV set, the options (set, size, padding, density) and the chart tuning. */
uint64_t ms_uv_cache_key(const ms_scene *sc, const ms_bake_uv_params *p);

/* Reads path into out (the caller's arrays, sized for sc) when it holds key: 1. 0 when there is no such
 * file. -1 when there is one that cannot be used (another key, another triangle count, truncated, corrupt):
 * why says so in a few words, out is untouched. */
int ms_uv_cache_read(const char *path, uint64_t key, size_t n_tris, size_t n_objects, ms_bake_uv_layout *out,
                     char *why, size_t whylen);
#endif
