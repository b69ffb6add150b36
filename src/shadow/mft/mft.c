/* Method "mft": multi-frusta tracing (Benthin & Wald 2009, "Efficient Ray Traced Soft Shadows using
 * Multi-Frusta Tracing", HPG 2009). Pixels are taken in 4x4 blocks; the shadow frusta of a block (hit
 * point -> the pixel's light samples) traverse a shallow BVH together, one frustum per SIMD lane, and in a
 * leaf each triangle is culled for all sixteen by the frusta's corner rays before the surviving frusta
 * test their live rays against it, 16 rays per operation, one bit per ray (mft_impl.h, per ISA).
 *
 * This file: the method's frame set-up, the grouping of the driver's queries into blocks, and each
 * block's rays. The rays are the light samples of the shared patterns (ms_pattern_points: the points
 * method raytrace traces) and are formed exactly as raytrace forms them (raytrace_impl.h: d = P - C,
 * the shear of each 16-sample packet), so that mft and raytrace decide every ray alike; see mft_impl.h
 * for what departs from the paper. */
#include "shadow/method.h"
#include "visibility/occluders.h"
#include "mft.h"
#include "light/light_frame.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "shadow/microraster/block_group.h"
#include "core/vec.h"
#include "accel/ray_triangle.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest leaf of the shallow BVH (accel/bvh.h: subtrees of at most this many triangles collapsed into
 * one leaf). 8 measured fastest for the grid and stratified tracer (faster on the statues, no slower
 * elsewhere), 4 for the interleaved one (figures: docs/notebook/2026-11-29-source-comment-figures.md). */
#define MFT_SHALLOW_LEAF 8
#define MFT_SHALLOW_LEAF_INTERLEAVED 4

/* The interleaved mode's tables of the 16 sample sets (each set the same in every block, pattern.c): per set
 * its n = N/16 points and each point's cell of the g x g grid over the light; per cell the points of the
 * 16 sets [cell][axis][set], the sample of each set in it [cell][set], and the box of its points ([lo x, y, z,
 * hi x, y, z][cell]: 16 cells' in a vector);
 * have: the sets formed; regular: those with one sample per cell (all of pattern.c's sets: nets). */
typedef struct mft_sets {
    int n, gside, ncell;
    unsigned have, regular;
    float *set_pts, *cell_pts, *cell_box, *st;
    uint16_t *sample_of;
    int *set_cell;
} mft_sets;

typedef struct mft_method {
    ms_mft_fn block;
    ms_mft_group_fn groups;       /* the interleaved mode's tracer (mft_group_impl.h) */
    ms_isa isa;
    ms_bvh_shallow sh;
    ms_mft_frame f;
    mft_sets sets;                /* the frame light's, all 16 formed by mft_create (interleaved mode) */
} mft_method;

static void mft_sets_free(mft_sets *T)
{
    free(T->set_pts); free(T->cell_pts); free(T->cell_box); free(T->st); free(T->sample_of); free(T->set_cell);
    memset(T, 0, sizeof *T);
}

static int mft_sets_alloc(mft_sets *T, int n)
{
    memset(T, 0, sizeof *T);
    T->n = n;
    T->gside = 1;
    while (T->gside * T->gside < n) T->gside *= 2;
    T->ncell = T->gside * T->gside;
    T->set_pts = malloc((size_t)16 * 3 * n * sizeof *T->set_pts);
    T->cell_pts = malloc((size_t)T->ncell * 3 * 16 * sizeof *T->cell_pts);
    T->cell_box = malloc((size_t)T->ncell * 6 * sizeof *T->cell_box);
    T->st = malloc((size_t)2 * n * sizeof *T->st);
    T->sample_of = malloc((size_t)16 * T->ncell * sizeof *T->sample_of);
    T->set_cell = malloc((size_t)16 * n * sizeof *T->set_cell);
    if (!T->set_pts || !T->cell_pts || !T->cell_box || !T->st || !T->sample_of || !T->set_cell) { mft_sets_free(T); return -1; }
    for (int c = 0; c < T->ncell; c++)
        for (int a = 0; a < 3; a++) { T->cell_box[(size_t)a * T->ncell + c] = INFINITY; T->cell_box[(size_t)(3 + a) * T->ncell + c] = -INFINITY; }
    return 0;
}

