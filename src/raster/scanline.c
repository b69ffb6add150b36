/* Scalar Scanline kernels for 16x16, 32x32 and 64x64 buffers (scanline_impl.h). */
#include "raster_internal.h"

#define MS_K 16
#define MS_WORD uint16_t
#include "scanline_impl.h"

#define MS_K 32
#define MS_WORD uint32_t
#include "scanline_impl.h"

#define MS_K 64
#define MS_WORD uint64_t
#include "scanline_impl.h"

int ms_scanline_rows(const ms_raster_frame *f, const float tri[9])
{
    ms_tri_setup t;
    ms_scan_setup s;
    if (!ms_tri_setup_run(f, tri, &t) || !ms_scan_setup_run(f, &t, &s)) return 0;
    return s.y1 - s.y0 + 1;
}

void ms_raster_clear_halfplane(int k, const float e[3], void *buf)
{
    switch (k) {
    case 16: ms_clear_halfplane_16(e, buf); break;
    case 32: ms_clear_halfplane_32(e, buf); break;
    case 64: ms_clear_halfplane_64(e, buf); break;
    default: break;
    }
}
