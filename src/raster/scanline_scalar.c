/* Scalar Scanline kernels for 16x16, 32x32 and 64x64 buffers (scanline_impl.h). */
#include "raster_internal.h"

#define MS_PERK_IMPL "raster/scanline_impl.h"
#include "core/perk_each.h"

int ms_scanline_rows(const ms_raster_frame *f, const float tri[9])
{
    ms_tri_setup t;
    ms_scan_setup s;
    if (!ms_tri_setup_run(f, tri, &t) || !ms_scan_setup_run(f, &t, &s)) return 0;
    return s.y1 - s.y0 + 1;
}

void ms_raster_clear_halfplane(int k, const float e[3], void *buf)
{
    static void (*const fn[3])(const float e[3], void *buf) = MS_PERK_TABLE(ms_clear_halfplane, scalar);
    const int w = ms_k_index(k);
    if (w >= 0) fn[w](e, buf);
}
