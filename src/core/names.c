/* ms_nearest_name: the "did you mean" of scene keys, command-line options and method names. */
#include "microshadow.h"
#include <ctype.h>
#include <string.h>

/* Levenshtein distance, case-insensitive; names of 64 characters or more count as 64 from everything. */
static size_t edit_distance(const char *a, const char *b)
{
    size_t n = strlen(b), row[64];
    if (n >= 64 || strlen(a) >= 64) return 64;
    for (size_t j = 0; j <= n; j++) row[j] = j;
    for (size_t i = 1; a[i - 1]; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= n; j++) {
            const size_t up = row[j];
            size_t best = diag + (tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]));
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[n];
}

const char *ms_nearest_name(const char *word, const char *const *names, size_t *distance)
{
    const char *best = NULL;
    size_t bd = (size_t)-1;
    for (size_t k = 0; names && names[k]; k++) {
        const size_t d = edit_distance(word, names[k]);
        if (d < bd) { bd = d; best = names[k]; }
    }
    if (distance) *distance = bd;
    return best;
}
