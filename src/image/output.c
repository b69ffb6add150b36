#include "microshadow.h"
#include "image_rows.h"
#include "output_stream.h"
#include <errno.h>
#include <math.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Staging files that exist right now, for the signal handler: it may only read these. */
static char g_stage[MS_MAX_OUTPUTS][PATH_MAX];
static volatile sig_atomic_t g_live[MS_MAX_OUTPUTS];

/* A signal can be delivered to any thread that does not block it, e.g. an idle OpenMP worker, so
 * blocking signals in the writing thread alone does not keep the handler out of its critical
 * sections (creating, removing or committing staging files). One atomic state serialises them: the
 * handler only acts from IDLE; a signal that arrives while the writer is BUSY is recorded and
 * re-raised when the writer leaves, so it finds every rename done or none. (CI saw one output
 * committed without the other two when SIGTERM landed on a worker thread in the middle of the
 * renames.) */
enum { STATE_IDLE, STATE_BUSY, STATE_DYING };
static atomic_int g_state = STATE_IDLE;
/* The deferred signal: written by a handler on one thread, read by the writer on another, so an atomic
 * (lock-free here, hence safe in a handler), not a volatile sig_atomic_t, which orders only within one
 * thread (ThreadSanitizer found the race). */
_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "the signal handler needs a lock-free atomic int");
static atomic_int g_pending;

