/* microshadow/output.h, a part of <microshadow.h>: outputs written all or nothing, the image and statistics
 * writers, frames rendered straight to outputs. Programs include <microshadow.h>, which includes every part in
 * order; a part relies on the ones before it. */
#ifndef MICROSHADOW_OUTPUT_H
#define MICROSHADOW_OUTPUT_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

/* Outputs, all or nothing. A caller that writes several outputs of one frame lists them in an ms_output
 * table: ms_outputs_check before the render refuses bad targets (two outputs to one file, a target that
 * exists and is not a regular file, an unwritable directory, a name past the filesystem's limit, a wrong
 * ending); ms_outputs_write after it writes each to a staging file beside its target and renames them
 * into place only when all were written; any failure removes the staging files, and so do SIGINT,
 * SIGTERM, SIGHUP and SIGQUIT once ms_outputs_cleanup_on_signals was called (for programs: a library
 * caller with its own signal handling need not call it). New files get 0666 less the umask. */
typedef ms_status (*ms_output_write_fn)(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
typedef struct ms_output {
    const char *flag;             /* how the caller named it, for messages ("-o", "--vis") */
    const char *path;             /* NULL: not requested */
    ms_output_write_fn write;     /* one of the writers below, or the caller's own; NULL: the file is `bytes` */
    const char *const *suffixes;  /* NULL-terminated accepted endings (case-insensitive), or NULL: any */
    /* With write NULL, the file's bytes as the caller made them (a file that needs more than the frame, e.g. a
     * glb of the scene and its lightmap): set by the time of ms_outputs_write, checked like any output before. */
    const void *bytes;
    size_t n_bytes;
} ms_output;
#define MS_MAX_OUTPUTS 64   /* a paged lightmap writes each output once per page */
MS_API ms_status ms_outputs_check(const ms_output *outs, int n, char *err, size_t errlen);
/* Before writing anything it checks the frame (ms_frame_check_finite): a NaN or infinite value is an error
 * naming the first output's path and the pixel, and no file is written. */
MS_API ms_status ms_outputs_write(const ms_frame *f, const ms_output *outs, int n, char *err, size_t errlen);
/* 0 when every value of the frame or lightmap (rgb, each light's vis, shadow, shadow_spec; the NULL ones
 * skipped) and, with rgb, the exposure are finite; else MS_ERR_INVALID with one line "what: ... at pixel (x, y) is NaN". */
MS_API ms_status ms_frame_check_finite(const ms_frame *f, const char *what, char *err, size_t errlen);
MS_API void ms_outputs_cleanup_on_signals(void);
/* The writers, ms_<what>_write_stream (an ms_output_write_fn each) and ms_write_<what> for one file alone
 * (checked, staged and renamed): tone-mapped sRGB PNG; the EXR of everything; V resp. S as .pfm or .exr (by
 * name; with several lights the EXR has one channel per light, V0, V1, ... resp. S0, S1, ..., and the PFM
 * light 0); the stats as JSON. The EXR of a frame or lightmap: 32-bit float channels R, G, B (rgb: radiance
 * of frames, irradiance of lightmaps), V and S; with several lights S0, S1, ... and V0, V1, ... (one per
 * light) instead of S and V; it ends in .exr. */
MS_API ms_status ms_png_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_exr_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_vis_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_shadow_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_stats_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API extern const char *const ms_float_image_suffixes[];   /* ".pfm", ".exr": the endings of --vis and --shadow */

/* A frame rendered and written to outs[0..n) (ms_outputs_check them first), all or nothing: the whole frame in
 * memory, then ms_outputs_write; or, streamed (opt->stream, docs/memory.md), band by band of MS_TILE_SIZE-row
 * tile rows, each image output (the writers above) taking a band's rows as they finish, so that memory holds
 * one band of the frame's planes instead of all of them; the PNG last, from the band's radiance spilled to an
 * unlinked scratch file beside it, once its exposure (the exact 99th percentile, from a histogram gathered as the
 * bands finish and one pass over the spill) is known. Byte for byte the same files either way. exposure_ev:
 * stops added to the PNG's automatic exposure. stats (may be NULL) gets the frame's stats. 0; MS_ERR_BUDGET,
 * MS_ERR_CANCELLED or another status when the frame failed (nothing written); MS_ERR_IO when an output failed (nothing
 * written either); each with a message. */
static inline ms_status ms_render_outputs(const ms_scene *scene, const ms_render_options *opt, double exposure_ev,
                                          const ms_output *outs, int n, ms_stats *stats, char *err, size_t errlen);

/* One output alone, all or nothing (checked, staged and renamed). */
MS_API ms_status ms_write_png(const ms_frame *f, const char *path, char *err, size_t errlen);      /* tone-mapped sRGB */
MS_API ms_status ms_write_exr(const ms_frame *f, const char *path, char *err, size_t errlen);      /* .exr, all channels */
MS_API ms_status ms_write_vis(const ms_frame *f, const char *path, char *err, size_t errlen);      /* .pfm or .exr, float V */
MS_API ms_status ms_write_shadow(const ms_frame *f, const char *path, char *err, size_t errlen);   /* .pfm or .exr, float S */
MS_API ms_status ms_write_stats(const ms_frame *f, const char *path, char *err, size_t errlen);    /* JSON */

#endif
