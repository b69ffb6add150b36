/* The MPI mode's common part (mpi_run.h): start and end, agreeing on failure, and handing out chunks of
 * work by one of three schedules. */
#include "mpi_run.h"
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_active, g_rank, g_size = 1;
static int g_failed_agreed, g_first_failed = -1;
static FILE *g_real_stderr;
static char *g_held;
static size_t g_held_len;
ms_mpi_report ms_mpi_last_report;

int ms_mpi_active(void) { return g_active; }
int ms_mpi_rank(void) { return g_rank; }
int ms_mpi_size(void) { return g_size; }

int ms_mpi_start(int *argc, char ***argv)
{
    /* Launched by mpirun (OpenMPI), or a PMI/PMIx launcher: only then is MPI initialised, so that the plain
     * CLI never starts an MPI singleton. */
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMIX_RANK") && !getenv("PMI_RANK")) return 0;
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "microshadow: MPI_Init_thread failed\n");
        exit(2);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    g_active = 1;
    if (provided < MPI_THREAD_FUNNELED && g_rank == 0)
        fprintf(stderr, "microshadow: warning: the MPI library gives no MPI_THREAD_FUNNELED; OpenMP threads may not be safe\n");
    /* Hold stderr until the ranks agree on the outcome (ms_mpi_end prints one rank's lines). glibc's stderr
     * is an assignable variable; library messages written to it are held too. */
    FILE *held = open_memstream(&g_held, &g_held_len);
    if (held) {
        g_real_stderr = stderr;
        stderr = held;
    }
    return 1;
}

int ms_mpi_agree(int failed)
{
    int me = failed ? g_rank : g_size, first = g_size;
    MPI_Allreduce(&me, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first < g_size) {
        g_failed_agreed = 1;
        g_first_failed = first;
        return 1;
    }
    return 0;
}

int ms_mpi_end(int rc)
{
    if (!g_failed_agreed) ms_mpi_agree(rc != 0);
    int code = rc ? rc : 2;
    if (g_failed_agreed) MPI_Bcast(&code, 1, MPI_INT, g_first_failed, MPI_COMM_WORLD);
    else code = 0;
    if (g_real_stderr) {
        fflush(stderr);
        fclose(stderr);
        stderr = g_real_stderr;
        if (g_rank == (g_failed_agreed ? g_first_failed : 0) && g_held_len) fwrite(g_held, 1, g_held_len, stderr);
        fflush(stderr);
        free(g_held);
        g_held = NULL;
    }
    ms_mpi_report_free(&ms_mpi_last_report);
    MPI_Finalize();
    return code;
}

void ms_mpi_fatal(const char *msg)
{
    dprintf(2, "microshadow: rank %d: %s\n", g_rank, msg);
    MPI_Abort(MPI_COMM_WORLD, 1);
    exit(1);
}

int ms_mpi_schedule_from_name(const char *name, ms_mpi_schedule *out)
{
    if (!strcmp(name, "queue")) *out = MS_MPI_QUEUE;
    else if (!strcmp(name, "counter")) *out = MS_MPI_COUNTER;
    else if (!strcmp(name, "static")) *out = MS_MPI_STATIC;
    else return -1;
    return 0;
}

const char *ms_mpi_schedule_name(ms_mpi_schedule s)
{
    return s == MS_MPI_QUEUE ? "queue" : s == MS_MPI_COUNTER ? "counter" : s == MS_MPI_STATIC ? "static" : "unknown";
}

void ms_mpi_report_free(ms_mpi_report *rep)
{
    free(rep->rank_chunks);
    free(rep->rank_units);
    free(rep->rank_busy_s);
    free(rep->rank_wall_s);
    memset(rep, 0, sizeof *rep);
}

typedef struct runner {
    ms_mpi_work_fn work;
    void *user;
    int nunits, chunk;
    unsigned char *done;
    int failed, chunks, units;
    double busy_s;
    char *err;
    size_t errlen;
} runner;

/* One chunk on this rank. After a failure the rank still takes its chunks (marking them done, so that the
 * gather stays regular) but no longer works: the agreement afterwards fails the run. */
static void run_chunk(runner *r, int c)
{
    const int first = c * r->chunk;
    const int count = r->nunits - first < r->chunk ? r->nunits - first : r->chunk;
    if (!r->failed) {
        const double t = MPI_Wtime();
        if (r->work(r->user, first, count, r->err, r->errlen)) r->failed = 1;
        r->busy_s += MPI_Wtime() - t;
    }
    memset(r->done + first, 1, (size_t)count);
    r->chunks++;
    r->units += count;
}

enum { TAG_REQUEST = 17, TAG_REPLY = 18 };

/* Rank 0 hands out chunks in order on request and works on the next one itself between requests. It sees a
 * request only between its own chunks, so every worker keeps QUEUE_DEPTH requests in flight: asking for the
 * next chunks as soon as it starts one, it has work in hand while rank 0 is busy, and can take up to
 * QUEUE_DEPTH chunks per chunk of rank 0's (with one request in flight a worker was paced to rank 0's chunks
 * and idled: docs/mpi.md). Replies between two ranks arrive in request order (MPI's non-overtaking rule);
 * once the chunks are out every request gets "none" (-1), QUEUE_DEPTH per worker. */