static int mft_morton(int x, int y);

/* Forms set `set`'s tables for frame f (its light, pattern, k, seed). */
static void mft_sets_form(mft_sets *T, const ms_mft_frame *f, int set)
{
    const int n = T->n, gside = T->gside;
    const uint32_t px = (uint32_t)set & 3u, py = (uint32_t)set >> 2;   /* a pixel of the set */
    float *pts = T->set_pts + (size_t)set * 3 * n, *st = T->st;
    ms_pattern_points_range(f->pattern, &f->light, f->k, px, py, f->seed, 0, n, pts);
    ms_pattern_st(f->pattern, f->k, px, py, f->seed, st);
    unsigned seen[MS_SAMPLES_MAX / 16 / 32] = { 0 };
    int ok = 1;
    for (int j = 0; j < n; j++) {
        const int cx = (int)(st[2 * j] * (float)gside), cy = (int)(st[2 * j + 1] * (float)gside);
        const int c = mft_morton(cx < gside ? cx : gside - 1, cy < gside ? cy : gside - 1);
        T->set_cell[(size_t)set * n + j] = c;
        ok &= !(seen[c >> 5] >> (c & 31) & 1u);
        seen[c >> 5] |= 1u << (c & 31);
        T->sample_of[(size_t)c * 16 + set] = (uint16_t)j;
        for (int a = 0; a < 3; a++) {
            const float x = pts[3 * j + a];
            float *lo = &T->cell_box[(size_t)a * T->ncell + c], *hi = lo + (size_t)3 * T->ncell;
            T->cell_pts[((size_t)c * 3 + a) * 16 + set] = x;
            *lo = x < *lo ? x : *lo;
            *hi = x > *hi ? x : *hi;
        }
    }
    T->have |= 1u << set;
    T->regular |= (unsigned)ok << set;
}

ms_mft_fn ms_mft_isa(ms_isa isa)
{
    static const ms_mft_fn table[] = {
        [MS_ISA_SCALAR] = ms_mft_block_scalar,
        [MS_ISA_AVX2] = ms_mft_block_avx2,
        [MS_ISA_AVX512] = ms_mft_block_avx512,
    };
    if (isa < MS_ISA_SCALAR || isa > MS_ISA_AVX512 || ms_cpu_isa() < isa) return NULL;
    return table[isa];
}

static ms_mft_group_fn mft_groups_isa(ms_isa isa)
{
    static const ms_mft_group_fn table[] = {
        [MS_ISA_SCALAR] = ms_mft_groups_scalar,
        [MS_ISA_AVX2] = ms_mft_groups_avx2,
        [MS_ISA_AVX512] = ms_mft_groups_avx512,
    };
    return table[isa];
}

ms_mft_fn ms_mft_select(ms_isa cap, ms_isa *chosen)
{
    const ms_isa isa = ms_isa_select(cap, MS_ISA_ALL);
    const ms_mft_fn fn = isa == MS_ISA_AUTO ? NULL : ms_mft_isa(isa);
    if (fn && chosen) *chosen = isa;
    return fn;
}

void ms_mft_corners(const ms_mft_frame *f, const float c[3], const int r[4], float d[4][3])
{
    const double a[2] = { (r[0] - f->margin) / f->k, (r[1] + 1 + f->margin) / f->k };
    const double b[2] = { (r[2] - f->margin) / f->k, (r[3] + 1 + f->margin) / f->k };
    for (int q = 0; q < 4; q++)
        for (int x = 0; x < 3; x++)
            d[q][x] = (float)(f->lp[x] + a[q & 1] * f->ls[x] + b[q >> 1] * f->lt[x] - c[x]);
}

static void mft_frame_light(ms_mft_frame *f, const ms_light *l);

