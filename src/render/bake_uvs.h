/* The UVs a bake bakes into (bake_uvs.c): per object the asset's own layout where one of its UV sets is a
 * valid one (its own region of the lightmap), xatlas charts for the rest; on one page, or at a texel
 * density on as many pages as it takes. */
#ifndef MS_BAKE_UVS_H
#define MS_BAKE_UVS_H
#include "microshadow.h"
#include "lightmap_unwrap.h"

typedef struct ms_bake_uv_params {
    int uv_set;              /* the set tried first for every object; -1: xatlas for all */
    int size, padding;
    float density;           /* texels per world unit (times each mesh's scale); 0: everything on one page */
    ms_uv_packing packing;   /* ms_bake_options.uv_packing */
} ms_bake_uv_params;

/* What ms_bake_uvs did, for the caller's report. */
typedef struct ms_bake_uv_report {
    size_t unwrapped;       /* triangles xatlas charted */
    size_t excluded;        /* triangles of meshes with "lightmap": false */
    size_t regions;         /* regions packed (0: the file's UVs as they are, or xatlas alone) */
    size_t overlap_texels;  /* texel centres two objects' UVs both cover (0: none) */
    int relaid;             /* 1: the file's UVs were scaled and offset (per object or as a whole) */
    size_t charts;          /* xatlas's charts */
    size_t objects_kept, objects_unwrapped;   /* objects baked in a file set, objects xatlas charted */
} ms_bake_uv_report;

/* The layout: uv (6 floats per scene triangle, in [0,1]^2 of its page, NaN for triangles not baked), page
 * (per triangle), the pages used, and per object (ms_scene.n_objects, else one per mesh: ms_bake_uv_objects)
 * the set it was baked in (-1: xatlas, -2: not baked) and its scale and offset (uv = file uv * s + o:
 * su, sv, ou, ov; 0 0 0 0 for xatlas and for islands packed one by one). All arrays are the caller's. */
typedef struct ms_bake_uv_layout {
    float *uv;
    uint32_t *page;
    int pages;
    int *object_set;
    float *object_scale_offset;
} ms_bake_uv_layout;

size_t ms_bake_uv_objects(const ms_scene *sc);
/* 0, or -1 with a message. */
int ms_bake_uvs(const ms_scene *sc, const ms_bake_uv_params *p, ms_bake_uv_layout *out, ms_bake_uv_report *rep, char *err,
                size_t errlen);
#endif
