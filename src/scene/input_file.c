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