static int mft_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    mft_method *s = calloc(1, sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->block = ms_mft_select(ctx->isa_cap, &s->isa);
    if (s->block) s->groups = mft_groups_isa(s->isa);
    const int leaf = ctx->pattern == MS_PATTERN_INTERLEAVED ? MFT_SHALLOW_LEAF_INTERLEAVED : MFT_SHALLOW_LEAF;
    if (!s->block || ms_bvh_shallow_build(&s->sh, ctx->bvh, leaf)) {
        free(s);
        snprintf(err, errlen, "out of memory for the shallow BVH");
        return -1;
    }
    ms_mft_frame *f = &s->f;
    f->k = ctx->k;
    f->samples = ctx->samples;
    f->mask_words = ctx->mask_words;
    f->near = ctx->near;
    f->far = ctx->far;
    mft_frame_light(f, &ctx->light);
    f->pattern = ctx->pattern;
    f->seed = ctx->seed;
    f->alpha = ctx->alpha;
    f->flags = (ctx->no_child_order ? 0 : MS_MFT_ORDER) | (ctx->frustum_shrink ? MS_MFT_FS : 0);
    /* The paper's own mode: each pixel of a 4x4 block its own set of N/16 points (pattern.c), traced by
     * cell of the light across the block (mft_visibility_groups). */
    f->cells = ctx->pattern != MS_PATTERN_INTERLEAVED;
    /* The 16 sets' tables once for the frame's light (they were formed per call, i.e. per tile). */
    if (!f->cells) {
        if (mft_sets_alloc(&s->sets, ms_pattern_spp(f->pattern, f->k))) {
            ms_bvh_shallow_free(&s->sh);
            free(s);
            snprintf(err, errlen, "out of memory for the interleaved sets");
            return -1;
        }
        for (int set = 0; set < 16; set++) mft_sets_form(&s->sets, f, set);
    }
    *state = s;
    return 0;
}

/* The frame's light: corner, edges and the margin of the stored points. Per frame, or per call when the
 * context's light is not the frame's (a sphere light's per-receiver outline disk, frame_job.c). */
static void mft_frame_light(ms_mft_frame *f, const ms_light *l)
{
    const double P[3] = { l->corner.x, l->corner.y, l->corner.z }, S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z };
    const double T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    memcpy(f->lp, P, sizeof P);
    memcpy(f->ls, S, sizeof S);
    memcpy(f->lt, T, sizeof T);
    /* The stored points are P + s S + t T (or the grid's p0 + i ds + j dt) rounded to float: a few ulps
     * of |P| + |S| + |T| per coordinate. In cells of the light (height |S x T| / max(|S|, |T|) over k),
     * 64 ulps of that, plus 1/100 of a cell. |P| is the scene frame's (scene_frame.c): of the scene's size,
     * not of its distance from the world's origin, so the margin stays near 1/100 of a cell far out. */
    double n[3], mag = 0.0;
    d3_cross(n, S, T);
    for (int a = 0; a < 3; a++) mag += fabs(P[a]) + fabs(S[a]) + fabs(T[a]);
    const double h = d3_len(n) / fmax(d3_len(S), d3_len(T));
    f->margin = 0.01 + (h > 0.0 ? 64.0 * FLT_EPSILON * mag * f->k / h : 0.0);
    f->light = *l;
    f->shear_axis = ms_light_shear_axis(l);
}

void ms_mft_rays(const ms_mft_frame *f, ms_mft_lane *L, int ch)
{
    float pts[3 * 16];
    if (f->pattern == MS_PATTERN_GRID)
        ms_grid_points(&L->grid, ch * 16, 16, pts);   /* the lane's grid, formed once (mft_lane_setup) */
    else
        ms_pattern_points_range(f->pattern, &f->light, f->k, L->px, L->py, f->seed, ch * 16, 16, pts);
    ms_mft_rays_from(f, L, ch, pts);
}

