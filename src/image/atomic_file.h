/* Outputs are written to a temporary file beside the target and renamed into place only when
 * complete, so a failed or interrupted write never leaves a half-written file. */
#ifndef MS_ATOMIC_FILE_H
#define MS_ATOMIC_FILE_H
#include <stdio.h>

typedef struct ms_atomic_file {
    FILE *f;
    char tmp[4096];
    const char *path;
} ms_atomic_file;

int ms_atomic_open(ms_atomic_file *a, const char *path, char *err, size_t errlen);
/* Flushes, syncs, closes and renames; on any failure removes the temporary and reports. */
int ms_atomic_commit(ms_atomic_file *a, char *err, size_t errlen);
void ms_atomic_abort(ms_atomic_file *a);
/* 0 if a file could be created at path (checked by creating and removing a temporary). */
int ms_check_writable(const char *path, char *err, size_t errlen);

#endif
