/* ms_abi_check: a program's ABI level and struct sizes against this library's (microshadow/abi.h, "The ABI
 * check"); ms_abi_options: an option struct the program passed, read at its size. */
#include "abi.h"
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* The struct sizes, in the table's order. */
static const char *const names[] = { "ms_camera", "ms_light", "ms_procedural", "ms_scene", "ms_texture",
    "ms_texture_sampling", "ms_material", "ms_scene_load_options", "ms_render_options", "ms_stats", "ms_frame",
    "ms_output", "ms_points", "ms_points_options", "ms_bake_options", "ms_lightmap", "ms_bake_gltf_options" };
_Static_assert(sizeof names / sizeof names[0] == (sizeof(ms_abi) - offsetof(ms_abi, camera)) / sizeof(uint32_t),
               "every size of ms_abi has its name");

/* The option structs' sizes when this ABI level began (LP64): the least a program of the level passes. They
 * stay until MS_ABI_LEVEL changes; a field appended within the level goes at or past them (never into a
 * struct's tail padding, which a program of the level may not have zeroed). */
enum { FLOOR_SCENE_LOAD = 4, FLOOR_RENDER = 128, FLOOR_POINTS = 64, FLOOR_BAKE = 128, FLOOR_BAKE_GLTF = 8 };
#if UINTPTR_MAX == UINT64_MAX
_Static_assert(MS_ABI_LEVEL == 12, "a new ABI level: set the floors to the option structs' sizes");
_Static_assert(sizeof(ms_scene_load_options) >= FLOOR_SCENE_LOAD && sizeof(ms_render_options) >= FLOOR_RENDER &&
               sizeof(ms_points_options) >= FLOOR_POINTS && sizeof(ms_bake_options) >= FLOOR_BAKE &&
               sizeof(ms_bake_gltf_options) >= FLOOR_BAKE_GLTF, "option structs only grow within a level");
#endif

static uint32_t level_floor(size_t i)
{
#define MS_AT(field) ((uint32_t)(offsetof(ms_abi, field) - offsetof(ms_abi, camera)) / (uint32_t)sizeof(uint32_t))
#if UINTPTR_MAX == UINT64_MAX
#define MS_FLOOR(n, type) (n)
#else
#define MS_FLOOR(n, type) sizeof(type)   /* no other data model has had a level of its own */
#endif
    const uint32_t at = (uint32_t)i;
    if (at == MS_AT(scene_load_options)) return (uint32_t)MS_FLOOR(FLOOR_SCENE_LOAD, ms_scene_load_options);
    if (at == MS_AT(render_options)) return (uint32_t)MS_FLOOR(FLOOR_RENDER, ms_render_options);
    if (at == MS_AT(points_options)) return (uint32_t)MS_FLOOR(FLOOR_POINTS, ms_points_options);
    if (at == MS_AT(bake_options)) return (uint32_t)MS_FLOOR(FLOOR_BAKE, ms_bake_options);
    if (at == MS_AT(bake_gltf_options)) return (uint32_t)MS_FLOOR(FLOOR_BAKE_GLTF, ms_bake_gltf_options);
#undef MS_FLOOR
#undef MS_AT
    return 0;   /* not an option struct: its size is fixed within the level */
}

ms_status ms_abi_check(const ms_abi *abi, const char *fn, char *err, size_t errlen)
{
    char dummy[1];
    if (!err || !errlen) { err = dummy; errlen = sizeof dummy; }
    if (!abi) { snprintf(err, errlen, "%s: no ABI table (call it through microshadow.h)", fn); return MS_ERR_INVALID; }
    const ms_abi *ours = ms_abi_compiled();
    if (abi->abi_size < offsetof(ms_abi, camera)) {
        snprintf(err, errlen, "%s: an ABI table of %u bytes is too small to be one", fn, (unsigned)abi->abi_size);
        return MS_ERR_INVALID;
    }
    if (abi->abi_level && abi->abi_level != ours->abi_level) {
        snprintf(err, errlen, "%s: the program was built against microshadow 0.%u (ABI level %u), this library is %s "
                 "(ABI level %u): rebuild it against this library's header", fn, (unsigned)abi->version_minor,
                 (unsigned)abi->abi_level, MS_VERSION_STRING, (unsigned)ours->abi_level);
        return MS_ERR_INVALID;
    }
    /* A table from a later header may list more structs (not ours to check). */
    const uint32_t *theirs = &abi->camera, *mine = &ours->camera;
    size_t n = (abi->abi_size - offsetof(ms_abi, camera)) / sizeof(uint32_t);
    if (n > sizeof names / sizeof names[0]) n = sizeof names / sizeof names[0];
    for (size_t i = 0; i < n; i++) {
        if (!theirs[i] || theirs[i] == mine[i]) continue;
        const uint32_t floor = level_floor(i);
        if (floor && theirs[i] >= floor && theirs[i] < mine[i]) continue;   /* an earlier header of the level */
        snprintf(err, errlen, "%s: the program's %s has %u bytes, this library's (%s) %u%s: rebuild the program "
                 "against this library's header", fn, names[i], (unsigned)theirs[i], MS_VERSION_STRING,
                 (unsigned)mine[i], floor && theirs[i] > mine[i] ? " (the program's header is newer)" : "");
        return MS_ERR_INVALID;
    }
    return MS_OK;
}

const void *ms_abi_options(const void *theirs, uint32_t their_size, void *mine, size_t my_size)
{
    if (!theirs || !their_size || their_size >= my_size) return theirs;
    memset(mine, 0, my_size);
    memcpy(mine, theirs, their_size);
    return mine;
}

_Static_assert(offsetof(ms_bake_options, size) == sizeof(ms_points_options), "the bake's own fields follow its points");

const ms_bake_options *ms_abi_bake_options(const ms_abi *abi, const ms_bake_options *theirs, ms_bake_options *mine)
{
    if (!theirs) { memset(mine, 0, sizeof *mine); return mine; }
    const uint32_t points = MS_ABI_SIZE(abi, points_options);
    const uint32_t bake = MS_ABI_SIZE(abi, bake_options);
    if ((!points || points == sizeof mine->points) && (!bake || bake == sizeof *mine)) return theirs;
    /* An earlier header of the level: its ms_points_options first (its size; a struct's size is a multiple of
     * its alignment, so the bake's own fields follow at that offset, as here at sizeof mine->points), then
     * the bake's own fields. */
    const uint32_t p = points ? points : (uint32_t)sizeof mine->points;
    const uint32_t b = bake ? bake : (uint32_t)sizeof *mine;
    memset(mine, 0, sizeof *mine);
    memcpy(&mine->points, theirs, p);
    if (b <= p) return mine;
    const size_t own = b - p, room = sizeof *mine - sizeof mine->points;
    memcpy((unsigned char *)mine + sizeof mine->points, (const unsigned char *)theirs + p, own < room ? own : room);
    return mine;
}