void ms_mft_rays_from(const ms_mft_frame *f, ms_mft_lane *L, int ch, const float *pts)
{
    const int base = ch * 16;
    for (int l = 0; l < 16; l++)
        for (int a = 0; a < 3; a++) {
            L->d[a][base + l] = pts[3 * l + a] - L->c[a];
            if (L->inv[a]) L->inv[a][base + l] = 1.0f / L->d[a][base + l];
        }
    /* The shear axis raytrace shares over a packet (ms_wt_packet_axis), sx = d[kx] * (1 / d[kz]). */
    int kz;
    L->kz[ch] = (signed char)ms_wt_packet_axis(L->d[0] + base, L->d[1] + base, L->d[2] + base, 16, f->shear_axis, &kz);
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    for (int l = base; l < base + 16; l++) {
        const float inv = 1.0f / L->d[kz][l];
        L->sx[l] = L->d[kx][l] * inv;
        L->sy[l] = L->d[ky][l] * inv;
    }
    L->ready[ch >> 6] |= UINT64_C(1) << (ch & 63);
}

/* Lane L for pixel q: its rays are formed when first tested (ms_mft_rays). Its cell projection for the
 * footprints: the inverse of the columns S/k, T/k, P - C (in double, then rounded), and the footprint's
 * slack: the rounding of the stored points (the frame's margin) and an angle of 1e-4 around each ray,
 * far above the watertight test's few ulps. */
static void mft_lane_setup(const ms_mft_frame *f, const ms_shadow_query *q, ms_mft_lane *L)
{
    memcpy(L->c, q->p, sizeof L->c);
    memcpy(L->n, q->n, sizeof L->n);
    L->skip = q->prim;
    L->px = q->px;
    L->py = q->py;
    memset(L->ready, 0, sizeof L->ready);
    if (f->pattern == MS_PATTERN_GRID) ms_grid_for_pixel(&f->light, f->k, L->px, L->py, f->seed, &L->grid);
    double u[3], v[3], w[3], vw[3], wu[3], uv[3];
    for (int a = 0; a < 3; a++) {
        u[a] = f->ls[a] / f->k;
        v[a] = f->lt[a] / f->k;
        w[a] = f->lp[a] - (double)q->p[a];
    }
    d3_cross(vw, v, w);
    d3_cross(wu, w, u);
    d3_cross(uv, u, v);
    const double det = d3_dot(u, vw);
    L->has_m = fabs(det) > 1e-6 * d3_len(u) * d3_len(v) * d3_len(w);
    if (!L->has_m) return;
    double m[3][3];
    for (int a = 0; a < 3; a++) {
        m[0][a] = vw[a] / det;
        m[1][a] = wu[a] / det;
        m[2][a] = uv[a] / det;
    }
    for (int r = 0; r < 3; r++) {
        L->m_l1[r] = (float)(fabs(m[r][0]) + fabs(m[r][1]) + fabs(m[r][2]));
        for (int a = 0; a < 3; a++) L->m[r][a] = (float)m[r][a];
    }
    L->foot_slack = (float)(f->margin + 0.02 + 1e-4 * d3_len(w) * (fmax(d3_len(m[0]), d3_len(m[1])) + f->k * d3_len(m[2])));
}

/* Morton index of cell (x, y), x, y < 16: cells 16 at a time form 4x4 squares of the light, so the 16
 * groups that traverse together are neighbours. */
static int mft_morton(int x, int y)
{
    int m = 0;
    for (int b = 0; b < 4; b++) m |= (x >> b & 1) << (2 * b) | (y >> b & 1) << (2 * b + 1);
    return m;
}

/* The shear axis every live ray of each group shares (the usual case: one light, nearby receivers). */
static void mft_groups_kz_all(ms_mft_rayblock *rb)
{
    for (int gi = 0; gi < rb->n; gi++) {
        ms_mft_group *G = &rb->g[gi];
        int kz = -2;
        G->alone = 0;
        for (unsigned m = G->live; m; m &= m - 1) {
            const int k = G->kz[__builtin_ctz(m)];
            if (k < 0) { G->alone |= m & -m; continue; }
            kz = kz == -2 || kz == k ? k : -1;
        }
        G->kz_all = kz < 0 ? (kz == -2 ? 0 : -1) : kz;
    }
}

/* A block whose queries have distinct sets, each set one sample per cell (every frame's block): slot =
 * set, so a group's points are one row of cell_pts; its rays are formed by the tracer, 16 at a time
 * (mft_group_impl.h, mftg_form). Returns 0 when no query has a front sample. */