#define QUEUE_DEPTH 2
static void schedule_queue(runner *r, int nchunks)
{
    int dummy = 0;
    if (g_rank == 0) {
        int next = 0, nones = (g_size - 1) * QUEUE_DEPTH;   /* "none" replies still to send */
        for (;;) {
            MPI_Status st;
            int flag = 1;
            while (nones > 0 && flag) {
                MPI_Iprobe(MPI_ANY_SOURCE, TAG_REQUEST, MPI_COMM_WORLD, &flag, &st);
                if (!flag) break;
                MPI_Recv(&dummy, 1, MPI_INT, st.MPI_SOURCE, TAG_REQUEST, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                int give = next < nchunks ? next++ : -1;
                nones -= give < 0;
                MPI_Send(&give, 1, MPI_INT, st.MPI_SOURCE, TAG_REPLY, MPI_COMM_WORLD);
            }
            if (next < nchunks) { run_chunk(r, next++); continue; }
            if (nones == 0) break;
            MPI_Recv(&dummy, 1, MPI_INT, MPI_ANY_SOURCE, TAG_REQUEST, MPI_COMM_WORLD, &st);
            const int none = -1;
            nones--;
            MPI_Send(&none, 1, MPI_INT, st.MPI_SOURCE, TAG_REPLY, MPI_COMM_WORLD);
        }
        return;
    }
    int got[QUEUE_DEPTH], live = QUEUE_DEPTH;
    MPI_Request rq[QUEUE_DEPTH][2];
    for (int d = 0; d < QUEUE_DEPTH; d++) {
        MPI_Isend(&dummy, 1, MPI_INT, 0, TAG_REQUEST, MPI_COMM_WORLD, &rq[d][0]);
        MPI_Irecv(&got[d], 1, MPI_INT, 0, TAG_REPLY, MPI_COMM_WORLD, &rq[d][1]);
    }
    for (int d = 0; live > 0; d = (d + 1) % QUEUE_DEPTH) {
        MPI_Waitall(2, rq[d], MPI_STATUSES_IGNORE);
        if (got[d] < 0) { live--; continue; }
        const int c = got[d];
        MPI_Isend(&dummy, 1, MPI_INT, 0, TAG_REQUEST, MPI_COMM_WORLD, &rq[d][0]);
        MPI_Irecv(&got[d], 1, MPI_INT, 0, TAG_REPLY, MPI_COMM_WORLD, &rq[d][1]);
        run_chunk(r, c);
    }
}

/* A shared counter in rank 0's memory: each rank takes the next chunk with one atomic fetch-and-add
 * (passive target: rank 0 takes part only as a worker). */
static void schedule_counter(runner *r, int nchunks)
{
    int *base = NULL;
    MPI_Win win;
    MPI_Win_allocate(g_rank == 0 ? (MPI_Aint)sizeof(int) : 0, sizeof(int), MPI_INFO_NULL, MPI_COMM_WORLD, &base, &win);
    if (g_rank == 0) {
        MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, win);
        *base = 0;
        MPI_Win_unlock(0, win);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    MPI_Win_lock_all(0, win);
    for (;;) {
        const int one = 1;
        int got = 0;
        MPI_Fetch_and_op(&one, &got, MPI_INT, 0, 0, MPI_SUM, win);
        MPI_Win_flush(0, win);
        if (got >= nchunks) break;
        run_chunk(r, got);
    }
    MPI_Win_unlock_all(win);
    MPI_Win_free(&win);
}

int ms_mpi_distribute(ms_mpi_schedule sched, int nunits, int chunk, ms_mpi_work_fn work, void *user,
                      unsigned char *done, ms_mpi_report *rep, char *err, size_t errlen)
{
    runner r = { work, user, nunits, chunk, done, 0, 0, 0, 0.0, err, errlen };
    memset(done, 0, (size_t)nunits);
    const int nchunks = (nunits + chunk - 1) / chunk;
    const double t0 = MPI_Wtime();
    if (sched == MS_MPI_STATIC || g_size == 1)
        for (int c = g_rank; c < nchunks; c += g_size) run_chunk(&r, c);
    else if (sched == MS_MPI_COUNTER) schedule_counter(&r, nchunks);
    else schedule_queue(&r, nchunks);
    const double wall = MPI_Wtime() - t0;
    int mine_i[2] = { r.chunks, r.units };
    double mine_d[2] = { r.busy_s, wall };
    int *all_i = g_rank == 0 ? malloc(2 * (size_t)g_size * sizeof *all_i) : NULL;
    double *all_d = g_rank == 0 ? malloc(2 * (size_t)g_size * sizeof *all_d) : NULL;
    MPI_Gather(mine_i, 2, MPI_INT, all_i, 2, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Gather(mine_d, 2, MPI_DOUBLE, all_d, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (g_rank == 0) {
        memset(rep, 0, sizeof *rep);
        rep->ranks = g_size;
        rep->chunk = chunk;
        rep->schedule = sched;
        rep->rank_chunks = malloc((size_t)g_size * sizeof *rep->rank_chunks);
        rep->rank_units = malloc((size_t)g_size * sizeof *rep->rank_units);
        rep->rank_busy_s = malloc((size_t)g_size * sizeof *rep->rank_busy_s);
        rep->rank_wall_s = malloc((size_t)g_size * sizeof *rep->rank_wall_s);
        if (all_i && all_d && rep->rank_chunks && rep->rank_units && rep->rank_busy_s && rep->rank_wall_s)
            for (int i = 0; i < g_size; i++) {
                rep->rank_chunks[i] = all_i[2 * i];
                rep->rank_units[i] = all_i[2 * i + 1];
                rep->rank_busy_s[i] = all_d[2 * i];
                rep->rank_wall_s[i] = all_d[2 * i + 1];
            }
        else ms_mpi_report_free(rep);
    }
    free(all_i);
    free(all_d);
    return r.failed ? -1 : 0;
}

void ms_mpi_report_json(const ms_mpi_report *rep, FILE *f)
{
    double busy_max = 0.0, busy_sum = 0.0;
    for (int i = 0; rep->rank_busy_s && i < rep->ranks; i++) {
        busy_sum += rep->rank_busy_s[i];
        busy_max = rep->rank_busy_s[i] > busy_max ? rep->rank_busy_s[i] : busy_max;
    }
    fprintf(f, "\"mpi\": {\n\t\t\"ranks\": %d,\n\t\t\"threads_per_rank\": %d,\n\t\t\"schedule\": \"%s\",\n\t\t\"chunk\": %d,\n"
               "\t\t\"distribute_s\": %.6f,\n\t\t\"busy_max_over_mean\": %.4f,\n\t\t\"per_rank\": [",
            rep->ranks, rep->threads, ms_mpi_schedule_name(rep->schedule), rep->chunk, rep->distribute_s,
            busy_sum > 0 ? busy_max / (busy_sum / rep->ranks) : 0.0);
    for (int i = 0; rep->rank_busy_s && i < rep->ranks; i++)
        fprintf(f, "%s{\"rank\": %d, \"chunks\": %d, \"units\": %d, \"busy_s\": %.6f, \"wall_s\": %.6f}", i ? ", " : "",
                i, rep->rank_chunks[i], rep->rank_units[i], rep->rank_busy_s[i], rep->rank_wall_s[i]);
    fprintf(f, "]\n\t}");
}

ms_status ms_mpi_stats_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    if (!m) { snprintf(err, errlen, "%s: out of memory", name); return MS_ERR_NO_MEMORY; }
    const ms_status rc = ms_stats_write_stream(f, m, name, err, errlen);
    fclose(m);
    if (rc) { free(buf); return rc; }
    /* The library's JSON object ends in "}\n": reopen it for the report. */
    while (len && (buf[len - 1] == '\n' || buf[len - 1] == '}')) {
        const int brace = buf[len - 1] == '}';
        len--;
        if (brace) break;
    }
    fwrite(buf, 1, len, out);
    free(buf);
    fputs(",\n\t", out);
    ms_mpi_report_json(&ms_mpi_last_report, out);
    fputs("\n}\n", out);
    return MS_OK;
}

uint64_t ms_mpi_hash(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    if (!h) h = 1469598103934665603ull;   /* FNV-1a */
    for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

uint64_t ms_mpi_hash_lights(uint64_t h, const ms_scene *s)
{
    size_t nl;
    const ms_light *lights = ms_scene_lights(s, &nl);
    h = ms_mpi_hash(h, &nl, sizeof nl);
    for (size_t l = 0; l < nl; l++) {   /* field by field: no padding, and the texels, not their address */
        const ms_light *L = &lights[l];
        const float f[] = { L->corner.x, L->corner.y, L->corner.z, L->edge_s.x, L->edge_s.y, L->edge_s.z,
                            L->edge_t.x, L->edge_t.y, L->edge_t.z, L->emission.x, L->emission.y, L->emission.z,
                            L->center.x, L->center.y, L->center.z, L->radius };
        const int d[] = { (int)L->shape, L->texture != NULL, L->texture_width, L->texture_height };
        h = ms_mpi_hash(h, f, sizeof f);
        h = ms_mpi_hash(h, d, sizeof d);
        if (L->texture)
            h = ms_mpi_hash(h, L->texture, (size_t)L->texture_width * (size_t)L->texture_height * 3 * sizeof *L->texture);
    }
    return h;
}

int ms_mpi_same(uint64_t h)
{
    uint64_t h0 = h;
    MPI_Bcast(&h0, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    int differ = h0 != h, any = 0;
    MPI_Allreduce(&differ, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return !any;
}
