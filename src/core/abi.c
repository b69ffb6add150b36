/* ms_abi_check: a program's struct sizes against this library's (microshadow/abi.h, "The ABI check"). */
#include "abi.h"
#include <stdio.h>

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
    if ((abi->version_major || abi->version_minor)
        && (abi->version_major != ours->version_major || abi->version_minor != ours->version_minor)) {
        snprintf(err, errlen, "%s: the program was built against microshadow %u.%u, this library is %s: rebuild it "
                 "against this library's header", fn, (unsigned)abi->version_major, (unsigned)abi->version_minor,
                 MS_VERSION_STRING);
        return MS_ERR_INVALID;
    }
    /* The struct sizes, in the table's order; a table from a later header may list more (not ours to check). */
    static const char *const names[] = { "ms_camera", "ms_light", "ms_procedural", "ms_scene", "ms_texture",
        "ms_texture_sampling", "ms_material", "ms_scene_load_options", "ms_render_options", "ms_stats", "ms_frame",
        "ms_output", "ms_points", "ms_points_options", "ms_bake_options", "ms_lightmap", "ms_bake_gltf_options" };
    const uint32_t *theirs = &abi->camera, *mine = &ours->camera;
    size_t n = (abi->abi_size - offsetof(ms_abi, camera)) / sizeof(uint32_t);
    if (n > sizeof names / sizeof names[0]) n = sizeof names / sizeof names[0];
    _Static_assert(sizeof names / sizeof names[0] == (sizeof(ms_abi) - offsetof(ms_abi, camera)) / sizeof(uint32_t),
                   "every size of ms_abi has its name");
    for (size_t i = 0; i < n; i++)
        if (theirs[i] && theirs[i] != mine[i]) {
            snprintf(err, errlen, "%s: the program's %s has %u bytes, this library's (%s) %u: rebuild the program "
                     "against this library's header", fn, names[i], (unsigned)theirs[i], MS_VERSION_STRING,
                     (unsigned)mine[i]);
            return MS_ERR_INVALID;
        }
    return MS_OK;
}