static int mft_block_by_set(const ms_shadow_query *q, const int *order, int g, int end, const uint64_t *front,
                            uint64_t *vis, size_t mw, int n, int ncell, const float *cell_pts, const uint16_t *sample_of,
                            const int *set_cell, ms_mft_rayblock *rb)
{
    unsigned present = 0;
    int first = -1;
    for (int e = g; e < end; e++) {
        const int i = order[e];
        uint64_t *m = vis + (size_t)i * mw;
        memcpy(m, front + (size_t)i * mw, mw * sizeof *m);   /* the front mask is the starting set */
        if (ms_mask_count(m, (int)mw) == 0) continue;
        const int set = ms_interleaved_set(q[i].px, q[i].py);
        present |= 1u << set;
        if (first < 0) first = set;
        for (int a = 0; a < 3; a++) rb->c[a][set] = q[i].p[a];
        rb->skip[set] = q[i].prim;
        rb->mask[set] = m;
    }
    if (!present) return 0;
    for (int set = 0; set < 16; set++)
        if (!(present >> set & 1)) {   /* an absent slot: a finite stand-in, never live */
            for (int a = 0; a < 3; a++) rb->c[a][set] = rb->c[a][first];
            rb->skip[set] = UINT32_MAX;
            rb->mask[set] = NULL;
        }
    rb->nq = 16;
    rb->n = ncell;
    rb->present = present;
    rb->form_n = n;
    rb->cell_pts = cell_pts;
    rb->sample_of = sample_of;
    rb->set_cell = set_cell;
    return 1;
}

/* The interleaved mode: per block, each query's rays formed as raytrace forms them (ms_mft_rays, per
 * 16-sample packet), then regrouped by the cell of the light their sample lies in (mft.h, ms_mft_rayblock):
 * cell (floor(s g), floor(t g)) of a g x g grid, g^2 = N/16. A pixel's set is a (0, m, 2)-net, so it has one
 * sample per cell; a second one (no shared pattern gives it) would open another group for that cell. */
