/* The CLI's MPI mode (built with -DMS_MPI=ON, docs/mpi.md): `mpirun -n R microshadow ...` renders one frame
 * (mpi_frame.c) or bakes one lightmap (mpi_bake.c) over R processes. Every rank parses the same command
 * line, loads the scene and builds its own acceleration structure; rank 0 alone writes the outputs.
 *
 * Failing as one: every rank's stderr is held in memory until the ranks agree on the outcome
 * (ms_mpi_agree); then only the first failing rank's lines are printed (rank 0's on success), so a run
 * in which one rank cannot read its scene ends with that one message, exit code 2 on every rank, and no
 * output. The agreements are collective: every rank passes through the same ones in the same order, or
 * leaves early through ms_mpi_end, which takes part in the one the others are waiting in. */
#ifndef MS_CLI_MPI_RUN_H
#define MS_CLI_MPI_RUN_H
#include "microshadow.h"

/* 1 when launched by an MPI launcher (OpenMPI's mpirun, or any PMI/PMIx one): MPI is then initialised
 * (MPI_THREAD_FUNNELED: OpenMP threads inside a rank, MPI calls from its main thread only) and stderr held.
 * 0 otherwise (the plain single-process CLI, MPI never touched). */
int ms_mpi_start(int *argc, char ***argv);
int ms_mpi_active(void);
int ms_mpi_rank(void);
int ms_mpi_size(void);
/* Collective: every rank says whether it failed; returns 0 when none did, else 1 on every rank (and
 * remembers the first failing rank, whose held stderr ms_mpi_end prints). */
int ms_mpi_agree(int failed);
/* Collective unless a failure was agreed already: agrees on rc (non-zero: failed), prints the held stderr
 * of the first failing rank (or rank 0's), finalises MPI. Returns the exit code for every rank. */
int ms_mpi_end(int rc);

/* Out of memory where the ranks cannot go on in step (the gather's bookkeeping): the message straight to
 * the real stderr, then MPI_Abort (mpirun ends every rank). */
void ms_mpi_fatal(const char *msg);

/* Work distribution: how ranks get chunks of work (tiles of a frame, row bands of a lightmap). */
typedef enum ms_mpi_schedule {
    MS_MPI_QUEUE = 0,    /* rank 0 hands out chunks on request (two-sided messages), rendering between requests */
    MS_MPI_COUNTER = 1,  /* a shared counter on rank 0 that every rank advances with MPI_Fetch_and_op */
    MS_MPI_STATIC = 2    /* chunk c to rank c mod R, for comparison */
} ms_mpi_schedule;
int ms_mpi_schedule_from_name(const char *name, ms_mpi_schedule *out);
const char *ms_mpi_schedule_name(ms_mpi_schedule s);

/* Per rank, what it did (for --stats: "mpi"). */
typedef struct ms_mpi_report {
    int ranks, threads, chunk;
    ms_mpi_schedule schedule;
    double distribute_s;          /* rank 0: wall seconds from the first chunk to the last result in */
    int *rank_chunks, *rank_units;/* per rank: chunks and tiles (texel rows) it did */
    double *rank_busy_s;          /* per rank: seconds rendering its chunks */
    double *rank_wall_s;          /* per rank: seconds from start to its results sent */
} ms_mpi_report;

/* The callback that does one chunk of work on a rank: units [first, first + count). 0 or -1 (err set). */
typedef int (*ms_mpi_work_fn)(void *user, int first, int count, char *err, size_t errlen);
/* Runs every chunk of nunits units (chunk units each) on some rank under the schedule; every rank calls it.
 * done: per unit, set to 1 where this rank did it (nunits entries). Fills the report's per-rank arrays on
 * rank 0 (allocated here; ms_mpi_report_free). Returns 0, or -1 when this rank's work failed (err set); the
 * other ranks go on and the caller agrees afterwards. */
int ms_mpi_distribute(ms_mpi_schedule sched, int nunits, int chunk, ms_mpi_work_fn work, void *user,
                      unsigned char *done, ms_mpi_report *rep, char *err, size_t errlen);
void ms_mpi_report_free(ms_mpi_report *rep);
/* The report as a JSON object's text (no braces around it: "\"mpi\": {...}"), into f. */
void ms_mpi_report_json(const ms_mpi_report *rep, FILE *f);
/* An ms_output_write_fn for --stats in MPI mode: the frame's stats JSON with the "mpi" report added. */
ms_status ms_mpi_stats_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
/* The report ms_mpi_stats_write_stream adds (set by the frame or bake driver on rank 0). */
extern ms_mpi_report ms_mpi_last_report;

/* A fingerprint of the scene and options; ranks compare theirs (ms_mpi_same). */
uint64_t ms_mpi_hash(uint64_t h, const void *data, size_t n);
/* h extended by every light of the scene (shape, frame, emission, texels). */
uint64_t ms_mpi_hash_lights(uint64_t h, const ms_scene *s);
/* Collective: 1 when every rank's h is rank 0's. */
int ms_mpi_same(uint64_t h);

/* The frame over all ranks (mpi_frame.c): on success every rank returns 0 and rank 0 has the frame in
 * *out (others a zeroed frame); -1 when the ranks agreed on a failure (its message, "microshadow: WHAT:
 * problem", held for ms_mpi_end). */
int ms_mpi_frame(const ms_scene *scene, const char *what, const ms_render_options *opt, ms_mpi_schedule sched,
                 int chunk, ms_frame *out, char *err, size_t errlen);
/* The lightmap likewise (mpi_bake.c); units are texel rows. */
int ms_mpi_bake(const ms_scene *scene, const char *what, const ms_bake_options *opt, ms_mpi_schedule sched,
                int chunk, ms_lightmap *out, char *err, size_t errlen);

#endif
