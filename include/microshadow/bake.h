/* microshadow/bake.h, a part of <microshadow.h>: lightmap baking, its row-by-row form, the UV cache and the bake
 * written back onto the asset as glTF. Programs include <microshadow.h>, which includes every part in order; a
 * part relies on the ones before it. */
#ifndef MICROSHADOW_BAKE_H
#define MICROSHADOW_BAKE_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

/* ---- Lightmap baking (docs/baking.md) ----
 *
 * Texel (x, y) of a size x size lightmap covers u in [x, x+1)/size and v in [y, y+1)/size of the UV set
 * baked into (row 0 at v = 0, the top of the image as glTF has it); page p of a paged lightmap is rows
 * [p size, (p+1) size) of the frame, its texel (x, y) at row p size + y. Every texel a triangle's UV image
 * touches (conservative rasterization) is carried to the triangle's surface: its centre's barycentric
 * coordinates, moved to the nearest point of the triangle when the centre lies outside (a texel several
 * triangles touch takes the one containing its centre, else the nearest), give the world position; the
 * normal (ms_lightmap.normal) is the triangle's, by its winding (cross(b - a, c - a)). V and S there come
 * from ms_visibility_points with the triangle as receiver and the texel as pattern key; the irradiance is
 * E_unshadowed * S * emission (ms_light_irradiance), E_unshadowed's cosine taken with the shading normal as
 * frames shade (the vertex normals interpolated, turned to the winding's side; the triangle's where the mesh
 * has none), so that smooth surfaces bake smooth. Texels no triangle touches are filled by dilation
 * from their neighbours (across chart seams) so that bilinear lookups do not bleed black. Then the seams
 * are stitched (unless no_seam_stitch): along every UV seam of a smooth edge the texels that bilinear
 * lookups from its two sides read are moved, by least squares, until both sides' lookups agree (the
 * irradiance and every light's S; V stays as baked); no other texel changes (docs/baking.md, "Seams"). */
/* Called at the end of each pass of a bake, from the calling thread, with its name ("UVs", "texels", "leak
 * test", "acceleration structure", "light 1/3", ..., "irradiance and dilation", "seam stitching", "seams") and its seconds: one
 * progress line per pass for a command line (the points' progress callback goes on within the lights). */
typedef void (*ms_bake_pass_fn)(void *user, const char *pass, double seconds);
/* How the objects' own UV layouts (the kept ones: docs/baking.md, "Charts") are placed on the lightmap's pages. */
typedef enum ms_uv_packing {
    /* The file's UVs as they are where they can be (every object in the same set, no overlap, all in [0, 1],
     * no "lightmap" scale, no texel density); else MS_UV_PACK_ISLANDS. */
    MS_UV_PACK_DEFAULT = 0,
    /* Each kept layout's islands (its triangles joined by shared UVs) packed one by one beside xatlas's charts,
     * each keeping its shape at the object's texel density: an object then has no single scale-offset
     * (object_scale_offset 0; engines read the baked UVs, the glTF's TEXCOORD_1). */
    MS_UV_PACK_ISLANDS = 1,
    /* Each object's layout moved whole into a rectangle of its own under one scale and one offset (Unity's
     * lightmapScaleOffset, object_scale_offset): the layouts' empty space travels with them, and two large
     * objects cap the scale, so pages fill less. */
    MS_UV_PACK_REGIONS = 2
} ms_uv_packing;

typedef struct ms_bake_options {
    ms_points_options points;  /* method, pattern, samples, threads, seed, isa, progress; zero: defaults */
    int size;                  /* texels per side; 0: 1024 (at most MS_MAX_IMAGE_SIZE) */
    int uv_set;                /* the UV set tried first (0 .. MS_MAX_UV_SETS-1): per object, the first of
                                * this set and then the others in order that is a valid layout (on every
                                * triangle, with area, no overlap) is kept in a region of its own; objects
                                * without one are charted by xatlas (docs/baking.md, "Charts"); -1: xatlas
                                * for every triangle */
    int dilate;                /* texels of dilation; 0: 4; -1: none */
    int padding;               /* texels between the charts' bilinear footprints (xatlas's charts and the
                                * regions); 0: none, footprints touch but never share a texel (docs/baking.md,
                                * "Padding"); 2 or more for an engine that mipmaps or block-compresses lightmaps */
    int no_leak_fix;           /* 1: texels inside geometry keep their points (docs/baking.md, "Quality"); 0: moved */
    ms_bake_pass_fn pass;      /* may be NULL */
    void *pass_user;
    int no_seam_stitch;        /* 1: the seams keep the baked texels; 0: stitched (docs/baking.md, "Seams") */
    float texel_density;       /* texels per world unit (times each mesh's "lightmap" scale) on as many size x size
                                * pages as it takes (ms_lightmap.pages); 0: everything on one page, at the
                                * largest density that fits */
    const char *uv_cache;      /* a UV cache file (ms_bake_write_uv_cache) to take the UVs from when it was
                                * made for this scene's geometry and these UV options (no unwrap); one that
                                * was not is not used, with a warning; a missing file is not an error. NULL:
                                * none (docs/baking.md, "The unwrap cache") */
    ms_uv_packing uv_packing;  /* how the kept layouts are placed (above); 0: MS_UV_PACK_DEFAULT */
} ms_bake_options;

