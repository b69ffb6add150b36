/* microshadow/render.h, a part of <microshadow.h>: sample patterns, instruction sets, the render options,
 * statistics, frames and frames tile by tile. Programs include <microshadow.h>, which includes every part in
 * order; a part relies on the ones before it. */
#ifndef MICROSHADOW_RENDER_H
#define MICROSHADOW_RENDER_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

typedef enum ms_pattern {
    MS_PATTERN_GRID = 0,       /* k x k lattice, slightly rotated and shifted per pixel (Woop, sec. 6) */
    MS_PATTERN_STRATIFIED = 1, /* k x k jittered strata, jitter hashed from pixel, sample and seed */
    MS_PATTERN_INTERLEAVED = 2 /* Benthin & Wald 2009: N QMC points in all, each pixel of a 4x4 block a
                                * different N/16 of them, then a 4x4 discontinuity-aware filter over V, S */
} ms_pattern;

/* "grid", "stratified", "interleaved" ("unknown" otherwise). */
MS_API const char *ms_pattern_name(ms_pattern p);
/* Parses one of those names; MS_OK, or MS_ERR_INVALID for anything else. */
MS_API ms_status ms_pattern_from_name(const char *name, ms_pattern *out);

/* Instruction-set levels of the SIMD kernels and the traversal, in increasing order. As a cap,
 * MS_ISA_AUTO (0) means none: the best level the CPU runs; a cap above the CPU gives the CPU's best. */
typedef enum ms_isa {
    MS_ISA_AUTO = 0,
    MS_ISA_SCALAR = 1,  /* portable C */
    MS_ISA_AVX2 = 2,    /* AVX2 + FMA + BMI1/2 + LZCNT + POPCNT */
    MS_ISA_AVX512 = 3   /* the above + AVX-512 F/BW/VL/DQ */
} ms_isa;

/* "auto", "scalar", "avx2", "avx512". */
MS_API const char *ms_isa_name(ms_isa isa);
/* Parses one of those names; MS_OK, or MS_ERR_INVALID for anything else. */
MS_API ms_status ms_isa_from_name(const char *name, ms_isa *out);
/* The best level this CPU (and OS: saved register state) runs. */
MS_API ms_isa ms_cpu_isa(void);

/* Progress with cancellation (like Embree's progress monitor), for frames, points and bakes: called with the
 * fraction done, from one thread at a time (never concurrently for one call), fractions growing to 1; return 0
 * to go on, non-zero to cancel the call, which then returns MS_ERR_CANCELLED soon after without results. */
typedef int (*ms_progress_cancel_fn)(void *user, double fraction_done);

/* How the embree method hands rays to Embree (docs/embree.md). */
typedef enum ms_embree_mode {
    MS_EMBREE_PACKET16 = 0,    /* rtcOccluded16 over groups of 16 samples */
    MS_EMBREE_STREAM = 1,      /* one coherent rtcOccluded1M stream per pixel */
    MS_EMBREE_PACKET8 = 2      /* rtcOccluded8 over groups of 8 samples (faster than 16 on some CPUs) */
} ms_embree_mode;

/* When the embree method filters out the receiver's own triangle. */
typedef enum ms_embree_filter {
    MS_EMBREE_FILTER_PLANE = 0,  /* only where a segment can meet its plane in the occluding range */
    MS_EMBREE_FILTER_ALWAYS = 1, /* every pixel (same V, slower) */
    MS_EMBREE_FILTER_NONE = 2    /* never: for measuring only, the receiver then occludes itself */
} ms_embree_filter;

/* How the micro-rasterization methods find the triangles between a point and the light. */
typedef enum ms_traversal {
    MS_TRAVERSAL_AUTO = 0,   /* the default: MS_TRAVERSAL_BLOCK */
    MS_TRAVERSAL_BLOCK = 1,  /* the frusta of a 4x4 pixel block together through a shallow BVH (Benthin & Wald 2009) */
    MS_TRAVERSAL_PIXEL = 2   /* each pixel's frustum alone through the deep BVH (Woop 2010) */
} ms_traversal;

/* Every field's zero means its default, so a zeroed struct renders with the defaults. */
/* Whether a light's occluders leave out the back of closed meshes (ms_render_options.closed_cull). */
typedef enum ms_closed_cull_mode {
    MS_CLOSED_CULL_DEFAULT = 0,   /* the method's measured choice */
    MS_CLOSED_CULL_ON = 1,
    MS_CLOSED_CULL_OFF = 2
} ms_closed_cull_mode;

