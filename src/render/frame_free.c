/* Releasing a finished frame's planes (ms_frame_free). */
#include "microshadow.h"
#include <stdlib.h>
#include <string.h>

void ms_frame_free(ms_frame *f)
{
    free(f->vis);
    free(f->shadow);
    free(f->shadow_spec);
    free(f->front);
    free(f->rgb);
    memset(f, 0, sizeof *f);
}
