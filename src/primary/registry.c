/* The primary-visibility methods microshadow knows (docs/primary.md). */
#include "primary.h"
#include <string.h>

extern const ms_primary_method ms_primary_bvh, ms_primary_depth;
extern const ms_primary_method ms_primary_3dr_bb, ms_primary_3dr_bin, ms_primary_3dr_fc, ms_primary_3dr_fs,
    ms_primary_3dr_full;
#ifdef MS_HAVE_EMBREE
extern const ms_primary_method ms_primary_embree;
#endif

const ms_primary_method *ms_find_primary_method(const char *name)
{
    static const ms_primary_method *const primaries[] = {
        &ms_primary_bvh, &ms_primary_depth, &ms_primary_3dr_bb, &ms_primary_3dr_bin, &ms_primary_3dr_fc,
        &ms_primary_3dr_fs, &ms_primary_3dr_full,
#ifdef MS_HAVE_EMBREE
        &ms_primary_embree,
#endif
    };
    for (size_t i = 0; i < sizeof primaries / sizeof *primaries; i++)
        if (strcmp(primaries[i]->name, name) == 0) return primaries[i];
    return NULL;
}
