/* A frame's or a call's counter by name (ms_stats_counter). */
#include "microshadow.h"
#include <string.h>

int ms_stats_counter(const ms_stats *st, const char *name, uint64_t *value)
{
    if (!st || !name) return 0;
    const int n = st->n_counters < MS_MAX_COUNTERS ? st->n_counters : MS_MAX_COUNTERS;
    for (int c = 0; c < n; c++)
        if (st->counter_name[c] && !strcmp(st->counter_name[c], name)) {
            if (value) *value = st->counter[c];
            return 1;
        }
    return 0;
}
