/* Scalar Scanline kernels for 16x16, 32x32 and 64x64 buffers (scanline_impl.h). */
#include "raster_internal.h"

#define MS_PERK_IMPL "raster/scanline_impl.h"
#include "../core/perk_each.h"

int ms_scanline_rows(const ms_raster_frame *f, const float tri[9])
{
    ms_tri_setup t;
    ms_scan_setup s;
    if (!ms_tri_setup_run(f, tri, &t) || !ms_scan_setup_run(f, &t, &s)) return 0;
    return s.y1 - s.y0 + 1;
}