static int mft_visibility_groups(const mft_method *s, const ms_mft_frame *f, const ms_render_ctx *ctx,
                                 const ms_shadow_query *q, const int *order, int nq, const uint64_t *front,
                                 uint64_t *vis, uint64_t *cnt)
{
    const size_t mw = (size_t)ctx->mask_words;
    const int n = ms_pattern_spp(f->pattern, f->k), np = n / 16;
    /* The sets' tables: the frame's (formed by mft_create), or for another light (a sphere's outline) this
     * call's own, formed when a query first needs them. */
    mft_sets own;
    memset(&own, 0, sizeof own);
    const mft_sets *T = &s->sets;
    if (f != &s->f || s->sets.have != 0xFFFFu) {
        if (mft_sets_alloc(&own, n)) return -1;
        T = &own;
    }
    const int ncell = T->ncell;
    ms_mft_rayblock rb;
    memset(&rb, 0, sizeof rb);
    rb.shear_axis = f->shear_axis;
    rb.cap = ncell + MS_BLOCK_LANES;
    rb.g = malloc((size_t)rb.cap * sizeof *rb.g);
    int *next = malloc((size_t)rb.cap * sizeof *next);
    float *scratch = malloc((size_t)n * 8 * sizeof(float));   /* a query's rays (the general grouping) */
    signed char kzs[MS_SAMPLES_MAX / 16];
    if (!rb.g || !next || !scratch) { free(rb.g); free(next); free(scratch); mft_sets_free(&own); return -1; }
    ms_mft_lane L;
    memset(&L, 0, sizeof L);
    for (int a = 0; a < 3; a++) { L.d[a] = scratch + (size_t)a * n; L.inv[a] = scratch + (size_t)(3 + a) * n; }
    L.sx = scratch + (size_t)6 * n;
    L.sy = scratch + (size_t)7 * n;
    L.kz = kzs;
    for (int g = 0; g < nq;) {
        const int end = ms_block_group_end(ctx, q, order, nq, g);
        unsigned sets = 0, dup = 0;
        for (int e = g; e < end; e++) {
            const int set = ms_interleaved_set(q[order[e]].px, q[order[e]].py);
            dup |= sets & 1u << set;
            sets |= 1u << set;
            if (!(T->have >> set & 1)) mft_sets_form(&own, f, set);   /* T is own here: the frame's has all */
        }
        const unsigned regular = T->regular;
        const float *cell_pts = T->cell_pts, *set_pts = T->set_pts;
        const uint16_t *sample_of = T->sample_of;
        const int *set_cell = T->set_cell;
        if (!dup && (sets & ~regular) == 0 && ncell == n) {
            if (mft_block_by_set(q, order, g, end, front, vis, mw, n, ncell, cell_pts, sample_of, set_cell, &rb)) {
                rb.cell_box = T->cell_box;   /* every set of the block is formed: the boxes hold its points */
                s->groups(f, &rb, ctx->bvh, &s->sh, cnt);
            }
            g = end;
            continue;
        }
        rb.nq = 0;
        rb.n = ncell;
        rb.cell_box = NULL;
        memset(rb.g, 0, (size_t)ncell * sizeof *rb.g);
        for (int c = 0; c < ncell; c++) next[c] = -1;
        for (int e = g; e < end; e++) {
            const int i = order[e];
            uint64_t *m = vis + (size_t)i * mw;
            memcpy(m, front + (size_t)i * mw, mw * sizeof *m);   /* the front mask is the starting set */
            if (ms_mask_count(m, (int)mw) == 0) continue;
            const int slot = rb.nq++;
            for (int a = 0; a < 3; a++) rb.c[a][slot] = q[i].p[a];
            rb.skip[slot] = q[i].prim;
            rb.mask[slot] = m;
            memcpy(L.c, q[i].p, sizeof L.c);
            L.px = q[i].px;
            L.py = q[i].py;
            memset(L.ready, 0, sizeof L.ready);
            const int set = ms_interleaved_set(L.px, L.py);
            const float *pts = set_pts + (size_t)set * 3 * n;
            const int *cell_of = set_cell + (size_t)set * n;
            for (int ch = 0; ch < np; ch++) {
                unsigned live = (unsigned)(m[ch >> 2] >> (ch & 3) * 16) & 0xFFFFu;
                if (!live) continue;
                ms_mft_rays_from(f, &L, ch, pts + 3 * 16 * ch);
                for (; live; live &= live - 1) {
                    const int j = 16 * ch + __builtin_ctz(live);
                    int gi = cell_of[j];
                    while (rb.g[gi].live >> slot & 1) {
                        if (next[gi] < 0) {
                            if (rb.n == rb.cap) {
                                const int cap = 2 * rb.cap;
                                ms_mft_group *ng = realloc(rb.g, (size_t)cap * sizeof *ng);
                                int *nn = ng ? realloc(next, (size_t)cap * sizeof *nn) : NULL;
                                if (ng) rb.g = ng;
                                if (nn) next = nn;
                                if (!ng || !nn) { free(rb.g); free(next); free(scratch); mft_sets_free(&own); return -1; }
                                rb.cap = cap;
                            }
                            memset(&rb.g[rb.n], 0, sizeof *rb.g);
                            next[rb.n] = -1;
                            next[gi] = rb.n++;
                        }
                        gi = next[gi];
                    }
                    ms_mft_group *G = &rb.g[gi];
                    for (int a = 0; a < 3; a++) {
                        G->d[a][slot] = L.d[a][j];
                        G->inv[a][slot] = L.inv[a][j];
                        G->p[a][slot] = pts[3 * j + a];
                    }
                    G->sx[slot] = L.sx[j];
                    G->sy[slot] = L.sy[j];
                    G->kz[slot] = L.kz[ch];
                    G->sample[slot] = (uint16_t)j;
                    G->live |= 1u << slot;
                }
            }
        }
        mft_groups_kz_all(&rb);
        rb.form_n = 0;
        if (rb.nq) s->groups(f, &rb, ctx->bvh, &s->sh, cnt);
        g = end;
    }
    free(rb.g);
    free(next);
    free(scratch);
    mft_sets_free(&own);
    return 0;
}

