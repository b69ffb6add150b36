/* The interior boxes' pass of the block traversal (shadow/microraster/block_box_impl.h): each box is rasterized
 * as its silhouette seen from the pixel. Against a segment-box test written here in double precision, on random
 * boxes and receivers under an axis-aligned light (edges parallel to the rows: n_x = 0 exactly) and a tilted one:
 *   - nothing cleared that no box blocks: every cleared sample's segment meets a box grown by 1e-4;
 *   - nothing left that a box blocks where the pass must take it: a sample whose segment meets a box shrunk by
 *     1e-4, from a pixel that sees the whole box within the depth range and none of its edges end-on, is cleared;
 * for every buffer size and every ISA instance with the row loop it uses. */
#include "testutil.h"
#include "shadow/microraster/block_raster.h"
#include "raster/raster.h"
#include "raster/raster_internal.h"   /* ms_raster_rows */
#include "accel/bvh.h"
#include "core/cpu.h"
#include "visibility/context.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N_BOXES 40
#define N_BLOCKS 24

static double rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

/* 1 when the segment c -> p meets box b grown by g (g < 0: shrunk) at a parameter in [0, 1]. */
static int segment_meets(const double c[3], const double p[3], const float b[6], double g)
{
    double t0 = 0.0, t1 = 1.0;
    for (int a = 0; a < 3; a++) {
        const double lo = b[a] - g, hi = b[3 + a] + g, d = p[a] - c[a];
        if (d == 0.0) {
            if (c[a] < lo || c[a] > hi) return 0;
            continue;
        }
        double ta = (lo - c[a]) / d, tb = (hi - c[a]) / d;
        if (ta > tb) { const double t = ta; ta = tb; tb = t; }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    return t0 <= t1;
}

/* 1 when the pass must take box b whole for the pixel of frame f: every corner at a segment parameter well
 * inside [near, far], C well outside, and no box edge seen end-on. */
static int box_expected(const ms_raster_frame *f, const float b[6])
{
    double v[8][3];
    for (int q = 0; q < 8; q++) {
        double x[3];
        for (int a = 0; a < 3; a++) x[a] = (double)b[(q >> a & 1) ? 3 + a : a] - f->c[a];
        for (int r = 0; r < 3; r++) v[q][r] = f->m[r][0] * x[0] + f->m[r][1] * x[1] + f->m[r][2] * x[2];
        if (!(v[q][2] > f->near + 1e-3 && v[q][2] < f->far - 1e-3)) return 0;
    }
    for (int a = 0; a < 3; a++)
        if (f->c[a] > b[a] - 1e-3f && f->c[a] < b[3 + a] + 1e-3f) return 0;
    for (int q = 0; q < 8; q++)
        for (int a = 0; a < 3; a++) {
            if (q >> a & 1) continue;
            const double *p0 = v[q], *p1 = v[q | 1 << a];
            const double n[3] = { p0[1] * p1[2] - p0[2] * p1[1], p0[2] * p1[0] - p0[0] * p1[2], p0[0] * p1[1] - p0[1] * p1[0] };
            const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            const double l0 = p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2], l1 = p1[0] * p1[0] + p1[1] * p1[1] + p1[2] * p1[2];
            if (nn < 1e-5 * l0 * l1) return 0;
        }
    return 1;
}

