/* The render options' defaults (ms_render_options_default). */
#include "microshadow.h"
#include <string.h>

void ms_render_options_default(ms_render_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = MS_DEFAULT_METHOD;
    o->pattern = MS_PATTERN_GRID;
    o->samples = 0;        /* the scene's */
}