typedef struct ms_lightmap {
    /* width = size, height = size * pages (one page: a square; "Pages" below); rgb: irradiance E (not
     * radiance, summed over the lights), vis and shadow V
     * and S per light (-1 where neither a triangle nor dilation reached), front: the texel's front samples
     * per light (0 off the triangles);
     * exposure and stats as for frames (visible_pixels: texels on triangles). The ms_output writers and
     * ms_exr_write_stream take &lightmap.frame. */
    ms_frame frame;
    float *position, *normal;  /* 3 floats per texel: where it was evaluated, in the scene's frame (world =
                                * position + ms_scene.origin); NaN off the triangles */
    uint32_t *triangle;        /* per texel: the scene triangle, MS_NO_TRIANGLE off the triangles */
    float *uv;                 /* 6 floats per scene triangle: the UVs baked into, in [0,1]^2; NaN if none */
    size_t n_tris;
    size_t texels;             /* texels on triangles */
    size_t unwrapped_tris;     /* triangles whose UVs xatlas made */
    double unwrap_s, raster_s; /* seconds in xatlas and in the texel rasterization */
    size_t texels_moved;       /* texels whose centre lay inside geometry, moved to the visible side */
    double leak_s;             /* seconds finding them */
    /* Chart seams (ms_bake_finish), after any stitching: where two triangles share an edge in space but not
     * in UVs on a smooth surface (their shading normals the same at both ends, or without shading normals
     * their planes within 8 degrees: across a crease the sides differ by right), the lightmap sampled
     * bilinearly on both sides at 2 points per texel of the edge; the difference of the irradiance's
     * largest channel relative to the lightmap's largest value, mean and max over the points, and their
     * number; seam_p99 their 99th percentile. */
    double seam_mean, seam_max;
    size_t seam_points;
    double seam_p99;
    size_t stitched_texels;    /* texels the seam stitching changed (0 with no_seam_stitch) */
    double stitch_s;           /* seconds stitching */
    /* Triangles left out of the lightmap (ms_bake_layout): excluded_tris of meshes with "lightmap": false (as
     * asked: reported, not warned about); unbaked_tris for any other reason - no area, no UVs (xatlas leaves out
     * triangles of area at most FLT_EPSILON once the scene's extent is scaled to about 1024 units), UVs without area or outside the lightmap - each reason a warning
     * with its count (ms_set_warning_handler). The glb names their primitives and materials after the reason. */
    size_t excluded_tris, unbaked_tris;
    /* Pages (docs/baking.md, "Texel density and pages"): the frame holds them stacked, width size, height
     * size * pages, page p in rows [p * size, (p + 1) * size); uv is in [0,1]^2 of the triangle's page. */
    int pages;
    uint32_t *page;            /* per scene triangle: its page */
    double *page_fill;         /* per page: the fraction of its texels whose centre lies on a triangle */
    /* Per object (ms_scene.tri_object; else per mesh): the UV set its layout was kept from (-1: xatlas
     * charted it, -2: not baked) and, for a kept layout, its scale and offset (uv = file uv * (su, sv) +
     * (ou, ov), 4 floats: su, sv, ou, ov; 0 for xatlas's and for islands packed one by one: MS_UV_PACK_ISLANDS). */
    size_t n_objects;
    int *object_uv_set;
    float *object_scale_offset;
    size_t charts;             /* charts xatlas made (0: none, or the UVs came from the cache) */
    int uv_cached;             /* 1: the UVs came from ms_bake_options.uv_cache, nothing was unwrapped */
    uint64_t uv_key;           /* the hash of what the UVs depend on (geometry, UV sets, scales, UV options) */
} ms_lightmap;

/* Bakes the scene's lights into a lightmap: V, S and front per light (frame.n_lights planes, light l at
 * vis + l*size*size, as frames hold them), the irradiance summed over the lights. accel: the scene's
 * (ms_accel_build), or NULL to build one here. MS_OK, or an error with out zeroed. */
static inline ms_status ms_bake(const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *out,
                                char *err, size_t errlen);
MS_API void ms_lightmap_free(ms_lightmap *lm);

/* A lightmap row by row, for drivers that spread a bake over processes (the CLI's MPI mode): ms_bake is
 * ms_bake_layout, ms_bake_rows over every row, ms_bake_finish. A driver may bake any rows in any number of
 * calls in several lightmaps laid out from the same scene and options, copy the baked rows' vis, shadow and
 * front into one, and finish that one: the same lightmap bit for bit (each texel's V and S depend only on
 * the texel, its point and the seed; the irradiance, exposure and dilation, which look across rows, are
 * finish's). */