static void run(int k, ms_isa isa, int tilted, unsigned seed)
{
    const ms_block_raster_fn fn = ms_block_raster_isa(k, isa);
    const ms_raster_fn raster = ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, isa);
    if (!fn || !raster) return;
    /* The light: a 2 x 2 square at height 4, its grid along x and z, or turned and tilted. */
    ms_grid g = { { -1.0f, 4.0f, -1.0f }, { 2.0f / (float)k, 0.0f, 0.0f }, { 0.0f, 0.0f, 2.0f / (float)k }, k };
    if (tilted) {
        const float c = cosf(0.5f), s = sinf(0.5f), t = 0.3f;
        const float ds[3] = { c * 2.0f / (float)k, t * 2.0f / (float)k, s * 2.0f / (float)k };
        const float dt[3] = { -s * 2.0f / (float)k, 0.1f * 2.0f / (float)k, c * 2.0f / (float)k };
        memcpy(g.ds, ds, sizeof ds);
        memcpy(g.dt, dt, sizeof dt);
    }
    float box[N_BOXES][6], tri[N_BOXES * 9];
    for (int i = 0; i < N_BOXES; i++) {
        const double w = 0.05 + 0.7 * rnd(&seed), h = 0.05 + 0.7 * rnd(&seed), dep = 0.05 + 0.7 * rnd(&seed);
        const double x = -2.0 + 4.0 * rnd(&seed), y = 0.5 + 2.5 * rnd(&seed), z = -2.0 + 4.0 * rnd(&seed);
        const float b[6] = { (float)x, (float)y, (float)z, (float)(x + w), (float)(y + h), (float)(z + dep) };
        memcpy(box[i], b, sizeof b);
        for (int a = 0; a < 3; a++) tri[9 * i + a] = tri[9 * i + 6 + a] = b[a];
        for (int a = 0; a < 3; a++) tri[9 * i + 3 + a] = b[3 + a];
    }
    ms_bvh bvh;
    ms_bvh_shallow sh;
    assert_int_equal(ms_bvh_build(&bvh, tri, N_BOXES, 1), 0);
    assert_int_equal(ms_bvh_shallow_build(&sh, &bvh, 4), 0);
    float (*leaf_box)[6] = malloc((size_t)bvh.n_tris * sizeof *leaf_box);
    assert_non_null(leaf_box);
    for (uint32_t i = 0; i < bvh.n_tris; i++) memcpy(leaf_box[i], box[bvh.tri_source[i]], sizeof box[0]);
    const float near = MS_SEGMENT_NEAR, far = MS_SEGMENT_FAR;
    long cleared = 0, expected = 0, checked = 0;
    for (int blk = 0; blk < N_BLOCKS; blk++) {
        ms_raster_frame f[MS_BLOCK_LANES];
        uint64_t buf[MS_BLOCK_LANES][64];
        ms_block_input in;
        memset(&in, 0, sizeof in);
        in.n = MS_BLOCK_LANES;
        in.box = (const float (*)[6])leaf_box;
        /* A block's receivers close together on the ground, or (every fourth block) among the boxes, some inside. */
        const double cx = -3.0 + 6.0 * rnd(&seed), cz = -3.0 + 6.0 * rnd(&seed), cy = blk % 4 == 3 ? 0.5 + 2.0 * rnd(&seed) : 0.0;
        for (int l = 0; l < MS_BLOCK_LANES; l++) {
            const float c[3] = { (float)(cx + 0.4 * rnd(&seed)), (float)(cy + 0.2 * rnd(&seed)), (float)(cz + 0.4 * rnd(&seed)) };
            assert_int_equal(ms_raster_frame_init(&f[l], c, &g, near, far, 0), 0);
            ms_buffer_fill_visible(buf[l], k);
            in.frame[l] = &f[l];
            in.buf[l] = buf[l];
            in.skip[l] = UINT32_MAX;
        }
        uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
        fn(&in, &bvh, &sh, raster, near, far, cnt, MS_BR_ORDER);
        for (int l = 0; l < MS_BLOCK_LANES; l++) {
            int must[N_BOXES];
            for (int i = 0; i < N_BOXES; i++) must[i] = box_expected(&f[l], box[i]);
            for (int j = 0; j < k; j++)
                for (int i = 0; i < k; i++) {
                    double c[3], p[3];
                    for (int a = 0; a < 3; a++) {
                        c[a] = f[l].c[a];
                        p[a] = (double)(g.p0[a] + (float)i * g.ds[a] + (float)j * g.dt[a]);
                    }
                    const int bit = (int)(buf[l][(j * k + i) >> 6] >> ((j * k + i) & 63) & 1u);
                    int meets = 0, want = 0;
                    for (int b = 0; b < N_BOXES; b++) {
                        meets |= segment_meets(c, p, box[b], 1e-4);
                        want |= must[b] && segment_meets(c, p, box[b], -1e-4);
                    }
                    checked++;
                    if (!bit) {
                        cleared++;
                        if (!meets)
                            fail_msg("k %d isa %d tilted %d block %d pixel %d: sample (%d, %d) cleared, no box on its segment", k,
                                     (int)isa, tilted, blk, l, i, j);
                    }
                    if (want) {
                        expected++;
                        if (bit)
                            fail_msg("k %d isa %d tilted %d block %d pixel %d: sample (%d, %d) left, a box on its segment", k,
                                     (int)isa, tilted, blk, l, i, j);
                    }
                }
        }
    }
    /* Not vacuous: the boxes shadow a good part of the samples, and most of what they clear was required. */
    assert_true(cleared > checked / 20);
    assert_true(expected > cleared / 2);
    free(leaf_box);
    ms_bvh_shallow_free(&sh);
    ms_bvh_free(&bvh);
}

static void test_silhouettes(void **state)
{
    (void)state;
    const int ks[] = { 16, 32, 64 };
    const ms_isa isas[] = { MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    int ran = 0;
    for (int ki = 0; ki < 3; ki++)
        for (int ii = 0; ii < 3; ii++) {
            if (!ms_raster_rows(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, ks[ki], isas[ii]), ks[ki], 5)) continue;
            for (int tilted = 0; tilted < 2; tilted++) run(ks[ki], isas[ii], tilted, 1234u + 77u * (unsigned)(ki * 6 + ii * 2 + tilted));
            ran++;
        }
    if (!ran) {
        printf("test_silhouettes: skipped: no ISA instance with the SIMD Scanline row loop on this CPU\n");
        skip();
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_silhouettes),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
