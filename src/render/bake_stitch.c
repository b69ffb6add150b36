/* Seam stitching (bake_stitch.h): the seam-erasure half of Liu, Ferguson, Jacobson and Gingold, "Seamless:
 * seam erasure and seam-aware decoupling of shape from mesh resolution" (SIGGRAPH Asia 2017). Along every
 * seam, side A's bilinear lookup should equal side B's at every point; over the texels those lookups read,
 * minimise  sum over points of w (lookup_A - lookup_B)^2 + sum over texels lam (x - x_baked)^2,  a
 * sparse least-squares problem solved per channel by conjugate gradients on its normal equations. Every
 * other texel keeps its baked bits.
 * Where this departs from the paper:
 *   - the seam energy is sampled at PER_TEXEL points per texel of the edge, each weighted by the length it
 *     stands for, instead of integrated exactly per bilinear piece: simpler, and as close at that density;
 *   - Jacobi-preconditioned conjugate gradients instead of a sparse direct factorisation: no solver
 *     library; the system falls apart into groups of texels joined by seams, each solved alone (in
 *     parallel, each by one thread, so the result does not depend on the thread count);
 *   - only seams on smooth edges (bake_seams.c): across a hard edge the two sides differ by right;
 *   - the pull lam towards the baked value is weaker on texels whose centre lies off their triangle: the
 *     paper's texels are all equally trusted, ours off the triangles are stand-ins (see below). */
#include "bake_stitch.h"
#include "core/union_find.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define PER_TEXEL 3
/* The pull towards the baked values, per texel, against the seam term in texel-length units: small, so the
 * seams close almost fully, yet it alone fixes what the seams leave free (the paper's small regulariser
 * towards the input). Small enough that the texels beside a seam, which interior lookups also read, yield
 * to it: where a kept layout puts a seam's two sides a few texels apart those texels decide the seam. The
 * lightmap stays within the points API's answer (docs/baking.md, "Quality"; figures in the lab notebook). */
#define LAMBDA 1e-4
/* Texels whose centre lies off their triangle (the conservative rasterization's edge texels, evaluated at the
 * nearest point of the triangle, and dilation's) hold stand-ins rather than the surface at their centre: they
 * are pulled LAMBDA_OFF_SCALE times less, so the seams close there first and the texels interior lookups
 * rely on move least. */
#define LAMBDA_OFF_SCALE 0.001
/* On the preconditioned residual, relative to the right-hand side's: seams within about 1% of the largest
 * value at the 99th percentile on real assets; tighter costs several times the iterations for little. */
#define CG_TOL 1e-4
#define CG_MAX 1000

typedef struct row {
    int32_t var[8];   /* side A's 4 texels, then side B's */
    float w[8];       /* bilinear weights times sqrt(point weight), side B's negated */
} row;

typedef struct stitch_sys {
    size_t nr, nv;
    row *rows;
    size_t *start;   /* per variable: its entries in C's transpose, start[k] .. start[k+1] */
    uint32_t *trow;
    float *tw;
    double *lam;     /* per variable: its pull towards the baked value (LAMBDA, or less off the triangles) */
    double *diag;    /* of C^T C + diag(lam), the preconditioner */
    /* Independent systems: the texels of component c (joined by the rows that read them) are variables
     * comp_v[c] .. comp_v[c+1], its rows comp_r[c] .. comp_r[c+1]. */
    size_t ncomp, *comp_v, *comp_r;
} stitch_sys;

/* The four texels and weights of the clamped bilinear lookup at (u, v) (bake_seams.c's convention). */
static void taps(int W, int H, double u, double v, size_t idx[4], double w[4])
{
    const double x = u * W - 0.5, y = v * H - 0.5;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double fx = x - x0, fy = y - y0;
    for (int q = 0; q < 4; q++) {
        const int i = q & 1, j = q >> 1;
        const int xx = x0 + i < 0 ? 0 : x0 + i >= W ? W - 1 : x0 + i, yy = y0 + j < 0 ? 0 : y0 + j >= H ? H - 1 : y0 + j;
        idx[q] = (size_t)yy * W + xx;
        w[q] = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
    }
}