/* Whether ms_render_outputs writes the outputs as the rows finish (ms_render_options.stream; docs/memory.md). */
typedef enum ms_stream_mode {
    MS_STREAM_AUTO = 0,   /* only when the whole frame would exceed the memory budget and a streamed one fits */
    MS_STREAM_ON = 1,     /* always (refused for frame-level methods and the interleaved filter) */
    MS_STREAM_OFF = 2     /* never: the whole frame in memory, then the outputs */
} ms_stream_mode;

/* What a frame shades (ms_render_options.shading; docs/shading.md). */
typedef enum ms_shading {
    MS_SHADING_STANDARD = 0,  /* the materials as they are: diffuse and GGX specular, emission */
    MS_SHADING_DIFFUSE = 1    /* base colour * E_unshadowed * S / pi alone (no specular, no metallic darkening, no
                               * emission): the picture a lightmap can give, to compare with the baked glb's
                               * viewer (docs/baking.md) */
} ms_shading;

typedef struct ms_render_options {
    const char *method;     /* shadow method by name: see ms_method_names(); NULL: MS_DEFAULT_METHOD */
    ms_pattern pattern;
    int samples;            /* N: 256, 1024 or 4096 (k*k with k = 16, 32, 64), stratified also 16, 64;
                             * 0: the scene's */
    int width, height;      /* 0: the scene camera's */
    int threads;            /* 0: all cores; the host's OpenMP settings are left alone */
    uint32_t seed;
    ms_progress_cancel_fn progress;   /* may be NULL; non-zero from it cancels the frame */
    void *progress_user;
    ms_isa isa;             /* cap on the instruction set of kernels and traversal; MS_ISA_AUTO: the CPU's best */
    /* Switches to measure what a part buys; leave them 0. */
    ms_embree_mode embree_mode;
    ms_embree_filter embree_filter;
    ms_traversal traversal; /* micro-raster methods: block (default) or per-pixel traversal */
    int frustum_shrink;     /* block traversal and mft: also narrow a pixel's traversal frustum as its samples are
                             * occluded (the paper's "FS"; off: only its leaf rectangle shrinks, "CR") */
    int no_filter;          /* interleaved pattern: leave out the 4x4 discontinuity-aware filter (raw V, S) */
    /* Primary visibility (docs/primary.md): NULL pairs it with the shadow method ("bvh", "embree"; "depth"
     * for a streamed procedural scene), else one of bvh, embree, depth (procedural scenes only), 3dr-bb,
     * 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full. A procedural scene is streamed when both the shadow method and the
     * primary stream (3dr-bb, 3dr-bin, depth), else materialised. */
    const char *primary;
    int consistent_primary; /* bvh primary: decide each ray with the 3D rasterizers' consistent edge test
                             * (ties by the top-left rule, t ties to the smaller id): the same hits as 3dr-* */
    ms_closed_cull_mode closed_cull; /* leave out of every light's occluders the triangles of closed meshes that face
                             * away from the whole light: the same V and S (docs/culling.md). Default: on for the
                             * micro-raster methods and mft (with their interior boxes it pays: thin closed parts
                             * halve) and hpc, hpc-scanline (every triangle left out is pairs saved), off for
                             * raytrace (on bulky meshes it costs it: the kept far side projects smaller); embree
                             * never culls */
    int no_interior;        /* micro-raster methods: no interior boxes (virtual occluders inside closed meshes,
                             * docs/culling.md: the same V and S); to measure what they buy */
    int no_merge;           /* micro-raster methods, mft, hpc: occluders as given, without merging the two halves
                             * of axis-aligned rectangles and rectangles sharing a side into one (docs/culling.md:
                             * the same points; the same V and S for mft and hpc, which take each sample from a
                             * set that decides it as the pieces do, and up to ties on the rectangles' sides for
                             * the micro-raster methods) */
    uint64_t max_memory;    /* the memory budget in bytes (ms_memory_budget); 0: the default */
    ms_stream_mode stream;  /* ms_render_outputs only (ms_render always holds the whole frame) */
    int stream_rows;        /* streamed: rows per band of the rendered frame (with anti-aliasing s times the output's,
                             * s = sqrt aa), a multiple of s * MS_TILE_SIZE; 0: about 512 tiles' worth, fewer (down to
                             * s tile rows) when the budget needs */
    /* Pixel anti-aliasing (docs/antialiasing.md): K = aa primary samples per pixel (1, 4, 9 or 16; 0: the
     * scene's render.aa, else 1), on the s x s grid of the pixel's strata centres (s = sqrt K). Each has its own
     * hit, front mask and shadow query (every method answers each as a pixel of an s-times larger frame, on
     * that pixel's samples), and the frame's rgb, V, S and S_spec are their box-filtered average per pixel (V,
     * S over the samples that hit; -1 where none did; rgb counts misses as black). K = 1 is the frame as without
     * anti-aliasing, bit for bit. */
    int aa;
    int aa_split;           /* aa > 1: the pixel's N light samples split among its K hits (N/K each, which must be
                             * a valid sample count for the pattern) instead of all N for every hit */
    ms_shading shading;     /* 0: standard; the automatic exposure is that of the picture shaded */
} ms_render_options;

