#include "atomic_file.h"
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int ms_atomic_open(ms_atomic_file *a, const char *path, char *err, size_t errlen)
{
    a->f = NULL;
    a->path = path;
    if (!path || !path[0]) { snprintf(err, errlen, "empty output path"); return -1; }
    if ((size_t)snprintf(a->tmp, sizeof a->tmp, "%s.tmp-XXXXXX", path) >= sizeof a->tmp) {
        snprintf(err, errlen, "%s: output path too long", path);
        return -1;
    }
    int fd = mkstemp(a->tmp);
    if (fd < 0) { snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno)); return -1; }
    a->f = fdopen(fd, "wb");
    if (!a->f) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        close(fd);
        unlink(a->tmp);
        return -1;
    }
    return 0;
}

int ms_atomic_commit(ms_atomic_file *a, char *err, size_t errlen)
{
    int bad = fflush(a->f) != 0 || ferror(a->f) || fsync(fileno(a->f)) != 0;
    int saved = errno;
    if (fclose(a->f) != 0 && !bad) { bad = 1; saved = errno; }
    a->f = NULL;
    if (bad) {
        unlink(a->tmp);
        snprintf(err, errlen, "%s: write failed: %s", a->path, strerror(saved));
        return -1;
    }
    if (rename(a->tmp, a->path) != 0) {
        saved = errno;
        unlink(a->tmp);
        snprintf(err, errlen, "%s: cannot rename into place: %s", a->path, strerror(saved));
        return -1;
    }
    return 0;
}

void ms_atomic_abort(ms_atomic_file *a)
{
    if (a->f) fclose(a->f);
    a->f = NULL;
    unlink(a->tmp);
}

int ms_check_writable(const char *path, char *err, size_t errlen)
{
    /* A directory passes the temporary-file test beside it but fails the final rename, after the
     * render and after the other outputs were written: refuse it up front. */
    struct stat st;
    if (path && stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s: cannot write: is a directory", path);
        return -1;
    }
    ms_atomic_file a;
    if (ms_atomic_open(&a, path, err, errlen)) return -1;
    ms_atomic_abort(&a);
    return 0;
}
