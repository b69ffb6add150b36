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
    if (strcmp(name, MS_AUTO_METHOD) == 0 || ms_find_shadow_method(name)) return 1;
    for (size_t i = 0; known_not_compiled[i]; i++)
        if (strcmp(known_not_compiled[i], name) == 0) return -1;
    return 0;
}

/* The rule behind "auto" (issue 28, from the measurements in docs/methods.md and docs/scenes.md; every
 * method gives the same V and S, so the choice is speed only):
 *   - the grid pattern: scanline, the fastest method on every benchmark scene at 1024 samples (2-59x the
 *     faster Embree mode, 13 scenes) and on all but the big-light Sponza at 256 (0.9x Embree there);
 *   - the stratified and interleaved patterns, which the micro-raster methods cannot take: Embree when
 *     compiled in (its 16-ray packets beat our raytrace on every scene of docs/scenes.md), else raytrace;
 *     mft wins in the interleaved mode only on architectural scenes with a small light (Dabrovic Sponza
 *     2.1x, docs/methods.md), which the scene alone does not tell.
 * A procedural scene too big for the memory budget once materialised goes to hpc, the streaming method
 * (frame_job.c: the budget decides, after this choice). */
const char *ms_auto_method(ms_pattern pattern)
{
    if (pattern == MS_PATTERN_GRID) return "scanline";
    return ms_find_shadow_method("embree") ? "embree" : "raytrace";
}