/* y = (C^T C + diag(lam)) p over component c's variables; cp: C p over its rows. */
static void apply(const stitch_sys *s, size_t c, const double *p, double *cp, double *y)
{
    for (size_t r = s->comp_r[c]; r < s->comp_r[c + 1]; r++) {
        double a = 0.0;
        for (int j = 0; j < 8; j++) a += s->rows[r].w[j] * p[s->rows[r].var[j]];
        cp[r] = a;
    }
    for (size_t k = s->comp_v[c]; k < s->comp_v[c + 1]; k++) {
        double a = s->lam[k] * p[k];
        for (size_t e = s->start[k]; e < s->start[k + 1]; e++) a += s->tw[e] * cp[s->trow[e]];
        y[k] = a;
    }
}

static double dot(const stitch_sys *s, size_t c, const double *a, const double *b)
{
    double t = 0.0;
    for (size_t k = s->comp_v[c]; k < s->comp_v[c + 1]; k++) t += a[k] * b[k];
    return t;
}

/* Solves (C^T C + diag(lam)) d = -C^T C x0 for the change d of one channel over component c (preconditioned CG
 * from d = 0); every array indexed by the global variable and row numbers, only c's touched. */
static void solve(const stitch_sys *s, size_t c, const double *x0, double *d, double *r, double *z, double *p, double *q,
                  double *cp)
{
    const size_t v0 = s->comp_v[c], v1 = s->comp_v[c + 1];
    apply(s, c, x0, cp, q);
    for (size_t k = v0; k < v1; k++) {
        r[k] = -(q[k] - s->lam[k] * x0[k]);
        d[k] = 0.0;
        z[k] = r[k] / s->diag[k];
        p[k] = z[k];
    }
    double rz = dot(s, c, r, z);
    const double rz0 = rz;
    for (int it = 0; it < CG_MAX && rz > CG_TOL * CG_TOL * rz0 && rz > 0.0; it++) {
        apply(s, c, p, cp, q);
        const double pq = dot(s, c, p, q);
        if (!(pq > 0.0)) break;
        const double alpha = rz / pq;
        for (size_t k = v0; k < v1; k++) {
            d[k] += alpha * p[k];
            r[k] -= alpha * q[k];
            z[k] = r[k] / s->diag[k];
        }
        const double rz1 = dot(s, c, r, z);
        const double beta = rz1 / rz;
        rz = rz1;
        for (size_t k = v0; k < v1; k++) p[k] = z[k] + beta * p[k];
    }
}

/* Splits the system into its connected components (texels joined by a row): renumbers the variables and
 * orders the rows so that each component's are contiguous, in the order of their first variable. */
