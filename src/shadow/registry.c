/* The shadow methods microshadow knows. A method not compiled into this build is still named, so that
 * asking for it says "not compiled in" rather than "unknown". */
#include "method.h"
#include <string.h>

extern const ms_shadow_method ms_shadow_raytrace, ms_shadow_mft;
extern const ms_shadow_method ms_shadow_scanline, ms_shadow_bounds, ms_shadow_hierarchical;
extern const ms_shadow_method ms_shadow_hpc, ms_shadow_hpc_scanline;
#ifdef MS_HAVE_EMBREE
extern const ms_shadow_method ms_shadow_embree;
#endif

static const ms_shadow_method *const shadow_methods[] = {
    &ms_shadow_scanline, &ms_shadow_bounds, &ms_shadow_hierarchical, &ms_shadow_raytrace, &ms_shadow_mft,
    &ms_shadow_hpc, &ms_shadow_hpc_scanline,
#ifdef MS_HAVE_EMBREE
    &ms_shadow_embree,
#endif
};
static const char *const known_not_compiled[] = {
#ifndef MS_HAVE_EMBREE
    "embree",
#endif
    NULL
};

const ms_shadow_method *ms_find_shadow_method(const char *name)
{
    for (size_t i = 0; i < sizeof shadow_methods / sizeof *shadow_methods; i++)
        if (strcmp(shadow_methods[i]->name, name) == 0) return shadow_methods[i];
    return NULL;
}

const char *const *ms_method_names(void)
{
    static const char *names[sizeof shadow_methods / sizeof *shadow_methods + 1];
    for (size_t i = 0; i < sizeof shadow_methods / sizeof *shadow_methods; i++) names[i] = shadow_methods[i]->name;
    return names;
}

int ms_method_available(const char *name)
{
    if (ms_find_shadow_method(name)) return 1;
    for (size_t i = 0; known_not_compiled[i]; i++)
        if (strcmp(known_not_compiled[i], name) == 0) return -1;
    return 0;
}