static int mft_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                          const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const mft_method *s = state;
    const size_t mw = (size_t)ctx->mask_words, ns = (size_t)ctx->samples;
    int *order = malloc((size_t)nq * sizeof *order);
    float *rayf = malloc(MS_BLOCK_LANES * 5 * ns * sizeof *rayf);
    signed char *kzs = malloc(MS_BLOCK_LANES * (ns / 16));
    if (!order || !rayf || !kzs) { free(order); free(rayf); free(kzs); return -1; }
    ms_block_order(ctx, q, nq, order);
    /* A light other than the frame's (a sphere's outline disk): the frame re-derived for it. */
    const ms_mft_frame *f = &s->f;
    ms_mft_frame own;
    const ms_light *cl = &ctx->light, *fl = &s->f.light;
    if (memcmp(&cl->corner, &fl->corner, sizeof cl->corner) || memcmp(&cl->edge_s, &fl->edge_s, sizeof cl->edge_s) ||
        memcmp(&cl->edge_t, &fl->edge_t, sizeof cl->edge_t) || cl->shape != fl->shape) {
        own = s->f;
        mft_frame_light(&own, cl);
        f = &own;
    }
    if (!f->cells) {
        free(rayf);
        free(kzs);
        const int rc = mft_visibility_groups(s, f, ctx, q, order, nq, front, vis, cnt);
        free(order);
        return rc;
    }
    ms_mft_block blk;
    for (int l = 0; l < MS_BLOCK_LANES; l++) {
        float *base = rayf + (size_t)l * 5 * ns;
        for (int a = 0; a < 3; a++) blk.lane[l].d[a] = base + (size_t)a * ns;
        for (int a = 0; a < 3; a++) blk.lane[l].inv[a] = NULL;   /* the grid's tracer takes no ray box test */
        blk.lane[l].sx = base + 3 * ns;
        blk.lane[l].sy = base + 4 * ns;
        blk.lane[l].kz = kzs + (size_t)l * (ns / 16);
    }
    for (int g = 0; g < nq;) {
        blk.n = 0;
        const int end = ms_block_group_end(ctx, q, order, nq, g);
        for (int e = g; e < end; e++) {
            const int i = order[e];
            uint64_t *m = vis + (size_t)i * mw;
            memcpy(m, front + (size_t)i * mw, mw * sizeof *m);   /* the front mask is the starting set */
            if (ms_mask_count(m, (int)mw) == 0) continue;
            ms_mft_lane *L = &blk.lane[blk.n++];
            L->mask = m;
            mft_lane_setup(f, &q[i], L);
        }
        if (blk.n) s->block(f, &blk, ctx->bvh, &s->sh, cnt);
        g = end;
    }
    free(order);
    free(rayf);
    free(kzs);
    return 0;
}

static void mft_destroy(void *state)
{
    mft_method *s = state;
    mft_sets_free(&s->sets);
    ms_bvh_shallow_free(&s->sh);
    free(s);
}

static void mft_isa_used(const void *state, ms_isa *kernel, ms_isa *traversal)
{
    const mft_method *s = state;
    *kernel = *traversal = s->isa;
}

const ms_shadow_method ms_shadow_mft = {
    .name = "mft",
    .primary = "bvh",
    .needs_grid = 0,
    /* the closed cull by default: with the interior boxes it pays on thin closed parts and costs nothing
     * measurable elsewhere (docs/culling.md) */
    .occluders = MS_OCC_CULL | MS_OCC_CULL_BY_DEFAULT | MS_OCC_INTERIOR | MS_OCC_INTERIOR_PASS | MS_OCC_MERGE | MS_OCC_MERGE_EXACT,
    .n_counters = MS_MFT_COUNTERS,
    .counter_names = { "blocks", "aabb_tests", "leaves", "tris_accessed", "blocks_early_out", "frusta",
                       "leaf_frusta_culled", "tri_frustum_pairs", "culled_horizon", "culled_plane", "culled_corner_rays",
                       "culled_footprint", "pairs_tested", "isec_tests16", "frusta_early_out", "rect_shrinks",
                       "culled_tri_box", "ray_box_tests16" },
    .create = mft_create,
    .visibility = mft_visibility,
    .destroy = mft_destroy,
    .isa_used = mft_isa_used,
};