static int split(stitch_sys *s, size_t *texel_of)
{
    const size_t nv = s->nv, nr = s->nr;
    uint32_t *par = malloc((nv ? nv : 1) * sizeof *par), *comp = malloc((nv ? nv : 1) * sizeof *comp);
    uint32_t *newi = malloc((nv ? nv : 1) * sizeof *newi);
    size_t *tex = malloc((nv ? nv : 1) * sizeof *tex);
    row *rows = malloc((nr ? nr : 1) * sizeof *rows);
    int rc = -1;
    if (!par || !comp || !newi || !tex || !rows) goto done;
    for (size_t k = 0; k < nv; k++) par[k] = (uint32_t)k;
    for (size_t r = 0; r < nr; r++)
        for (int j = 1; j < 8; j++) {
            ms_uf_union(par, (uint32_t)s->rows[r].var[0], (uint32_t)s->rows[r].var[j]);
        }
    s->ncomp = 0;
    for (size_t k = 0; k < nv; k++) {   /* a root is its own smallest member: numbered when first met */
        const uint32_t root = ms_uf_find(par, (uint32_t)k);
        comp[k] = root == k ? (uint32_t)s->ncomp++ : comp[root];
    }
    s->comp_v = calloc(s->ncomp + 1, sizeof *s->comp_v);
    s->comp_r = calloc(s->ncomp + 1, sizeof *s->comp_r);
    if (!s->comp_v || !s->comp_r) goto done;
    for (size_t k = 0; k < nv; k++) s->comp_v[comp[k] + 1]++;
    for (size_t r = 0; r < nr; r++) s->comp_r[comp[s->rows[r].var[0]] + 1]++;
    for (size_t c = 0; c < s->ncomp; c++) { s->comp_v[c + 1] += s->comp_v[c]; s->comp_r[c + 1] += s->comp_r[c]; }
    /* placed through the starts, then the starts restored */
    for (size_t k = 0; k < nv; k++) {
        newi[k] = (uint32_t)s->comp_v[comp[k]]++;
        tex[newi[k]] = texel_of[k];
    }
    for (size_t r = 0; r < nr; r++) {
        row *t = &rows[s->comp_r[comp[s->rows[r].var[0]]]++];
        *t = s->rows[r];
        for (int j = 0; j < 8; j++) t->var[j] = (int32_t)newi[t->var[j]];
    }
    for (size_t c = s->ncomp; c > 0; c--) { s->comp_v[c] = s->comp_v[c - 1]; s->comp_r[c] = s->comp_r[c - 1]; }
    s->comp_v[0] = s->comp_r[0] = 0;
    memcpy(texel_of, tex, nv * sizeof *tex);
    free(s->rows);
    s->rows = rows;
    rows = NULL;
    rc = 0;
done:
    free(par);
    free(comp);
    free(newi);
    free(tex);
    free(rows);
    return rc;
}

/* Whether texel i's centre lies on its triangle's UV image (its value is the surface's there). */
static int centre_on_triangle(const float *uv, const uint32_t *triangle, int W, int H, size_t i)
{
    const uint32_t t = triangle[i];
    if (t == MS_NO_TRIANGLE) return 0;
    const double px = ((double)(i % (size_t)W) + 0.5) / W, py = ((double)(i / (size_t)W) + 0.5) / H;
    const float *u = uv + 6 * (size_t)t;
    double e[3];
    for (int k = 0; k < 3; k++) {
        const float *a = u + 2 * k, *b = u + 2 * ((k + 1) % 3);
        e[k] = ((double)b[0] - a[0]) * (py - a[1]) - ((double)b[1] - a[1]) * (px - a[0]);
    }
    return (e[0] >= 0 && e[1] >= 0 && e[2] >= 0) || (e[0] <= 0 && e[1] <= 0 && e[2] <= 0);
}

/* The rows: one per sample point whose 8 texels are all filled, its variables numbered in var_of. */
static int build_rows(const ms_frame *f, const ms_seam *seams, size_t n, int32_t *var_of, stitch_sys *s, size_t **texel_of)
{
    const int W = f->width, H = f->height;
    size_t cap = 0;
    for (size_t i = 0; i < n; i++) cap += (size_t)ms_seam_samples(ms_seam_len_texels(&seams[i], W, H), PER_TEXEL);
    s->rows = malloc((cap ? cap : 1) * sizeof *s->rows);
    const size_t np = (size_t)W * H;
    *texel_of = malloc((8 * cap < np ? 8 * cap + 1 : np) * sizeof **texel_of);
    if (!s->rows || !*texel_of) return -1;
    for (size_t i = 0; i < n; i++) {
        const ms_seam *sm = &seams[i];
        const double len = ms_seam_len_texels(sm, W, H);
        const int ns = ms_seam_samples(len, PER_TEXEL);
        const float sw = (float)sqrt(len / ns);
        for (int j = 0; j < ns; j++) {
            const double t = (j + 0.5) / ns;
            size_t idx[8];
            double w[8];
            taps(W, H, sm->a0[0] + t * (sm->a1[0] - sm->a0[0]), sm->a0[1] + t * (sm->a1[1] - sm->a0[1]), idx, w);
            taps(W, H, sm->b0[0] + t * (sm->b1[0] - sm->b0[0]), sm->b0[1] + t * (sm->b1[1] - sm->b0[1]), idx + 4, w + 4);
            /* a tap of weight 0 (the point on a texel centre's row or column: chart edges lie there) is no
             * variable: the texel may be another chart's, and would join its system to this one */
            for (int side = 0; side < 8; side += 4) {
                int best = side;
                for (int q = side + 1; q < side + 4; q++) best = w[q] > w[best] ? q : best;
                for (int q = side; q < side + 4; q++)
                    if (w[q] == 0.0) idx[q] = idx[best];
            }
            int filled = 1;
            for (int q = 0; q < 8; q++) filled &= f->vis[idx[q]] >= 0.0f;
            if (!filled) continue;
            row *rw = &s->rows[s->nr++];
            for (int q = 0; q < 8; q++) {
                if (var_of[idx[q]] < 0) { var_of[idx[q]] = (int32_t)s->nv; (*texel_of)[s->nv++] = idx[q]; }
                rw->var[q] = var_of[idx[q]];
                rw->w[q] = (float)(q < 4 ? w[q] : -w[q]) * sw;
            }
        }
    }
    return 0;
}

