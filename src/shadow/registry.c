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

/* The rule behind "auto" (docs/methods.md, "What to pick"; the figures behind it are in the lab notebook,
 * docs/notebook/2026-11-26-what-to-pick-figures.md; every method gives the same V and S, so the choice is
 * speed only):
 *   - the grid pattern: scanline, the fastest method on every benchmark scene at 1024 samples and at 256;
 *   - the interleaved pattern (16 rays per pixel): mft, faster than raytrace on every benchmark scene and
 *     than Embree's 16-ray packets on nearly all, and exact;
 *   - the stratified pattern: Embree when compiled in, else raytrace. mft is faster in the geometric mean
 *     there too, but slower than Embree with the big light and on the game models, which the scene alone
 *     does not tell.
 * A procedural scene too big for the memory budget once materialised goes to hpc, the streaming method
 * (frame_job.c: the budget decides, after this choice). */
const char *ms_auto_method(ms_pattern pattern)
{
    if (pattern == MS_PATTERN_GRID) return "scanline";
    if (pattern == MS_PATTERN_INTERLEAVED) return "mft";
    return ms_find_shadow_method("embree") ? "embree" : "raytrace";
}
