/* microshadow/abi.h, a part of <microshadow.h>: the ABI check: struct sizes handed to the library, the exported
 * *_abi entry points and the inline wrappers. Programs include <microshadow.h>, which includes every part in
 * order; a part relies on the ones before it. */
#ifndef MICROSHADOW_ABI_H
#define MICROSHADOW_ABI_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

/* ---- The ABI check ----
 *
 * Each checked entry point of the other parts (ms_scene_load, ms_scene_load_ex, ms_scene_default, ms_scene_showcase,
 * ms_render, ms_render_outputs, ms_frame_job_create, ms_accel_build, ms_visibility_points, ms_bake,
 * ms_bake_layout, ms_bake_rows, ms_bake_finish, ms_bake_gltf, ms_bake_write_gltf, ms_bake_write_uv_cache) is an
 * inline function that hands the library the ABI level and the size of every public struct as the program was
 * compiled (ms_abi_compiled), and the library compares them with its own before it reads or writes any: a
 * program built against another ABI level, or with a struct the library cannot read at the size given, gets
 * MS_ERR_INVALID and one line naming the first struct that differs, never a struct read or written at the wrong
 * size.
 *
 * The ABI level (MS_ABI_LEVEL) changes only when a field of a public struct moves or changes; the soname carries
 * it (libmicroshadow.so.0.<level> before 1.0). Within a level:
 * - the option structs (ms_scene_load_options, ms_render_options, ms_points_options, ms_bake_options,
 *   ms_bake_gltf_options) only grow at their end, each new field placed at or past the struct's previous size:
 *   a program built against an earlier header of the level passes them smaller, and the library reads the
 *   bytes passed and takes zero, the default, for the fields the program does not know;
 * - every other struct keeps its size. A method's new figure is a named counter of ms_stats (counter_name,
 *   counter; ms_stats_counter finds one by name), never a new field.
 * Bindings that mirror the structs call the *_abi functions with their mirrors' sizes (0 for a struct they do
 * not mirror: not compared). */
typedef struct ms_abi {
    uint32_t abi_size;                      /* sizeof(ms_abi): the fields that follow that the caller knows */
    uint32_t abi_level;                     /* MS_ABI_LEVEL; 0: not compared */
    uint32_t version_minor;                 /* MS_VERSION_MINOR, for messages only */
    uint32_t camera, light, procedural, scene, texture, texture_sampling, material, scene_load_options,
             render_options, stats, frame, output, points, points_options, bake_options, lightmap,
             bake_gltf_options;
} ms_abi;

static inline const ms_abi *ms_abi_compiled(void)
{
    static const ms_abi abi = {
        (uint32_t)sizeof(ms_abi), MS_ABI_LEVEL, MS_VERSION_MINOR, (uint32_t)sizeof(ms_camera),
        (uint32_t)sizeof(ms_light), (uint32_t)sizeof(ms_procedural), (uint32_t)sizeof(ms_scene),
        (uint32_t)sizeof(ms_texture), (uint32_t)sizeof(ms_texture_sampling), (uint32_t)sizeof(ms_material),
        (uint32_t)sizeof(ms_scene_load_options), (uint32_t)sizeof(ms_render_options), (uint32_t)sizeof(ms_stats),
        (uint32_t)sizeof(ms_frame), (uint32_t)sizeof(ms_output), (uint32_t)sizeof(ms_points),
        (uint32_t)sizeof(ms_points_options), (uint32_t)sizeof(ms_bake_options), (uint32_t)sizeof(ms_lightmap),
        (uint32_t)sizeof(ms_bake_gltf_options)
    };
    return &abi;
}

/* The exported forms of the checked entry points: abi first, then the arguments documented in the other parts
 * (ms_scene_load is ms_scene_load_abi with opt NULL). */
MS_API ms_status ms_scene_load_abi(const ms_abi *abi, const char *json_path, const ms_scene_load_options *opt,
                                   ms_scene *out, char *err, size_t errlen);
MS_API ms_status ms_scene_default_abi(const ms_abi *abi, ms_scene *out);
MS_API ms_status ms_scene_showcase_abi(const ms_abi *abi, ms_scene *out);
MS_API ms_status ms_render_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt, ms_frame *out,
                               char *err, size_t errlen);
MS_API ms_status ms_render_outputs_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                       double exposure_ev, const ms_output *outs, int n, ms_stats *stats, char *err,
                                       size_t errlen);
MS_API ms_status ms_frame_job_create_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                         ms_frame_job **job, char *err, size_t errlen);
MS_API ms_status ms_accel_build_abi(const ms_abi *abi, const ms_scene *scene, int threads, ms_accel **out, char *err,
                                    size_t errlen);
MS_API ms_status ms_visibility_points_abi(const ms_abi *abi, const ms_accel *a, const ms_light *light,
                                          const ms_points *pts, const ms_points_options *opt, float *vis,
                                          float *shadow, uint16_t *front, ms_stats *stats, char *err, size_t errlen);
