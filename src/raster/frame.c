/* Frame setup (one 3x3 inverse per projection centre), occlusion buffer queries and kernel names. */
#include <math.h>
#include <string.h>
#include "raster_internal.h"

int ms_raster_frame_init(ms_raster_frame *f, const float c[3], const ms_grid *g, float near, float far,
                         int cull_backfaces)
{
    /* M has columns (ds, dt, p0 - C): M (i, j, 1) = sample(i,j) - C. Inverted in double and rounded
     * once, so m carries a single rounding per entry. */
    double a[3][3];
    for (int r = 0; r < 3; r++) {
        a[r][0] = g->ds[r];
        a[r][1] = g->dt[r];
        a[r][2] = (double)g->p0[r] - (double)c[r];
    }
    const double c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    const double c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    const double c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    const double det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    double scale = 1.0;
    for (int col = 0; col < 3; col++)
        scale *= sqrt(a[0][col] * a[0][col] + a[1][col] * a[1][col] + a[2][col] * a[2][col]);
    /* C on (or numerically on) the light plane, or a degenerate grid. */
    if (!(fabs(det) > 1e-9 * scale) || !isfinite(det)) return -1;
    const double inv = 1.0 / det;
    const double adj[3][3] = {
        { c00, a[0][2] * a[2][1] - a[0][1] * a[2][2], a[0][1] * a[1][2] - a[0][2] * a[1][1] },
        { c01, a[0][0] * a[2][2] - a[0][2] * a[2][0], a[0][2] * a[1][0] - a[0][0] * a[1][2] },
        { c02, a[0][1] * a[2][0] - a[0][0] * a[2][1], a[0][0] * a[1][1] - a[0][1] * a[1][0] },
    };
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++) {
            f->m[r][col] = (float)(adj[r][col] * inv);
            f->mt[r][col] = (float)a[col][r];
        }
    memcpy(f->c, c, sizeof f->c);
    f->near = near;
    f->far = far;
    f->k = g->k;
    f->cull_backfaces = cull_backfaces;
    f->alpha = NULL;
    return 0;
}

void ms_buffer_fill_visible(void *buf, int k)
{
    memset(buf, 0xFF, (size_t)k * (size_t)k / 8);
}

int ms_buffer_all_occluded(const void *buf, int k)
{
    /* OR of all words, 64 bits at a time (the buffer is k*k/8 = 32, 128 or 512 bytes). */
    const size_t n = (size_t)k * (size_t)k / 64;
    uint64_t acc = 0;
    for (size_t i = 0; i < n; i++) {
        uint64_t w;
        memcpy(&w, (const char *)buf + 8 * i, 8);
        acc |= w;
    }
    return acc == 0;
}

int ms_buffer_visible_count(const void *buf, int k)
{
    const size_t n = (size_t)k * (size_t)k / 64;
    int count = 0;
    for (size_t i = 0; i < n; i++) {
        uint64_t w;
        memcpy(&w, (const char *)buf + 8 * i, 8);
        count += __builtin_popcountll(w);
    }
    return count;
}

const char *ms_kernel_name(ms_kernel_id id)
{
    switch (id) {
    case MS_KERNEL_SCANLINE: return "scanline";
    case MS_KERNEL_BOUNDS: return "bounds";
    case MS_KERNEL_HIERARCHICAL: return "hierarchical";
    default: return "unknown";
    }
}
