/* The UVs a bake bakes into (bake_uvs.c): the asset's own set where it can be used as it is, a region of the
 * lightmap per object where objects' UVs overlap, xatlas charts for what has none. */
#ifndef MS_BAKE_UVS_H
#define MS_BAKE_UVS_H
#include "microshadow.h"

/* What ms_bake_uvs did, for the caller's report. */
typedef struct ms_bake_uv_report {
    size_t unwrapped;       /* triangles xatlas charted */
    size_t excluded;        /* triangles of meshes with "lightmap": false */
    size_t regions;         /* regions packed (0: the file's UVs as they are, or xatlas alone) */
    size_t overlap_texels;  /* texel centres two objects' UVs both cover (0: none) */
    int relaid;             /* 1: the file's UVs were scaled and offset (per object or as a whole) */
} ms_bake_uv_report;

/* uv: 6 floats per scene triangle, in [0,1]^2, NaN for triangles not baked. uv_set -1: xatlas for all. */
int ms_bake_uvs(const ms_scene *sc, int uv_set, int size, int padding, float *uv, ms_bake_uv_report *rep, char *err,
                size_t errlen);

#endif
