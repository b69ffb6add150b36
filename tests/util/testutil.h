/* Shared helpers for the cmocka tests. */
#ifndef MS_TESTUTIL_H
#define MS_TESTUTIL_H
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include "microshadow.h"

/* A fresh directory under the build tree for this test program; returns its path. */
const char *tu_tmpdir(const char *test_name);
/* Path buf = dir/name. */
const char *tu_path(char *buf, size_t n, const char *dir, const char *name);
int tu_write_file(const char *path, const char *text);
int tu_file_exists(const char *path);
/* Number of entries in dir other than . and .. (to prove nothing was left behind). */
int tu_count_entries(const char *dir);
/* Runs the CLI with argv (NULL-terminated, without argv[0]); returns its exit status and the first
 * line of its stderr in err_line. */
int tu_run_cli(const char *const *args, char *err_line, size_t n);
/* tu_run_cli with limits: the child's file size limit (0: none; SIGXFSZ is ignored so writes fail with
 * EFBIG, as on a full disk), umask (-1: inherited) and a time limit (seconds, 0: 120). Returns the exit
 * status (128 + signal if killed), all of stderr, its number of lines, the child's peak RSS in MB and
 * its wall time in seconds. */
typedef struct tu_run_opts { long fsize_limit; int umask; int timeout_s; } tu_run_opts;
typedef struct tu_run_result { int lines; double max_rss_mb, seconds; } tu_run_result;
int tu_run_cli_ex(const char *const *args, const tu_run_opts *opts, char *err_all, size_t n, tu_run_result *res);
/* 1 if ../shared/scenes is present; prints a skip message otherwise. */
int tu_have_shared_scenes(void);
const char *tu_shared_scene(char *buf, size_t n, const char *rel);
/* Reads a PFM written by ms_write_vis into a top-row-first array (caller frees). */
float *tu_read_pfm(const char *path, int *w, int *h);

/* splitmix64: small, seedable, reproducible random numbers for the randomized tests. */
typedef struct tu_rng { uint64_t s; } tu_rng;
static inline uint64_t tu_rng_next(tu_rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

#endif
