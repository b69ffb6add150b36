/* The check behind the API's checked entry points (microshadow/abi.h, "The ABI check"). */
#ifndef MS_CORE_ABI_H
#define MS_CORE_ABI_H
#include "microshadow.h"

/* MS_OK when abi's level is this library's (or 0) and every non-zero size in it is this library's, or, for an
 * option struct, between the level's first size and this library's; else MS_ERR_INVALID with one line naming
 * fn, the first struct that differs and both sizes in err (which may be NULL: the message is then dropped). */
ms_status ms_abi_check(const ms_abi *abi, const char *fn, char *err, size_t errlen);

/* An option struct the program passed at their_size bytes (ms_abi's entry for it; 0: this library's size), as
 * this library reads it: theirs itself when it is at least my_size, else mine (my_size bytes) holding their
 * bytes and zeroes, the defaults, for the rest. NULL stays NULL. Call it after ms_abi_check. */
const void *ms_abi_options(const void *theirs, uint32_t their_size, void *mine, size_t my_size);

/* The same for ms_bake_options, whose first field (ms_points_options) may itself be an earlier header's;
 * NULL gives mine zeroed (the defaults). */
const ms_bake_options *ms_abi_bake_options(const ms_abi *abi, const ms_bake_options *theirs, ms_bake_options *mine);

/* abi's entry for a struct, 0 when its table is too short to hold it (a table from an earlier header). */
#define MS_ABI_SIZE(abi, field) \
    ((abi)->abi_size >= offsetof(ms_abi, field) + sizeof(uint32_t) ? (abi)->field : 0u)

#endif
