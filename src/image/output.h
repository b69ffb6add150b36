/* Outputs, all or nothing: every output is written to a staging file beside its target and the staging
 * files are renamed into place only when all of them were written; any failure, and SIGINT, SIGTERM,
 * SIGHUP or SIGQUIT meanwhile, removes them. Targets are checked before the render: each its own file,
 * a regular file or a new name, in a writable directory, the name within the filesystem's limit. */
#ifndef MS_OUTPUT_H
#define MS_OUTPUT_H
#include "microshadow.h"
#include <stdio.h>

/* Writes the frame to out; name is the target (messages, format by extension). */
typedef int (*ms_output_write_fn)(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);

typedef struct ms_output {
    const char *flag;             /* the option that named it, for messages ("-o", "--vis") */
    const char *path;             /* NULL: not requested */
    ms_output_write_fn write;
    const char *const *suffixes;  /* NULL-terminated accepted endings (case-insensitive), or NULL: any */
} ms_output;

#define MS_MAX_OUTPUTS 8

int ms_outputs_check(const ms_output *outs, int n, char *err, size_t errlen);
int ms_outputs_write(const ms_frame *f, const ms_output *outs, int n, char *err, size_t errlen);
/* Installs the signal handlers that remove staging files (signals ignored at start stay ignored). */
void ms_outputs_cleanup_on_signals(void);

/* The writers. */
int ms_png_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
int ms_vis_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
int ms_stats_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
extern const char *const ms_vis_suffixes[];

#endif
