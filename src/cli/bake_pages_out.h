/* The bake's outputs over several lightmap pages (bake_pages_out.c). */
#ifndef MS_CLI_BAKE_PAGES_OUT_H
#define MS_CLI_BAKE_PAGES_OUT_H
#include "microshadow.h"

/* Expands outs[0..*n-1] in place (room for MS_MAX_OUTPUTS) for a lightmap of lm->pages pages: the image
 * outputs (EXR, PNG, V, S) once per page, page 0 at the path given and page p at the path with ".p" before
 * its ending (lightmap.exr, lightmap.1.exr, ...), each writing its page. Nothing changes with one page.
 * 0, or -1 with a message (too many outputs, out of memory). ms_bake_pages_out_free after writing. */
int ms_bake_pages_out(const ms_lightmap *lm, ms_output *outs, int *n, char *err, size_t errlen);
void ms_bake_pages_out_free(void);
/* The UV cache as an output (ms_bake_write_uv_cache of the lightmap set here). */
void ms_bake_uv_cache_source(const ms_lightmap *lm);
ms_status ms_bake_uv_cache_write(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
/* "lm.exr" -> "lm.uvcache" (the default cache beside the lightmap); malloc'ed, NULL when out of memory. */
char *ms_bake_uv_cache_default(const char *exr_path);
#endif