/* The options' checks, the UVs (xatlas where needed) and the texels' points: out->position, normal,
 * triangle, texels, and frame's arrays (vis, shadow -1 until baked). MS_OK, or an error with out zeroed. */
static inline ms_status ms_bake_layout(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *out, char *err,
                                       size_t errlen);
/* V, S and front of the texels of rows [y0, y1) for every light of the accel (ms_visibility_points with
 * the texel keys, one call per light), their stats added to lm->frame.stats. lm is left as it was on an
 * error. */
static inline ms_status ms_bake_rows(const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *lm, int y0, int y1,
                                     char *err, size_t errlen);
/* Irradiance (rgb), exposure and dilation over the whole lightmap, once every row was baked; the stats'
 * image fields; total_s: the sum of the parts' seconds. */
static inline ms_status ms_bake_finish(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *lm, char *err,
                                       size_t errlen);

/* The UV cache of a bake (docs/baking.md, "The unwrap cache"): lm's key, UVs, pages and per-object sets and
 * scale-offsets, which a later bake of the same geometry with the same UV options (lights, samples and
 * methods may differ) reads through ms_bake_options.uv_cache instead of unwrapping. An ms_output-style
 * writer; name is for messages. */
static inline ms_status ms_bake_write_uv_cache(const ms_lightmap *lm, FILE *out, const char *name, char *err, size_t errlen);

/* ---- The bake back onto the asset: a binary glTF 2.0 (docs/baking.md, "Back onto the asset") ----
 *
 * The scene's triangles as they were baked, in one .glb: node transforms applied (the loaders flatten every
 * node tree into world positions, so each object is one node with the identity transform,
 * under a root node that carries ms_scene.origin as its translation when it is not zero: positions stay in
 * the scene's frame, as exact as the scene holds them). One glTF node and mesh per object (ms_scene.tri_object:
 * a glTF node's mesh, a file of another format; else per scene-file mesh), one primitive per material in it;
 * vertices welded per primitive where position, normal and both UV sets agree bit for bit (a chart seam or a
 * crease keeps two vertices). Attributes: POSITION, NORMAL (the shading normals where the scene has them,
 * else the triangle's), TEXCOORD_0 (UV set 0 where the primitive has it, else a copy of TEXCOORD_1: glTF
 * numbers the sets densely) and TEXCOORD_1 = the UVs the lightmap was baked into (ms_lightmap.uv), and TANGENT where the
 * material carries a normal texture (the scene's tangents, MikkTSpace's where the asset has none); triangles without
 * baked UVs (a mesh left out of the bake, triangles xatlas left out) form their own primitive without TEXCOORD_1 and
 * without the lightmap, its extras {"name": "not baked: REASON", "triangles": n} and its material's name saying
 * why. The scene's extras.microshadow {lights, exposure, exposure_diffuse}: the scene's lights as ms_scene_lights
 * lists them (the shadowmask channels' "light" indices), in the glb's world coordinates, with their shape, geometry
 * and radiance (docs/baking.md), for a viewer's live lights; the automatic exposures of microshadow's frame of the
 * scene's camera (ms_render_options.shading standard, diffuse), for a viewer's default. Materials carry
 * the scene's base colour, metallic, roughness, emission and alpha mode, and their base-colour, normal,
 * emissive and metallic-roughness textures (the decoded texels re-encoded as PNG: no file is read) where
 * those use UV set 0. Every baked material references:
 *   - the lightmap, extension MOZ_lightmap {index, texCoord: 1, intensity}: the irradiance summed over the
 *     lights (ms_lightmap.frame.rgb), linear (no sRGB curve), divided by its largest value I over the texels
 *     and channels, as an 8-bit RGB PNG; intensity = I restores it (E = texel / 255 * I, within half a step,
 *     I / 510). Texels neither a triangle nor dilation reached are 0;
 *   - the shadowmask in extras.shadowmask {index, texCoord: 1, channels: [{channel, light, shape}]}: S of
 *     lights 0..3 in R, G, B, A of an 8-bit RGBA PNG (linear, S = byte / 255; unused channels 0, alpha 255
 *     when fewer than 4 lights), a warning naming the lights left out beyond 4.
 * Zero-area triangles (no normal) are left out with a warning. */
typedef struct ms_bake_gltf_options {
    int no_textures;     /* 1: materials keep their factors, no embedded material textures */
    int no_shadowmask;   /* 1: no shadowmask image */
} ms_bake_gltf_options;
/* The .glb of scene and its lightmap lm (ms_bake of that scene) into a malloc'ed buffer *glb of *len bytes
 * (free it). opt may be NULL. MS_OK, or an error with *glb = NULL. */
static inline ms_status ms_bake_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                     unsigned char **glb, size_t *len, char *err, size_t errlen);
/* The same written to path (ending in .glb), all or nothing (staged beside it and renamed: ms_outputs_write). */
static inline ms_status ms_bake_write_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                           const char *path, char *err, size_t errlen);

#endif