/* C's transpose (per variable, its rows in order) and the preconditioner. */
static int build_transpose(stitch_sys *s)
{
    s->start = calloc(s->nv + 1, sizeof *s->start);
    s->trow = malloc((s->nr ? 8 * s->nr : 1) * sizeof *s->trow);
    s->tw = malloc((s->nr ? 8 * s->nr : 1) * sizeof *s->tw);
    s->diag = malloc((s->nv ? s->nv : 1) * sizeof *s->diag);
    size_t *fill = malloc((s->nv ? s->nv : 1) * sizeof *fill);
    if (!s->start || !s->trow || !s->tw || !s->diag || !fill) { free(fill); return -1; }
    for (size_t r = 0; r < s->nr; r++)
        for (int j = 0; j < 8; j++) s->start[s->rows[r].var[j] + 1]++;
    for (size_t k = 0; k < s->nv; k++) { s->start[k + 1] += s->start[k]; fill[k] = s->start[k]; }
    for (size_t r = 0; r < s->nr; r++)
        for (int j = 0; j < 8; j++) {
            const size_t e = fill[s->rows[r].var[j]]++;
            s->trow[e] = (uint32_t)r;
            s->tw[e] = s->rows[r].w[j];
        }
    /* diag(C^T C): per variable, the square of its summed weight in each row (a clamped lookup may read a
     * texel twice; its entries of one row are adjacent) */
    for (size_t k = 0; k < s->nv; k++) {
        double dsum = s->lam[k], run = 0.0;
        for (size_t e = s->start[k]; e < s->start[k + 1]; e++) {
            run += s->tw[e];
            if (e + 1 == s->start[k + 1] || s->trow[e + 1] != s->trow[e]) { dsum += run * run; run = 0.0; }
        }
        s->diag[k] = dsum;
    }
    free(fill);
    return 0;
}

uint64_t ms_bake_stitch_need(const ms_frame *f, const ms_seam *seams, size_t n)
{
    if (!n) return 0;
    const uint64_t np = (uint64_t)f->width * (uint64_t)f->height;
    const uint64_t nch = 3u + (f->n_lights > 1 ? (uint64_t)f->n_lights : 1u);
    uint64_t nr = 0;   /* the rows: build_rows's capacity */
    for (size_t i = 0; i < n; i++) nr += (uint64_t)ms_seam_samples(ms_seam_len_texels(&seams[i], f->width, f->height), PER_TEXEL);
    const uint64_t nv = 8u * nr < np ? 8u * nr + 1u : np;   /* variables: texels read by some row */
    const uint64_t base = np * sizeof(int32_t) + nr * sizeof(row) + nv * sizeof(size_t);   /* var_of, rows, texel_of */
    /* split's copies (its union-find, renumbering and a second row array; the component starts at most one
     * per variable), then the transpose, the preconditioner, lam and the solver's work, which outlive it */
    const uint64_t split_peak = nv * (3u * sizeof(uint32_t) + sizeof(size_t)) + nr * sizeof(row) + 2u * (nv + 1u) * sizeof(size_t);
    const uint64_t solve = (nv + 1u) * sizeof(size_t) + 8u * nr * (sizeof(uint32_t) + sizeof(float)) + nv * (2u * sizeof(double) + sizeof(size_t)) +
                           nv * sizeof(double) + ((6u + nch) * nv + nr + 1u) * sizeof(double) + 2u * (nv + 1u) * sizeof(size_t);
    return base + (split_peak > solve ? split_peak : solve);
}