static void on_signal(int sig)
{
    int expect = STATE_IDLE;
    if (!atomic_compare_exchange_strong(&g_state, &expect, STATE_DYING) && expect == STATE_BUSY) {
        atomic_store(&g_pending, sig);
        /* The writer may have left between the failed exchange and the store above; then nobody
         * would re-raise, so try once more. */
        expect = STATE_IDLE;
        if (!atomic_compare_exchange_strong(&g_state, &expect, STATE_DYING)) return;
    }
    for (int i = 0; i < MS_MAX_OUTPUTS; i++)
        if (g_live[i]) unlink(g_stage[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

static const int g_signals[] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT };

void ms_outputs_cleanup_on_signals(void)
{
    for (size_t i = 0; i < sizeof g_signals / sizeof g_signals[0]; i++) {
        struct sigaction old, sa;
        if (sigaction(g_signals[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(g_signals[i], &sa, NULL);
    }
}

/* Enters a critical section: the signals blocked in this thread, and the state BUSY so that a
 * handler running on another thread defers. When the handler already owns the state the process is
 * being killed: wait for it. */
static void block(sigset_t *old)
{
    sigset_t s;
    sigemptyset(&s);
    for (size_t i = 0; i < sizeof g_signals / sizeof g_signals[0]; i++) sigaddset(&s, g_signals[i]);
    pthread_sigmask(SIG_BLOCK, &s, old);
    for (;;) {
        int expect = STATE_IDLE;
        if (atomic_compare_exchange_strong(&g_state, &expect, STATE_BUSY)) return;
        struct timespec ms = { 0, 1000000 };
        nanosleep(&ms, NULL);
    }
}

static void unblock(const sigset_t *old)
{
    atomic_store(&g_state, STATE_IDLE);
    const int sig = atomic_load(&g_pending);
    pthread_sigmask(SIG_SETMASK, old, NULL);
    if (sig) raise(sig);   /* the deferred signal, now with nothing half done */
}

static int free_slot(void)
{
    for (int i = 0; i < MS_MAX_OUTPUTS; i++)
        if (!g_live[i]) return i;
    return -1;
}

/* dir of path (".", when it has no slash) into d. */
static void dir_of(const char *path, char *d, size_t n)
{
    snprintf(d, n, "%s", path);
    char *s = strrchr(d, '/');
    if (!s) snprintf(d, n, ".");
    else if (s == d) d[1] = 0;
    else *s = 0;
}

static const char *base_of(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Creates a staging file in the target's directory: a short fixed-length name, so that any target
 * name the filesystem accepts can be staged; mode 0666 less the umask, as any new file. Returns the
 * slot (path in g_stage) or -1. */
static int stage_create_rw(const char *target, int *fd_out, int access, char *err, size_t errlen)
{
    char dir[PATH_MAX];
    dir_of(target, dir, sizeof dir);
    static unsigned counter;
    for (int attempt = 0; attempt < 100; attempt++) {
        sigset_t old;
        block(&old);
        int slot = free_slot();
        if (slot < 0) { unblock(&old); snprintf(err, errlen, "%s: too many outputs", target); return -1; }
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        unsigned r = (unsigned)ts.tv_nsec ^ (unsigned)getpid() * 2654435761u ^ ++counter * 40503u;
        int n = snprintf(g_stage[slot], sizeof g_stage[slot], "%s/.ms-stage-%08x", dir, r);
        if (n < 0 || (size_t)n >= sizeof g_stage[slot]) {
            unblock(&old);
            snprintf(err, errlen, "%s: cannot write: the directory's path is too long", target);
            return -1;
        }
        int fd = open(g_stage[slot], access | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) g_live[slot] = 1;
        int e = errno;
        unblock(&old);
        if (fd >= 0) { *fd_out = fd; return slot; }
        if (e != EEXIST) { snprintf(err, errlen, "%s: cannot write: %s", target, strerror(e)); return -1; }
    }
    snprintf(err, errlen, "%s: cannot write: no free staging name", target);
    return -1;
}

static int stage_create(const char *target, int *fd_out, char *err, size_t errlen)
{
    return stage_create_rw(target, fd_out, O_WRONLY, err, errlen);
}

static void stage_remove(int slot)
{
    sigset_t old;
    block(&old);
    if (g_live[slot]) unlink(g_stage[slot]);
    g_live[slot] = 0;
    unblock(&old);
}

/* Called inside the caller's critical section (block/unblock), which covers all the renames. */
static int stage_commit(int slot, const char *target, char *err, size_t errlen)
{
    int rc = rename(g_stage[slot], target);
    int e = errno;
    if (rc == 0) g_live[slot] = 0;
    if (rc) { snprintf(err, errlen, "%s: cannot rename into place: %s", target, strerror(e)); return -1; }
    return 0;
}

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* The target exists as a regular file, or not at all. */
static int target_kind_ok(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) != 0) return 0;
    if (S_ISREG(st.st_mode)) return 0;
    if (S_ISDIR(st.st_mode)) snprintf(err, errlen, "%s: cannot write: is a directory", path);
    else snprintf(err, errlen, "%s: cannot write: not a regular file (a %s is never replaced)", path,
                  S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "device" : S_ISFIFO(st.st_mode) ? "FIFO" : "special file");
    return -1;
}

/* Same file: the same inode when both exist, else the same name in the same (resolved) directory. */
static int same_target(const char *a, const char *b)
{
    struct stat sa, sb;
    int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0;
    if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ea != eb) return 0;
    if (strcmp(base_of(a), base_of(b))) return 0;
    char da[PATH_MAX], db[PATH_MAX], ra[PATH_MAX], rb[PATH_MAX];
    dir_of(a, da, sizeof da);
    dir_of(b, db, sizeof db);
    if (!realpath(da, ra) || !realpath(db, rb)) return strcmp(da, db) == 0;
    return strcmp(ra, rb) == 0;
}

ms_status ms_outputs_check(const ms_output *outs, int n, char *err, size_t errlen)
{
    for (int i = 0; i < n; i++) {
        const char *p = outs[i].path;
        if (!p) continue;
        if (!p[0]) { snprintf(err, errlen, "empty output path (%s)", outs[i].flag); return MS_ERR_INVALID; }
        for (int j = 0; j < i; j++)
            if (outs[j].path && same_target(outs[j].path, p)) {
                snprintf(err, errlen, "%s: given to both %s and %s (each output needs its own file)", p, outs[j].flag, outs[i].flag);
                return MS_ERR_INVALID;
            }
        if (target_kind_ok(p, err, errlen)) return MS_ERR_IO;
        char dir[PATH_MAX];
        dir_of(p, dir, sizeof dir);
        long name_max = pathconf(dir, _PC_NAME_MAX);
        size_t blen = strlen(base_of(p));
        if (blen == 0) { snprintf(err, errlen, "%s: cannot write: no file name", p); return MS_ERR_IO; }
        if (name_max > 0 && blen > (size_t)name_max) {
            snprintf(err, errlen, "%s: cannot write: the file name is %zu bytes, more than this filesystem's %ld", p, blen, name_max);
            return MS_ERR_IO;
        }
        if (strlen(p) >= PATH_MAX) { snprintf(err, errlen, "%s: cannot write: the path is too long", p); return MS_ERR_IO; }
        /* The directory accepts a new file (creating and removing a staging file proves it). */
        int fd;
        int slot = stage_create(p, &fd, err, errlen);
        if (slot < 0) return MS_ERR_IO;
        close(fd);
        stage_remove(slot);
    }
    /* The endings last: two outputs on one file, a device or a directory are named as such whatever the
     * names end in. */
    for (int i = 0; i < n; i++) {
        const char *p = outs[i].path;
        if (!p || !outs[i].suffixes) continue;
        int ok = 0;
        char list[128] = "";
        for (int k = 0; outs[i].suffixes[k]; k++) {
            ok |= has_suffix(p, outs[i].suffixes[k]);
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? " or " : "", outs[i].suffixes[k]);
        }
        if (!ok) { snprintf(err, errlen, "%s: %s needs a file ending in %s", p, outs[i].flag, list); return MS_ERR_INVALID; }
    }
    return MS_OK;
}

/* The first non-finite value of plane p (w*h values of `per` floats each, `planes` planes), or 0. */
static int first_bad(const float *p, int w, int h, int y0, int per, int planes, const char *name, const char *what,
                     char *err, size_t errlen)
{
    if (!p) return 0;
    const size_t n = (size_t)w * (size_t)h;
    for (int l = 0; l < planes; l++)
        for (size_t i = 0; i < n * (size_t)per; i++) {
            const float v = p[(size_t)l * n * (size_t)per + i];
            if (isfinite(v)) continue;
            char plane[32] = "";
            if (per == 3) snprintf(plane, sizeof plane, " %c", "RGB"[i % 3]);
            else if (planes > 1) snprintf(plane, sizeof plane, " of light %d", l);
            snprintf(err, errlen, "%s: %s%s at pixel (%zu, %zu) is %s: no output written (a NaN or infinite result is "
                     "an error, never a file)", what, name, plane, i / (size_t)per % (size_t)w, i / (size_t)per / (size_t)w + (size_t)y0,
                     isnan(v) ? "NaN" : "infinite");
            return -1;
        }
    return 0;
}

ms_status ms_frame_check_finite(const ms_frame *f, const char *what, char *err, size_t errlen)
{
    return ms_band_check_finite(f, 0, what, err, errlen) ? MS_ERR_INVALID : MS_OK;
}

int ms_band_check_finite(const ms_frame *f, int y0, const char *what, char *err, size_t errlen)
{
    const int planes = f->n_lights > 0 ? f->n_lights : 1;
    if (first_bad(f->rgb, f->width, f->height, y0, 3, 1, "the image's radiance", what, err, errlen) ||
        first_bad(f->vis, f->width, f->height, y0, 1, planes, "V", what, err, errlen) ||
        first_bad(f->shadow, f->width, f->height, y0, 1, planes, "S", what, err, errlen) ||
        first_bad(f->shadow_spec, f->width, f->height, y0, 1, planes, "S_spec", what, err, errlen))
        return -1;
    if (f->rgb && !isfinite(f->exposure)) {
        snprintf(err, errlen, "%s: the image's exposure is %g: no output written (the radiance is too small or too "
                 "large to scale)", what, (double)f->exposure);
        return -1;
    }
    return 0;
}

/* Flushes, syncs and closes fp (the staging file of output path); 0, or -1 with a message unless rc was set. */
static int close_staged(FILE *fp, const char *path, int rc, char *err, size_t errlen)
{
    if (!rc) {
        errno = 0;
        if (fflush(fp) != 0 || ferror(fp) || fsync(fileno(fp)) != 0) {
            snprintf(err, errlen, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
            rc = -1;
        }
    }
    if (fclose(fp) != 0 && !rc) { snprintf(err, errlen, "%s: write failed: %s", path, strerror(errno)); rc = -1; }
    return rc;
}

/* Renames the staging files slot[0..n) into place when rc is 0, then removes whatever is left. Every target
 * is still a regular file or absent before anything is renamed; the renames happen in one critical
 * section, so a signal arriving meanwhile finds all of them done. */
static int commit_all(const ms_output *outs, const int *slot, int n, int rc, char *err, size_t errlen)
{
    sigset_t old;
    int k;
    block(&old);
    for (k = 0; k < n && !rc; k++)
        if (outs[k].path) rc = target_kind_ok(outs[k].path, err, errlen);
    for (k = 0; k < n && !rc; k++)
        if (slot[k] >= 0) rc = stage_commit(slot[k], outs[k].path, err, errlen);
    unblock(&old);
    for (k = 0; k < n; k++)
        if (slot[k] >= 0) stage_remove(slot[k]);   /* nothing left for those renamed */
    return rc;
}

/* A staging file for output k, opened for writing; NULL with a message. */
static FILE *open_staged(const ms_output *o, int *slot, char *err, size_t errlen)
{
    int fd;
    *slot = stage_create(o->path, &fd, err, errlen);
    if (*slot < 0) return NULL;
    FILE *fp = fdopen(fd, "wb");
    if (!fp) { snprintf(err, errlen, "%s: cannot write: %s", o->path, strerror(errno)); close(fd); }
    return fp;
}

/* An output without a writer: its bytes as they are. */
static ms_status write_bytes(const ms_output *o, FILE *out, char *err, size_t errlen)
{
    if (!o->bytes) { snprintf(err, errlen, "%s: %s has neither a writer nor its bytes", o->path, o->flag); return MS_ERR_INVALID; }
    if (o->n_bytes && fwrite(o->bytes, 1, o->n_bytes, out) != o->n_bytes) {
        snprintf(err, errlen, "%s: write failed", o->path);
        return MS_ERR_IO;
    }
    return MS_OK;
}

ms_status ms_outputs_write(const ms_frame *f, const ms_output *outs, int n, char *err, size_t errlen)
{
    int slot[MS_MAX_OUTPUTS];
    int rc = 0, k;
    if (n > MS_MAX_OUTPUTS) { snprintf(err, errlen, "too many outputs"); return MS_ERR_INVALID; }
    /* The last guard: a frame or lightmap with a NaN or infinite value is an error, before any file exists. */
    for (k = 0; k < n; k++)
        if (outs[k].path) {
            if (ms_frame_check_finite(f, outs[k].path, err, errlen)) return MS_ERR_INVALID;
            break;
        }
    for (k = 0; k < n; k++) slot[k] = -1;
    for (k = 0; k < n && !rc; k++) {
        if (!outs[k].path) continue;
        FILE *fp = open_staged(&outs[k], &slot[k], err, errlen);
        if (!fp) { rc = -1; break; }
        const ms_status w = outs[k].write ? outs[k].write(f, fp, outs[k].path, err, errlen) : write_bytes(&outs[k], fp, err, errlen);
        rc = close_staged(fp, outs[k].path, w, err, errlen);
    }
    return commit_all(outs, slot, n, rc, err, errlen) ? MS_ERR_IO : MS_OK;
}

/* ---- Outputs written band by band (output_stream.h) ---- */

struct ms_outputs_stream {
    const ms_output *outs;
    int n, png;
    int slot[MS_MAX_OUTPUTS];
    FILE *fp[MS_MAX_OUTPUTS];
    ms_image_kind kind[MS_MAX_OUTPUTS];
    ms_image_rows *rows[MS_MAX_OUTPUTS];
};

int ms_outputs_streamable(const ms_output *outs, int n, char *err, size_t errlen)
{
    for (int k = 0; k < n; k++)
        if (outs[k].path && ms_image_kind_of(outs[k].write) == MS_IMAGE_OTHER) {
            snprintf(err, errlen, "%s: %s has its own writer, which needs the whole frame (not streamed)", outs[k].path,
                     outs[k].flag);
            return -1;
        }
    return 0;
}

static int stream_close(ms_outputs_stream *s, int rc, char *err, size_t errlen)
{
    for (int k = 0; k < s->n; k++) {
        if (s->rows[k]) rc = ms_image_rows_end(s->rows[k], !rc, err, errlen) || rc ? -1 : 0;
        s->rows[k] = NULL;
        if (s->fp[k]) rc = close_staged(s->fp[k], s->outs[k].path, rc, err, errlen);
        s->fp[k] = NULL;
    }
    return rc;
}

void ms_outputs_stream_abort(ms_outputs_stream *s)
{
    if (!s) return;
    char ignore[8];
    stream_close(s, -1, ignore, sizeof ignore);
    commit_all(s->outs, s->slot, s->n, -1, ignore, sizeof ignore);
    free(s);
}

int ms_outputs_stream_open(const ms_output *outs, int n, int W, int H, int n_lights, ms_outputs_stream **out, char *err,
                           size_t errlen)
{
    *out = NULL;
    if (n > MS_MAX_OUTPUTS) { snprintf(err, errlen, "too many outputs"); return -1; }
    if (ms_outputs_streamable(outs, n, err, errlen)) return -1;
    ms_outputs_stream *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->outs = outs;
    s->n = n;
    for (int k = 0; k < n; k++) s->slot[k] = -1;
    for (int k = 0; k < n; k++) {
        if (!outs[k].path) continue;
        s->kind[k] = ms_image_kind_of(outs[k].write);
        s->png |= s->kind[k] == MS_IMAGE_PNG;
        s->fp[k] = open_staged(&outs[k], &s->slot[k], err, errlen);
        if (s->fp[k] && s->kind[k] != MS_IMAGE_STATS)
            s->rows[k] = ms_image_rows_begin(s->kind[k], W, H, n_lights, s->fp[k], outs[k].path, err, errlen);
        if (!s->fp[k] || (s->kind[k] != MS_IMAGE_STATS && !s->rows[k])) { ms_outputs_stream_abort(s); return -1; }
    }
    *out = s;
    return 0;
}

const char *ms_outputs_stream_png_path(const ms_outputs_stream *s)
{
    for (int k = 0; k < s->n; k++)
        if (s->rows[k] && s->kind[k] == MS_IMAGE_PNG) return s->outs[k].path;
    return NULL;
}

int ms_outputs_stream_rows(ms_outputs_stream *s, const ms_frame *band, int y0, int png, char *err, size_t errlen)
{
    for (int k = 0; k < s->n; k++)
        if (s->rows[k] && (s->kind[k] == MS_IMAGE_PNG) == !!png && ms_image_rows_write(s->rows[k], band, y0, err, errlen))
            return -1;
    return 0;
}

int ms_outputs_stream_commit(ms_outputs_stream *s, const ms_frame *f, char *err, size_t errlen)
{
    int rc = 0;
    for (int k = 0; k < s->n && !rc; k++)
        if (s->fp[k] && s->kind[k] == MS_IMAGE_STATS) rc = s->outs[k].write(f, s->fp[k], s->outs[k].path, err, errlen);
    rc = stream_close(s, rc, err, errlen);
    rc = commit_all(s->outs, s->slot, s->n, rc, err, errlen);
    free(s);
    return rc;
}

int ms_outputs_spill(const char *near, char *err, size_t errlen)
{
    int fd;
    const int slot = stage_create_rw(near, &fd, O_RDWR, err, errlen);
    if (slot < 0) return -1;
    stage_remove(slot);   /* unlinked at once: open until closed, gone with the process whatever happens */
    return fd;
}

/* The single-output entry points of the public API. */
static int write_one(const ms_frame *f, const char *path, const char *flag, ms_output_write_fn fn,
                     const char *const *suffixes, char *err, size_t errlen)
{
    ms_output o = { flag, path ? path : "", fn, suffixes, NULL, 0 };
    if (ms_outputs_check(&o, 1, err, errlen)) return -1;
    return ms_outputs_write(f, &o, 1, err, errlen);
}

ms_status ms_write_png(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_one(f, path, "PNG", ms_png_write_stream, NULL, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_write_vis(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_one(f, path, "the visibility image", ms_vis_write_stream, ms_float_image_suffixes, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_write_shadow(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_one(f, path, "the shadow factor image", ms_shadow_write_stream, ms_float_image_suffixes, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_write_exr(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    static const char *const exr[] = { ".exr", NULL };
    return write_one(f, path, "EXR", ms_exr_write_stream, exr, err, errlen) ? MS_ERR_IO : MS_OK;
}

ms_status ms_write_stats(const ms_frame *f, const char *path, char *err, size_t errlen)
{
    return write_one(f, path, "stats", ms_stats_write_stream, NULL, err, errlen) ? MS_ERR_IO : MS_OK;
}