/* Zeroes o and names the default method: the same as a zeroed struct. */
static inline void ms_render_options_default(ms_render_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = MS_DEFAULT_METHOD;
}

/* Names of the shadow methods compiled in, NULL-terminated. */
MS_API const char *const *ms_method_names(void);
/* 1 if `name` is a known method compiled into this build, 0 if unknown, -1 if known but not compiled in. */
MS_API int ms_method_available(const char *name);

/* Room for a method's named counters in ms_stats: a new figure is a new name here, never a new field of the
 * struct (microshadow/abi.h, "The ABI check"). */
#define MS_MAX_COUNTERS 64

typedef struct ms_stats {
    size_t triangles;
    /* Seconds: scene loading, our BVH build, the methods' own set-up (e.g. Embree's scene build), primary
     * visibility, shadows, and all of it (total_s). */
    double load_s, build_s, setup_s, primary_s, shadow_s, total_s;
    int samples, threads, width, height;   /* samples: N, the frame's light samples */
    int samples_per_pixel;         /* N, or N/16 for the interleaved pattern */
    const char *method;
    const char *pattern;
    const char *kernel_isa;        /* instruction set the method's kernel ran ("none" when it has none) */
    const char *traversal_isa;     /* ... and its traversal */
    uint64_t visible_pixels;
    uint64_t shadow_rays;          /* samples in front of the visible points: the segments every method answers */
    uint64_t penumbra_pixels;      /* pixels with some but not all front samples visible: S needs weights */
    double shadow_factor_s;        /* part of shadow_s spent resolving V and S from the sample masks
                                    * (thread-seconds / threads) */
    double filter_s;               /* part of shadow_s spent in the interleaved pattern's filter (0: none) */
    int n_counters;                /* method-specific counters, by name (ms_stats_counter) */
    const char *counter_name[MS_MAX_COUNTERS];
    uint64_t counter[MS_MAX_COUNTERS];
    double shadow_cpu_s;           /* frames: the process's CPU seconds (all threads) during shadow_s, the
                                    * figure to compare methods by on a machine shared with other work;
                                    * 0 from the points API (other callers may share the process) */
    const char *primary;           /* the primary-visibility method used */
    /* Its counters where it has them (the 3D rasterizers, the consistent bvh caster; Dachsbacher et al.'s
     * Table 1): triangle set-ups, edge-function evaluations, BVH nodes visited; 0 otherwise. */
    uint64_t primary_setups, primary_edge_evals, primary_nodes;
    /* Triangles of closed components left out of the lights' occluders (ms_render_options.closed_cull),
     * and interior boxes rasterized before the triangles (micro-raster methods), summed over the lights
     * (docs/culling.md). */
    uint64_t occluders_culled, interior_boxes;
    uint64_t occluders_merged;     /* triangles saved by merging coplanar rectangles, summed over the lights */
    uint64_t receivers_on_merged;  /* visible points on a merged face, answered on the scene's own triangles by
                                    * the reference tracer (docs/culling.md), summed over the lights */
    uint64_t memory_need;          /* bytes the call estimated it would allocate, checked against its memory budget */
    uint64_t memory_budget;        /* that budget (max_memory, or the default: ms_memory_budget) */
    int stream_rows;               /* ms_render_outputs: the output rows of a band when the outputs were streamed, else 0 */
    int aa;                        /* frames: primary samples per pixel (1, 4, 9, 16); width and height above count
                                    * them (sqrt(aa) times the output's size); 0 from the points API and bakes */
} ms_stats;

/* 1 and *value (may be NULL) when st holds the counter `name`, else 0 (a method or build without it). */
MS_API int ms_stats_counter(const ms_stats *st, const char *name, uint64_t *value);

typedef struct ms_frame {
    int width, height;
    float *vis;       /* width*height, row 0 at the top: V; -1 where the primary ray missed */
    float *shadow;    /* width*height: the shadow factor S; -1 where the primary ray missed */
    uint16_t *front;  /* width*height: the pixel's samples in front of the receiver's plane (0..samples per
                       * pixel); 0 on misses */
    /* With the interleaved pattern (filter on) vis and shadow hold the filtered values: each mixes 16
     * pixels' sample sets, so they are not comparable sample for sample with another method's. */
    float *rgb;       /* 3*width*height linear radiance (docs/shading.md): emission * (c_diff/pi *
                       * E_unshadowed * S + F * LTC_GGX * S_spec); without materials albedo 0.8, no specular */
    float exposure;   /* scale that maps the 99th percentile of unshadowed radiance to 1 (for PNG) */
    ms_stats stats;
    /* The specular shadow factor S_spec (docs/shading.md), one width*height plane per light like shadow:
     * S where the pixel's material has no specular lobe; -1 where the primary ray missed. */
    float *shadow_spec;
    /* Lights of the frame (0 means 1). vis, shadow and front hold one width*height plane per light, light l
     * at vis + l*width*height (the first plane is light 0, as with one light); rgb sums the lights. */
    int n_lights;
} ms_frame;

