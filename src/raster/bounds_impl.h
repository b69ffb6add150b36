/* Scalar Bounds and Hierarchical kernels, instantiated once per buffer width through core/perk_each.h
 * (MS_K, MS_WORD); MS_BLOCK is the side of a Hierarchical block.
 *
 * Both evaluate e[0]*x + (e[1]*y + e[2]) per sample (ms_edge_eval). That float expression is monotone in
 * x and in y separately, so a block's extreme corner bounds every sample inside it even after rounding:
 * Hierarchical's trivial accepts and rejects agree exactly with the per-sample test, and both kernels,
 * restricted to the same bounding box, produce identical buffers bit for bit. */
/* Hierarchical blocks: 4x4 blocks of 4x4 samples (k = 16), 8x8 blocks of 4x4 (k = 32, the paper's
 * best), 8x8 blocks of 8x8 (k = 64). */
#define MS_BLOCK (MS_K == 64 ? 8 : 4)
#define MS_BROW_FN MS_KFN(ms_bounds_row)
#define MS_BOUNDS_FN MS_KFN(ms_bounds)
#define MS_HIER_FN MS_KFN(ms_hier)

/* Coverage mask of samples x0..x1 of scanline y: n is a compile-time constant at each call site. */
static inline __attribute__((always_inline)) uint64_t MS_BROW_FN(const ms_tri_setup *t, const int n, int y,
                                                                  int x0, int x1)
{
    float c[5];
    const float fy = (float)y;
    for (int e = 0; e < n; e++) c[e] = t->e[e][1] * fy + t->e[e][2];
    uint64_t covered = 0;
    for (int x = x0; x <= x1; x++) {
        const float fx = (float)x;
        int in = 1;
        for (int e = 0; e < n; e++) in &= t->e[e][0] * fx + c[e] >= 0.0f;
        covered |= (uint64_t)in << x;
    }
    return covered;
}

static uint64_t MS_KFN(ms_bounds_cover)(const ms_tri_setup *t, int y, int x0, int x1)
{
    switch (t->n) {
    case 3: return MS_BROW_FN(t, 3, y, x0, x1);
    case 4: return MS_BROW_FN(t, 4, y, x0, x1);
    default: return MS_BROW_FN(t, 5, y, x0, x1);
    }
}

void MS_BOUNDS_FN(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_tri_setup t;
    if (!ms_tri_setup_run(f, tri, &t)) return;
    MS_WORD *buf = (MS_WORD *)out;
    for (int y = t.y0; y <= t.y1; y++) buf[y] &= (MS_WORD)~MS_KFN(ms_bounds_cover)(&t, y, t.x0, t.x1);
}

/* Greene-style two-level hierarchy: (k/B) x (k/B) blocks of B x B samples. A block is rejected when some
 * edge is negative at the block corner where it is largest, accepted whole when every edge is
 * non-negative at the corner where it is smallest, and tested sample by sample otherwise. */
void MS_HIER_FN(const ms_raster_frame *f, const float tri[9], void *out)
{
    ms_tri_setup t;
    if (!ms_tri_setup_run(f, tri, &t)) return;
    MS_WORD *buf = (MS_WORD *)out;
    const int n = t.n;
    const uint64_t block_ones = (UINT64_C(1) << MS_BLOCK) - 1;
    /* Columns of the bounding box, so that an accepted block never clears what Bounds would not test. */
    const uint64_t box_cols = ((~UINT64_C(0)) >> (63 - t.x1)) & ((~UINT64_C(0)) << t.x0);
    for (int by = t.y0 / MS_BLOCK; by <= t.y1 / MS_BLOCK; by++) {
        const int ya = by * MS_BLOCK, yb = ya + MS_BLOCK - 1;
        const int ry0 = ya > t.y0 ? ya : t.y0, ry1 = yb < t.y1 ? yb : t.y1;
        for (int bx = t.x0 / MS_BLOCK; bx <= t.x1 / MS_BLOCK; bx++) {
            const int xa = bx * MS_BLOCK, xb = xa + MS_BLOCK - 1;
            int reject = 0, accept = 1;
            for (int e = 0; e < n; e++) {
                const float *q = t.e[e];
                const float hi = ms_edge_eval(q, (float)(q[0] > 0.0f ? xb : xa), (float)(q[1] > 0.0f ? yb : ya));
                const float lo = ms_edge_eval(q, (float)(q[0] > 0.0f ? xa : xb), (float)(q[1] > 0.0f ? ya : yb));
                reject |= hi < 0.0f;
                accept &= lo >= 0.0f;
            }
            if (reject) continue;
            const int cx0 = xa > t.x0 ? xa : t.x0, cx1 = xb < t.x1 ? xb : t.x1;
            if (accept) {
                const uint64_t m = (block_ones << xa) & box_cols;
                for (int y = ry0; y <= ry1; y++) buf[y] &= (MS_WORD)~m;
            } else {
                for (int y = ry0; y <= ry1; y++)
                    buf[y] &= (MS_WORD)~MS_KFN(ms_bounds_cover)(&t, y, cx0, cx1);
            }
        }
    }
}

#undef MS_BROW_FN
#undef MS_BOUNDS_FN
#undef MS_HIER_FN
#undef MS_BLOCK