MS_API ms_status ms_bake_abi(const ms_abi *abi, const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt,
                             ms_lightmap *out, char *err, size_t errlen);
MS_API ms_status ms_bake_layout_abi(const ms_abi *abi, const ms_scene *scene, const ms_bake_options *opt,
                                    ms_lightmap *out, char *err, size_t errlen);
MS_API ms_status ms_bake_rows_abi(const ms_abi *abi, const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *lm,
                                  int y0, int y1, char *err, size_t errlen);
MS_API ms_status ms_bake_finish_abi(const ms_abi *abi, const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *lm,
                                    char *err, size_t errlen);
MS_API ms_status ms_bake_write_uv_cache_abi(const ms_abi *abi, const ms_lightmap *lm, FILE *out, const char *name, char *err,
                                            size_t errlen);
MS_API ms_status ms_bake_gltf_abi(const ms_abi *abi, const ms_scene *scene, const ms_lightmap *lm,
                                  const ms_bake_gltf_options *opt, unsigned char **glb, size_t *len, char *err,
                                  size_t errlen);
MS_API ms_status ms_bake_write_gltf_abi(const ms_abi *abi, const ms_scene *scene, const ms_lightmap *lm,
                                        const ms_bake_gltf_options *opt, const char *path, char *err, size_t errlen);

static inline ms_status ms_scene_load(const char *json_path, ms_scene *out, char *err, size_t errlen)
{ return ms_scene_load_abi(ms_abi_compiled(), json_path, NULL, out, err, errlen); }
static inline ms_status ms_scene_load_ex(const char *json_path, const ms_scene_load_options *opt, ms_scene *out, char *err,
                                         size_t errlen)
{ return ms_scene_load_abi(ms_abi_compiled(), json_path, opt, out, err, errlen); }
static inline ms_status ms_scene_default(ms_scene *out) { return ms_scene_default_abi(ms_abi_compiled(), out); }
static inline ms_status ms_scene_showcase(ms_scene *out) { return ms_scene_showcase_abi(ms_abi_compiled(), out); }
static inline ms_status ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                                  size_t errlen)
{ return ms_render_abi(ms_abi_compiled(), scene, opt, out, err, errlen); }
static inline ms_status ms_render_outputs(const ms_scene *scene, const ms_render_options *opt, double exposure_ev,
                                          const ms_output *outs, int n, ms_stats *stats, char *err, size_t errlen)
{ return ms_render_outputs_abi(ms_abi_compiled(), scene, opt, exposure_ev, outs, n, stats, err, errlen); }
static inline ms_status ms_frame_job_create(const ms_scene *scene, const ms_render_options *opt, ms_frame_job **job,
                                            char *err, size_t errlen)
{ return ms_frame_job_create_abi(ms_abi_compiled(), scene, opt, job, err, errlen); }
static inline ms_status ms_accel_build(const ms_scene *scene, int threads, ms_accel **out, char *err, size_t errlen)
{ return ms_accel_build_abi(ms_abi_compiled(), scene, threads, out, err, errlen); }
static inline ms_status ms_visibility_points(const ms_accel *a, const ms_light *light, const ms_points *pts,
                                             const ms_points_options *opt, float *vis, float *shadow, uint16_t *front,
                                             ms_stats *stats, char *err, size_t errlen)
{ return ms_visibility_points_abi(ms_abi_compiled(), a, light, pts, opt, vis, shadow, front, stats, err, errlen); }
static inline ms_status ms_bake(const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *out,
                                char *err, size_t errlen)
{ return ms_bake_abi(ms_abi_compiled(), scene, accel, opt, out, err, errlen); }
static inline ms_status ms_bake_layout(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *out, char *err,
                                       size_t errlen)
{ return ms_bake_layout_abi(ms_abi_compiled(), scene, opt, out, err, errlen); }
static inline ms_status ms_bake_rows(const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *lm, int y0, int y1,
                                     char *err, size_t errlen)
{ return ms_bake_rows_abi(ms_abi_compiled(), accel, opt, lm, y0, y1, err, errlen); }
static inline ms_status ms_bake_finish(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *lm, char *err,
                                       size_t errlen)
{ return ms_bake_finish_abi(ms_abi_compiled(), scene, opt, lm, err, errlen); }
static inline ms_status ms_bake_write_uv_cache(const ms_lightmap *lm, FILE *out, const char *name, char *err, size_t errlen)
{ return ms_bake_write_uv_cache_abi(ms_abi_compiled(), lm, out, name, err, errlen); }
static inline ms_status ms_bake_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                     unsigned char **glb, size_t *len, char *err, size_t errlen)
{ return ms_bake_gltf_abi(ms_abi_compiled(), scene, lm, opt, glb, len, err, errlen); }
static inline ms_status ms_bake_write_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                           const char *path, char *err, size_t errlen)
{ return ms_bake_write_gltf_abi(ms_abi_compiled(), scene, lm, opt, path, err, errlen); }

#endif