int ms_bake_stitch(ms_frame *f, const float *uv, const uint32_t *triangle, const ms_seam *seams, size_t n, int threads,
                   size_t *texels)
{
    *texels = 0;
    if (!n) return 0;
    const size_t np = (size_t)f->width * f->height;
    const size_t nl = f->n_lights > 1 ? (size_t)f->n_lights : 1;
    stitch_sys s;
    memset(&s, 0, sizeof s);
    int32_t *var_of = malloc(np * sizeof *var_of);
    size_t *texel_of = NULL;
    double *work = NULL;
    int rc = -1;
    if (!var_of) goto done;
    for (size_t i = 0; i < np; i++) var_of[i] = -1;
    if (build_rows(f, seams, n, var_of, &s, &texel_of) || split(&s, texel_of)) goto done;
    s.lam = malloc((s.nv ? s.nv : 1) * sizeof *s.lam);
    if (!s.lam) goto done;
    for (size_t k = 0; k < s.nv; k++)
        s.lam[k] = centre_on_triangle(uv, triangle, f->width, f->height, texel_of[k]) ? LAMBDA : LAMBDA * LAMBDA_OFF_SCALE;
    if (build_transpose(&s)) goto done;
    const size_t nv = s.nv, nch = 3 + nl;
    /* x0, d, r, z, p, q per variable; the new values of every channel; C p per row */
    work = malloc(((6 + nch) * nv + s.nr + 1) * sizeof *work);
    if (!work) goto done;
    double *x0 = work, *d = x0 + nv, *r = d + nv, *z = r + nv, *p = z + nv, *q = p + nv, *val = q + nv;
    double *cp = val + nch * nv;
    /* Each component alone, by one thread: the result does not depend on the thread count. */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads > 0 ? threads : 1)
    for (size_t c = 0; c < s.ncomp; c++)
        for (size_t ch = 0; ch < nch; ch++) {
            for (size_t k = s.comp_v[c]; k < s.comp_v[c + 1]; k++)
                x0[k] = ch < 3 ? f->rgb[3 * texel_of[k] + ch] : f->shadow[(ch - 3) * np + texel_of[k]];
            solve(&s, c, x0, d, r, z, p, q, cp);
            /* irradiance stays >= 0, S within [0, 1] */
            for (size_t k = s.comp_v[c]; k < s.comp_v[c + 1]; k++) {
                const double v = x0[k] + d[k];
                val[ch * nv + k] = ch < 3 ? fmax(v, 0.0) : fmin(fmax(v, 0.0), 1.0);
            }
        }
    for (size_t k = 0; k < nv; k++) {
        int changed = 0;
        for (size_t c = 0; c < nch; c++) {
            float *dst = c < 3 ? &f->rgb[3 * texel_of[k] + c] : &f->shadow[(c - 3) * np + texel_of[k]];
            const float v = (float)val[c * nv + k];
            changed |= v != *dst;
            *dst = v;
        }
        *texels += (size_t)changed;
    }
    rc = 0;
done:
    free(var_of);
    free(texel_of);
    free(work);
    free(s.rows);
    free(s.start);
    free(s.trow);
    free(s.tw);
    free(s.diag);
    free(s.lam);
    free(s.comp_v);
    free(s.comp_r);
    return rc;
}
