/* Reading untrusted input files: regular files only, a size limit, never blocking on a FIFO. */
#include "scene_internal.h"
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int ms_read_input(const char *path, size_t max_bytes, ms_input_kind kind, char **out, size_t *len, char *err,
                  size_t errlen)
{
    *out = NULL;
    *len = 0;
    const int mesh = kind != MS_INPUT_SCENE;
    const char *noun = kind == MS_INPUT_AUX ? "file" : kind == MS_INPUT_TEXTURE ? "texture file" : "mesh file";
    /* O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        int e = errno;
        if (mesh && e == ENOENT) snprintf(err, errlen, "%s: %s not found", path, noun);
        else if (mesh) snprintf(err, errlen, "%s: %s is not readable: %s", path, noun, strerror(e));
        else snprintf(err, errlen, "%s: cannot open: %s", path, strerror(e));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const char *what = S_ISDIR(st.st_mode) ? "a directory" : S_ISFIFO(st.st_mode) ? "a FIFO"
                         : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "not a regular file";
        if (mesh) snprintf(err, errlen, "%s: %s is not a regular file (%s)", path,
                           kind == MS_INPUT_AUX ? "it" : kind == MS_INPUT_TEXTURE ? "texture" : "mesh", what);
        else snprintf(err, errlen, "%s: cannot read: not a regular file (%s)", path, what);
        close(fd);
        return -1;
    }
    if ((unsigned long long)st.st_size > max_bytes) {
        snprintf(err, errlen, "%s: %s is %lld bytes, more than the limit of %zu", path, mesh ? noun : "scene file",
                 (long long)st.st_size, max_bytes);
        close(fd);
        return -1;
    }
    /* The size may change while we read: read at most max_bytes + 1 and stop at end of file. */
    size_t cap = (size_t)st.st_size + 1, n = 0;
    char *buf = malloc(cap + 1);
    if (!buf) { snprintf(err, errlen, "%s: out of memory", path); close(fd); return -1; }
    for (;;) {
        if (n == cap) {
            if (cap > max_bytes) break;
            size_t nc = cap * 2 > max_bytes + 1 ? max_bytes + 1 : cap * 2;
            char *nb = realloc(buf, nc + 1);
            if (!nb) { free(buf); close(fd); snprintf(err, errlen, "%s: out of memory", path); return -1; }
            buf = nb;
            cap = nc;
        }
        ssize_t r = read(fd, buf + n, cap - n);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            int e = errno;
            free(buf);
            close(fd);
            snprintf(err, errlen, "%s: cannot read: %s", path, strerror(e));
            return -1;
        }
        if (r == 0) break;
        n += (size_t)r;
    }
    close(fd);
    if (n > max_bytes) {
        free(buf);
        snprintf(err, errlen, "%s: %s grew beyond the limit of %zu bytes while being read", path,
                 mesh ? "mesh file" : "scene file", max_bytes);
        return -1;
    }
    buf[n] = 0;   /* the text parsers rely on a terminator */
    *out = buf;
    *len = n;
    return 0;
}

/* ---- Paths a file names (docs/design.md, "Hostile input": a downloaded asset reads only its own files) ---- */

/* 1 when the components of rel never climb above its first folder ("a/../b" stays, "a/../../b" leaves). */
static int stays_below(const char *rel)
{
    long depth = 0;
    for (const char *c = rel; *c;) {
        const char *e = strchr(c, '/');
        const size_t n = e ? (size_t)(e - c) : strlen(c);
        if (n == 2 && c[0] == '.' && c[1] == '.') {
            if (--depth < 0) return 0;
        } else if (n && !(n == 1 && c[0] == '.')) {
            depth++;
        }
        c += n;
        while (*c == '/') c++;
    }
    return 1;
}

int ms_resolve_inside(const char *owner, const char *ref, int allow, const char *what, char *out, size_t n, char *err,
                      size_t errlen)
{
    const char *slash = strrchr(owner, '/');
    const int dl = slash ? (int)(slash - owner + 1) : 0;
    /* Messages show at most 200 bytes of the reference, made one line by the callers (ms_one_line). */
    const int rl = (int)(strlen(ref) > 200 ? 200 : strlen(ref));
    const char *hint = "only files inside the asset's folder are read; a trusted scene may say \"allow_outside_paths\": true";
    if (ref[0] == '/' && !allow) {
        snprintf(err, errlen, "%s: %s '%.*s' is an absolute path (%s)", owner, what, rl, ref, hint);
        return -1;
    }
    const int k = ref[0] == '/' ? snprintf(out, n, "%s", ref) : snprintf(out, n, "%.*s%s", dl, owner, ref);
    if (k < 0 || (size_t)k >= n) {
        snprintf(err, errlen, "%s: %s '%.*s': the path is longer than %zu bytes", owner, what, rl, ref, n - 1);
        return -1;
    }
    if (allow) return 0;
    if (!stays_below(ref)) {
        snprintf(err, errlen, "%s: %s '%.*s' leads outside the folder of the file naming it (%s)", owner, what, rl, ref, hint);
        return -1;
    }
    /* Symbolic links: the file, resolved, must lie inside the naming file's folder, resolved. A file that
     * does not resolve (missing, a dangling link) is left to the open, which fails and says so. Checked
     * before the open, by name: a link swapped in between the two by someone who can write into the
     * asset's folder is not caught (openat2's RESOLVE_BENEATH would; the asset's files are not expected to
     * change while they are read). */
    char dir[4096];
    if (snprintf(dir, sizeof dir, "%.*s", dl ? dl : 1, dl ? owner : ".") >= (int)sizeof dir) return 0;
    char *rdir = realpath(dir, NULL), *rfile = rdir ? realpath(out, NULL) : NULL;
    int rc = 0;
    if (rdir && rfile) {
        const size_t m = strlen(rdir);
        const int inside = !strcmp(rdir, "/") || (!strncmp(rfile, rdir, m) && (rfile[m] == '/' || rfile[m] == 0));
        if (!inside) {
            snprintf(err, errlen, "%s: %s '%.*s' is a symbolic link (or passes through one) leading outside the folder of the "
                     "file naming it, to %.200s (%s)", owner, what, rl, ref, rfile, hint);
            rc = -1;
        }
    }
    free(rdir);
    free(rfile);
    return rc;
}