/* A frame: MS_OK, or a status with a message in err and *out zeroed: MS_ERR_CANCELLED when the progress
 * callback cancelled it, MS_ERR_BUDGET when it would need more memory than the budget (nothing was allocated
 * for it then), MS_ERR_METHOD for a method (or primary) unknown, not compiled in or failing its set-up,
 * MS_ERR_NO_MEMORY, MS_ERR_INVALID for bad options or a bad scene. */
static inline ms_status ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                                  size_t errlen);
MS_API void ms_frame_free(ms_frame *f);

/* ---- A frame tile by tile: for drivers that spread one frame over processes (the CLI's MPI mode) ----
 *
 * ms_render is ms_frame_job_create, one ms_frame_job_render of every tile, and ms_frame_job_finish. A driver
 * may instead render any tiles in any number of calls, in several jobs of the same scene and options (one
 * per process), copy the rendered tiles' pixels of vis, shadow, shadow_spec and front, every light's plane
 * (ms_frame_job_frame), into one job, and finish that one: its frame equals ms_render's bit for bit, because
 * a pixel's V, S and S_spec depend only on the pixel, the seed and the scene, and finish does what depends on
 * the whole frame (primary hits and surfaces of the tiles rendered elsewhere, the interleaved pattern's
 * filter, the textured lights' mean texels, the shading and its exposure). Tiles are
 * MS_TILE_SIZE pixels square, numbered row by row: tile t covers x from MS_TILE_SIZE (t % tiles_x) and y
 * from MS_TILE_SIZE (t / tiles_x), clipped to the frame. A job is used from one thread at a time (each call
 * threads itself). */
#define MS_TILE_SIZE 16
typedef struct ms_frame_job ms_frame_job;
/* Checks the options, builds the acceleration structure and sets up the methods, the shadow method once per
 * light, kept until ms_frame_job_free (what ms_render does first, with its messages). MS_OK and *job, or a status
 * as ms_render's (MS_ERR_BUDGET over the memory budget, before allocating) with *job = NULL. */
static inline ms_status ms_frame_job_create(const ms_scene *scene, const ms_render_options *opt, ms_frame_job **job,
                                            char *err, size_t errlen);
/* The number of tiles; tiles_x and tiles_y (may be NULL) get the frame's tiles per row and per column. */
MS_API int ms_frame_job_tiles(const ms_frame_job *job, int *tiles_x, int *tiles_y);
/* 1 when the method renders split frames with the whole frame's answer; 0 for a frame-level method whose
 * answer at a pixel depends on the others (hpc-scanline), which ms_frame_job_render then refuses unless given
 * the whole frame in its first call. */
MS_API int ms_frame_job_splittable(const ms_frame_job *job);
/* Primary hits, and V, S, S_spec and front for every light, of the n tiles listed (tiles NULL: all of them, n = the number of tiles) into
 * the job's frame, the stats' visible_pixels, shadow_rays, penumbra_pixels, counters and seconds (primary_s,
 * shadow_s, shadow_cpu_s, and shadow_factor_s in thread-seconds until finish) summed over calls. MS_OK, or a status with a message
 * (MS_ERR_CANCELLED when the options' progress callback cancelled: the job's frame is then incomplete). */
MS_API ms_status ms_frame_job_render(ms_frame_job *job, const int *tiles, int n, char *err, size_t errlen);
/* The frame being assembled (full size, n_lights planes; only the rendered tiles' pixels are set;
 * vis, shadow and shadow_spec unfiltered).
 * Owned by the job. A driver may write other jobs' tiles and sums of their stats into it before finish. */
MS_API ms_frame *ms_frame_job_frame(ms_frame_job *job);
/* Completes the frame (see above) and moves it to *out (ms_frame_free it); the job is left empty: free it.
 * Every tile must have been rendered here or copied in. MS_OK, or a status with a message. */
MS_API ms_status ms_frame_job_finish(ms_frame_job *job, ms_frame *out, char *err, size_t errlen);
MS_API void ms_frame_job_free(ms_frame_job *job);

#endif
