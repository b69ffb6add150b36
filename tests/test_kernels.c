/* Micro-rasterization kernels (src/raster) against a brute-force per-sample oracle: the segment
 * C -> sample against the triangle by the Plücker test in double precision, in world space.
 *
 * A kernel may differ from the oracle only at a tie: a sample for which one of the quantities that decide
 * the hit (the three edge functions, the near and far clip functions, the determinant) lies within 1e-5 of
 * zero relative to the magnitude of its terms, i.e. where single-precision setup may legitimately round
 * either way. Each is a triple product of world vectors; the magnitude of its terms is the product of
 * their lengths, taking for a cross product the best-conditioned of its equivalent forms (A x B =
 * A x (B - A) = B x (B - A): the two shortest sides of the triangle they span). A plane through C and a
 * nearly collinear edge, or a sliver's own plane, is known to no better than that. Ties are counted and reported; any other difference fails the test. Bounds and
 * Hierarchical must agree bit for bit (same expression, monotone corner tests). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>
#include "testutil.h"
#include "raster/raster.h"

#define TIE_REL 1e-5

/* ---- random numbers ---- */
static double rng_unit(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }
static double rng_range(tu_rng *r, double a, double b) { return a + (b - a) * rng_unit(r); }
static int rng_int(tu_rng *r, int n) { return (int)(tu_rng_next(r) % (uint64_t)n); }

/* ---- a frame: light, grid, projection centre ---- */
typedef struct scene {
    ms_grid g;
    float c[3];
    double M[3][3]; /* columns ds, dt, p0 - C, from the float grid */
    float near, far;
    int k;
    int exact; /* axis-aligned grid where light-index coordinates map to world exactly */
    int grazing; /* C close to the light's plane: an ill-conditioned frame */
} scene;

static void scene_random(scene *s, tu_rng *r, int k)
{
    s->k = k;
    s->exact = rng_int(r, 5) == 0;
    s->grazing = 0;
    static const float nears[] = { 1e-4f, 1e-4f, 1e-4f, 1e-2f, 0.3f };
    s->near = nears[rng_int(r, 5)];
    s->far = rng_int(r, 4) == 0 ? 0.7f : 1.0f;
    if (s->exact) {
        /* Light [0,1]^2 at z = 0, C at (0, 0, -1): m = diag(k, k, 1), all powers of two. */
        for (int i = 0; i < 3; i++) { s->g.p0[i] = 0.0f; s->g.ds[i] = 0.0f; s->g.dt[i] = 0.0f; }
        s->g.ds[0] = 1.0f / (float)k;
        s->g.dt[1] = 1.0f / (float)k;
        s->g.k = k;
        s->c[0] = 0.0f; s->c[1] = 0.0f; s->c[2] = -1.0f;
    } else {
        ms_light l;
        memset(&l, 0, sizeof l);
        double es[3], et[3], n[3];
        for (int i = 0; i < 3; i++) { es[i] = rng_range(r, -1, 1); et[i] = rng_range(r, -1, 1); }
        n[0] = es[1] * et[2] - es[2] * et[1]; n[1] = es[2] * et[0] - es[0] * et[2]; n[2] = es[0] * et[1] - es[1] * et[0];
        double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double size = sqrt(nl);
        if (nl < 0.05) { es[0] += 1.0; et[1] += 1.0; scene_random(s, r, k); return; }
        l.corner = (ms_vec3){ (float)rng_range(r, -2, 2), (float)rng_range(r, -2, 2), (float)rng_range(r, -2, 2) };
        l.edge_s = (ms_vec3){ (float)es[0], (float)es[1], (float)es[2] };
        l.edge_t = (ms_vec3){ (float)et[0], (float)et[1], (float)et[2] };
        ms_grid_for_pixel(&l, k, (uint32_t)tu_rng_next(r), (uint32_t)tu_rng_next(r), 7u, &s->g);
        /* C in front of (or behind) the light, at 0.1 to 5 light sizes, laterally within a light size; or,
         * one frame in six, grazing: 1e-3 to 3e-2 light sizes off the light's plane and up to two sizes
         * aside, where the light-space transform is ill-conditioned (entries of 1e3 and more). */
        const int grazing = rng_int(r, 6) == 0;
        s->grazing = grazing;
        double dist = size * exp(grazing ? rng_range(r, log(1e-3), log(3e-2)) : rng_range(r, log(0.1), log(5.0))) *
                      (rng_int(r, 4) == 0 ? -1.0 : 1.0);
        double cs = grazing ? rng_range(r, -2.0, 3.0) : rng_range(r, -0.5, 1.5);
        double ct = grazing ? rng_range(r, -2.0, 3.0) : rng_range(r, -0.5, 1.5);
        s->c[0] = (float)(l.corner.x + cs * es[0] + ct * et[0] + dist * n[0] / nl);
        s->c[1] = (float)(l.corner.y + cs * es[1] + ct * et[1] + dist * n[1] / nl);
        s->c[2] = (float)(l.corner.z + cs * es[2] + ct * et[2] + dist * n[2] / nl);
    }
    for (int i = 0; i < 3; i++) {
        s->M[i][0] = s->g.ds[i];
        s->M[i][1] = s->g.dt[i];
        s->M[i][2] = (double)s->g.p0[i] - (double)s->c[i];
    }
}

/* World point of light-index coordinates (x, y, z): C + M (x, y, z), rounded to float. */
static void to_world(const scene *s, const double v[3], float out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = (float)((double)s->c[i] + s->M[i][0] * v[0] + s->M[i][1] * v[1] + s->M[i][2] * v[2]);
}

/* ---- random triangles, in light-index coordinates, by category ---- */
enum { CAT_FRONT, CAT_CROSS_Z0, CAT_BEHIND, CAT_BEYOND, CAT_TOUCH_CLIP, CAT_HUGE, CAT_TINY, CAT_DEGENERATE,
       CAT_FLAT_EDGE, CAT_EDGE_ON, CAT_WORLD, CAT_COUNT };
static const char *cat_name[CAT_COUNT] = { "front", "cross-z0", "behind", "beyond", "touch-clip", "huge",
                                           "tiny", "degenerate", "flat-edge", "edge-on", "world" };

/* A vertex projecting to (px, py) at depth z. */
static void vert(double v[3], double px, double py, double z) { v[0] = px * z; v[1] = py * z; v[2] = z; }

/* Round to a multiple of 1/8 so that exact frames see exactly representable coordinates. */
static double q8(double x) { return floor(x * 8.0 + 0.5) / 8.0; }

/* A triangle of random shape and orientation in world space, between C and a random point of the
 * light: in a grazing frame such a triangle is ill-conditioned in light-index space (how a wall or floor
 * triangle next to the receiver looks there), which the categories drawn in light-index space are not. */
static double len3(const double a[3]);
static void tri_world(const scene *s, tu_rng *r, float tri[9])
{
    double target[3], cen[3];
    const double ls = rng_range(r, 0.0, 1.0) * s->k, lt = rng_range(r, 0.0, 1.0) * s->k;
    for (int c = 0; c < 3; c++) target[c] = s->M[c][0] * ls + s->M[c][1] * lt + s->M[c][2];
    const double tau = exp(rng_range(r, log(1e-3), log(1.2))), dist = len3(target) * tau;
    const double size = dist * exp(rng_range(r, log(1e-2), log(3.0)));
    for (int c = 0; c < 3; c++) cen[c] = s->c[c] + tau * target[c];
    for (int v = 0; v < 3; v++)
        for (int c = 0; c < 3; c++) tri[3 * v + c] = (float)(cen[c] + size * rng_range(r, -1.0, 1.0));
}

static int tri_random(const scene *s, tu_rng *r, float tri[9])
{
    const double k = s->k;
    double v[3][3];
    int cat = rng_int(r, CAT_COUNT);
    if (cat == CAT_WORLD) {
        tri_world(s, r, tri);
        return cat;
    }
    double z[3];
    for (int i = 0; i < 3; i++) z[i] = rng_range(r, 0.02, 1.0);
    switch (cat) {
    case CAT_FRONT:
        for (int i = 0; i < 3; i++) vert(v[i], rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), z[i]);
        break;
    case CAT_CROSS_Z0:
        for (int i = 0; i < 3; i++) {
            double zz = rng_range(r, -1.0, 1.0);
            for (int c = 0; c < 2; c++) v[i][c] = rng_range(r, -1.5 * k, 2.5 * k) * fabs(zz) + rng_range(r, -k, k) * 0.1;
            v[i][2] = zz;
        }
        if (v[0][2] * v[1][2] > 0 && v[1][2] * v[2][2] > 0) v[0][2] = -v[0][2];
        break;
    case CAT_BEHIND:
        for (int i = 0; i < 3; i++) vert(v[i], rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), -z[i]);
        break;
    case CAT_BEYOND:
        for (int i = 0; i < 3; i++) vert(v[i], rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), s->far + z[i]);
        break;
    case CAT_TOUCH_CLIP:
        for (int i = 0; i < 3; i++) {
            int which = rng_int(r, 4);
            double zz = which == 0 ? s->near : which == 1 ? s->far : which == 2 ? rng_range(r, -0.5, 0.5) * s->near + s->near : rng_range(r, 0.0, 1.5);
            vert(v[i], rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), zz);
        }
        break;
    case CAT_HUGE:
        for (int i = 0; i < 3; i++) vert(v[i], rng_range(r, -20 * k, 20 * k), rng_range(r, -20 * k, 20 * k), z[i]);
        break;
    case CAT_TINY: {
        double cx = rng_range(r, 0, k), cy = rng_range(r, 0, k), sz = exp(rng_range(r, log(1e-3), log(1.0)));
        for (int i = 0; i < 3; i++) vert(v[i], cx + sz * rng_range(r, -1, 1), cy + sz * rng_range(r, -1, 1), z[i]);
        break;
    }
    case CAT_DEGENERATE: {
        for (int i = 0; i < 2; i++) vert(v[i], rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), z[i]);
        int how = rng_int(r, 3);
        double t = rng_range(r, -1, 2);
        for (int c = 0; c < 3; c++)
            v[2][c] = how == 0 ? v[0][c] + t * (v[1][c] - v[0][c]) : how == 1 ? v[1][c] : v[0][c];
        if (how == 2) for (int c = 0; c < 3; c++) v[1][c] = v[0][c];
        break;
    }
    case CAT_FLAT_EDGE: {
        /* Two vertices on one scanline (or one column), possibly exactly on sample rows. */
        int col = rng_int(r, 2), exact_row = rng_int(r, 2);
        double row = exact_row ? (double)rng_int(r, s->k) : rng_range(r, -1, k);
        for (int i = 0; i < 3; i++) {
            double a = rng_range(r, -0.3 * k, 1.3 * k), b = i < 2 ? row : rng_range(r, -0.3 * k, 1.3 * k);
            if (s->exact) { a = q8(a); z[i] = q8(z[i] * 8) / 8 + 0.125; }
            vert(v[i], col ? b : a, col ? a : b, z[i]);
        }
        if (rng_int(r, 2)) { z[1] = z[0]; for (int c = 0; c < 2; c++) v[1][c] = v[1][c] / v[1][2] * z[0]; v[1][2] = z[0]; }
        break;
    }
    default: { /* CAT_EDGE_ON: the plane of the triangle passes (nearly) through C */
        double a[3], b[3];
        vert(a, rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), z[0]);
        vert(b, rng_range(r, -0.3 * k, 1.3 * k), rng_range(r, -0.3 * k, 1.3 * k), z[1]);
        double eps = rng_int(r, 2) ? 0.0 : rng_range(r, -1e-3, 1e-3);
        for (int c = 0; c < 3; c++) {
            v[0][c] = a[c];
            v[1][c] = b[c] * rng_range(r, 0.3, 1.5);
            v[2][c] = a[c] * rng_range(r, 0.2, 1.2) + b[c] * rng_range(r, 0.2, 1.2) + eps * (c == 2);
        }
        break;
    }
    }
    if (rng_int(r, 2)) for (int c = 0; c < 3; c++) { double t = v[1][c]; v[1][c] = v[2][c]; v[2][c] = t; }
    for (int i = 0; i < 3; i++) to_world(s, v[i], tri + 3 * i);
    return cat;
}

/* ---- the oracle ---- */
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(double r[3], const double a[3], const double b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1]; r[1] = a[2] * b[0] - a[0] * b[2]; r[2] = a[0] * b[1] - a[1] * b[0];
}
static double len3(const double a[3]) { return sqrt(dot3(a, a)); }

typedef struct oracle {
    /* u, v, w and s = u + v + w as functions of (i, j): q = q0 + i qi + j qj (d = p0 - C + i ds + j dt). */
    double q0[4], qi[4], qj[4];
    double D, near, far;
    double mag_a[3]; /* |A1 x A2|, |A2 x A0|, |A0 x A1|: u / (|d| mag_a[0]) is the sine of the angle
                        between the segment and the plane through C and the edge */
    double mag_d;    /* min |A_i| |(A1 - A0) x (A2 - A0)|, the scale of D */
    double mag_s;    /* |(A1 - A0) x (A2 - A0)|, the scale of u + v + w per unit |d| */
    double dlen0[3], dlen_i[3], dlen_j[3];
    int k;
} oracle;

static void oracle_init(oracle *o, const scene *s, const float tri[9])
{
    double A[3][3], N[4][3];
    for (int v = 0; v < 3; v++)
        for (int c = 0; c < 3; c++) A[v][c] = (double)tri[3 * v + c] - (double)s->c[c];
    cross3(N[0], A[1], A[2]);
    cross3(N[1], A[2], A[0]);
    cross3(N[2], A[0], A[1]);
    for (int c = 0; c < 3; c++) N[3][c] = N[0][c] + N[1][c] + N[2][c];
    o->D = dot3(A[0], N[0]);
    double sign = o->D < 0 ? -1.0 : 1.0;
    o->D *= sign;
    double p0c[3], ds[3], dt[3];
    for (int c = 0; c < 3; c++) { p0c[c] = s->M[c][2]; ds[c] = s->M[c][0]; dt[c] = s->M[c][1]; }
    for (int e = 0; e < 4; e++) {
        o->q0[e] = sign * dot3(N[e], p0c);
        o->qi[e] = sign * dot3(N[e], ds);
        o->qj[e] = sign * dot3(N[e], dt);
    }
    /* Edge e: the sides A_{e+1}, A_{e+2} and their difference; the plane: the three triangle edges. */
    double la[3], le[3];
    for (int v = 0; v < 3; v++) {
        double ed[3];
        for (int c = 0; c < 3; c++) ed[c] = A[(v + 2) % 3][c] - A[(v + 1) % 3][c];
        la[v] = len3(A[v]);
        le[v] = len3(ed);
    }
    for (int e = 0; e < 3; e++) {
        double x = la[(e + 1) % 3], y = la[(e + 2) % 3], z = le[e];
        o->mag_a[e] = fmax(len3(N[e]), x * y * z / fmax(fmax(x, y), z));
    }
    double lmin = fmin(fmin(la[0], la[1]), la[2]);
    o->mag_s = fmax(len3(N[3]), le[0] * le[1] * le[2] / fmax(fmax(le[0], le[1]), le[2]));
    o->mag_d = lmin * o->mag_s;
    for (int c = 0; c < 3; c++) { o->dlen0[c] = p0c[c]; o->dlen_i[c] = ds[c]; o->dlen_j[c] = dt[c]; }
    o->near = s->near;
    o->far = s->far;
    o->k = s->k;
}

/* Hit bits of scanline j. */
static uint64_t oracle_row(const oracle *o, int j)
{
    if (!(o->D > 0)) return 0;
    uint64_t bits = 0;
    double b[4];
    for (int e = 0; e < 4; e++) b[e] = o->q0[e] + j * o->qj[e];
    for (int i = 0; i < o->k; i++) {
        double u = b[0] + i * o->qi[0], v = b[1] + i * o->qi[1], w = b[2] + i * o->qi[2], sum = b[3] + i * o->qi[3];
        int hit = (u >= 0) & (v >= 0) & (w >= 0) & (o->D - o->near * sum >= 0) & (o->far * sum - o->D >= 0);
        bits |= (uint64_t)hit << i;
    }
    return bits;
}

/* Whether sample (i, j) is a tie: the hit test flips within the relative tolerance. */
static int oracle_tie(const oracle *o, int i, int j)
{
    double d[3];
    for (int c = 0; c < 3; c++) d[c] = o->dlen0[c] + i * o->dlen_i[c] + j * o->dlen_j[c];
    double dl = len3(d);
    double q[5], tol[5];
    for (int e = 0; e < 3; e++) {
        q[e] = o->q0[e] + i * o->qi[e] + j * o->qj[e];
        tol[e] = TIE_REL * dl * o->mag_a[e];
    }
    double sum = o->q0[3] + i * o->qi[3] + j * o->qj[3];
    double msum = dl * o->mag_s;
    q[3] = o->D - o->near * sum; tol[3] = TIE_REL * (o->mag_d + o->near * msum);
    q[4] = o->far * sum - o->D; tol[4] = TIE_REL * (o->mag_d + o->far * msum);
    if (fabs(o->D) <= TIE_REL * o->mag_d) return 1; /* seen edge-on: the orientation itself is a tie */
    int loose = 1, tight = 1;
    for (int e = 0; e < 5; e++) { loose &= q[e] >= -tol[e]; tight &= q[e] >= tol[e]; }
    if (getenv("MS_TIE_DEBUG") && loose == tight)
        fprintf(stderr, "  q/tol: %.3g %.3g %.3g %.3g %.3g  D %.3g magd %.3g\n", q[0] / tol[0], q[1] / tol[1],
                q[2] / tol[2], q[3] / tol[3], q[4] / tol[4], o->D, o->mag_d);
    return loose != tight;
}

/* ---- running kernels ---- */
typedef struct kernel_under_test {
    const char *name;
    ms_raster_fn fn;
    long ties, bad;
} kernel_under_test;

static void buffer_row_get(const void *buf, int k, int j, uint64_t *w)
{
    if (k == 16) *w = ((const uint16_t *)buf)[j];
    else if (k == 32) *w = ((const uint32_t *)buf)[j];
    else *w = ((const uint64_t *)buf)[j];
}

static long g_cat_count[CAT_COUNT], g_cat_ties[CAT_COUNT];

/* The AVX2 Scanline variant, also on a CPU that dispatches to AVX-512; NULL (with a message, once per k)
 * without AVX2+FMA. */
static ms_raster_fn avx2_scanline(int k)
{
    ms_raster_fn fn = tu_isa_allowed(MS_ISA_AVX2) ? ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_AVX2) : NULL;
    if (fn == NULL) printf("  no AVX2+FMA on this CPU (or capped by MS_TEST_ISA): the avx2 Scanline variant is skipped\n");
    return fn;
}

static void run_random(int k, long n_tris, uint64_t seed)
{
    ms_isa chosen = MS_ISA_AUTO;
    const ms_raster_fn dispatched = ms_raster_kernel(MS_KERNEL_SCANLINE, k, tu_isa_cap(), &chosen);
    kernel_under_test kt[8] = {
        { "scanline-scalar", ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_SCALAR), 0, 0 },
        { "scanline", dispatched, 0, 0 },
        { "bounds", ms_raster_kernel_isa(MS_KERNEL_BOUNDS, k, MS_ISA_SCALAR), 0, 0 },
        { "hierarchical", ms_raster_kernel_isa(MS_KERNEL_HIERARCHICAL, k, MS_ISA_SCALAR), 0, 0 },
    };
    int nk = 4;
    /* Same function as one already listed: no need to run it twice. */
    const ms_raster_fn bounds_dispatch = ms_raster_kernel(MS_KERNEL_BOUNDS, k, tu_isa_cap(), NULL), avx2 = avx2_scanline(k);
    const ms_raster_fn hier_dispatch = ms_raster_kernel(MS_KERNEL_HIERARCHICAL, k, tu_isa_cap(), NULL);
    /* Bounds and Hierarchical compiled for the dispatched ISA: the same C, so the same buffers bit for bit
     * as the portable ones (asserted below). */
    int i_bd = -1, i_hd = -1;
    if (bounds_dispatch != kt[2].fn) { i_bd = nk; kt[nk++] = (kernel_under_test){ "bounds-dispatch", bounds_dispatch, 0, 0 }; }
    if (hier_dispatch != kt[3].fn) { i_hd = nk; kt[nk++] = (kernel_under_test){ "hier-dispatch", hier_dispatch, 0, 0 }; }
    /* and Bounds compiled for AVX2 on an AVX-512 CPU */
    const ms_raster_fn bounds_avx2 = tu_isa_allowed(MS_ISA_AVX2) ? ms_raster_kernel_isa(MS_KERNEL_BOUNDS, k, MS_ISA_AVX2) : NULL;
    int i_b2 = -1;
    if (bounds_avx2 && bounds_avx2 != bounds_dispatch) { i_b2 = nk; kt[nk++] = (kernel_under_test){ "bounds-avx2", bounds_avx2, 0, 0 }; }
    int i_avx2 = -1;
    if (avx2 != NULL && avx2 != kt[1].fn) {
        i_avx2 = nk;
        kt[nk++] = (kernel_under_test){ "scanline-avx2", avx2, 0, 0 };
    }
    /* The AVX-512 and AVX2 variants do the same arithmetic: reported (not asserted) when both run. */
    const int cmp_simd = i_avx2 >= 0 && chosen == MS_ISA_AVX512;
    long simd_diff = 0;
    for (int i = 0; i < nk; i++) assert_non_null(kt[i].fn);
    memset(g_cat_count, 0, sizeof g_cat_count);
    memset(g_cat_ties, 0, sizeof g_cat_ties);
    tu_rng r = { seed };
    scene s;
    ms_raster_frame f;
    uint64_t bufs[8][64];
    long occluded = 0, bounds_hier_diff = 0, isa_build_diff = 0, frames = 0, grazing_frames = 0;
    clock_t t0 = clock();
    for (long t = 0; t < n_tris; t++) {
        if (t % 64 == 0) {
            do scene_random(&s, &r, k);
            while (ms_raster_frame_init(&f, s.c, &s.g, s.near, s.far, 0) != 0);
            frames++;
            grazing_frames += s.grazing;
        }
        float tri[9];
        int cat = tri_random(&s, &r, tri);
        g_cat_count[cat]++;
        for (int i = 0; i < nk; i++) {
            ms_buffer_fill_visible(bufs[i], k);
            kt[i].fn(&f, tri, bufs[i]);
        }
        oracle o;
        oracle_init(&o, &s, tri);
        int any_tie = 0;
        for (int j = 0; j < k; j++) {
            uint64_t hit = oracle_row(&o, j);
            occluded += __builtin_popcountll(hit);
            uint64_t want = ~hit & (k == 64 ? ~0ull : ((1ull << k) - 1));
            uint64_t wb, wh;
            buffer_row_get(bufs[2], k, j, &wb);
            buffer_row_get(bufs[3], k, j, &wh);
            bounds_hier_diff += wb != wh;
            for (int c = 0; c < 3; c++) {
                const int i = c == 2 ? i_b2 : c ? i_hd : i_bd;
                if (i < 0) continue;
                uint64_t wd;
                buffer_row_get(bufs[i], k, j, &wd);
                isa_build_diff += wd != (c == 1 ? wh : wb);
            }
            if (cmp_simd) {
                uint64_t w512, w2;
                buffer_row_get(bufs[1], k, j, &w512);
                buffer_row_get(bufs[i_avx2], k, j, &w2);
                simd_diff += w512 != w2;
            }
            for (int i = 0; i < nk; i++) {
                uint64_t got;
                buffer_row_get(bufs[i], k, j, &got);
                uint64_t diff = got ^ want;
                while (diff) {
                    int x = __builtin_ctzll(diff);
                    diff &= diff - 1;
                    if (oracle_tie(&o, x, j)) { kt[i].ties++; any_tie = 1; }
                    else {
                        if (kt[i].bad < 5)
                            print_error("%s k=%d: triangle %ld (%s) sample (%d,%d): kernel %s, oracle %s; "
                                        "tri %a %a %a  %a %a %a  %a %a %a\n",
                                        kt[i].name, k, t, cat_name[cat], x, j, (got >> x) & 1 ? "visible" : "occluded",
                                        (want >> x) & 1 ? "visible" : "occluded", tri[0], tri[1], tri[2], tri[3],
                                        tri[4], tri[5], tri[6], tri[7], tri[8]);
                        kt[i].bad++;
                    }
                }
            }
        }
        g_cat_ties[cat] += any_tie;
    }
    double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("k=%d: %ld triangles in %ld frames (%ld grazing), %.2f s, %ld occluded samples (oracle), kernel variant %s\n",
           k, n_tris, frames, grazing_frames, secs, occluded, ms_isa_name(chosen));
    for (int i = 0; i < nk; i++)
        printf("  %-16s ties %ld (%.2e per sample), non-tie differences %ld\n", kt[i].name, kt[i].ties,
               (double)kt[i].ties / ((double)n_tris * k * k), kt[i].bad);
    printf("  triangles with a tie by category:");
    for (int c = 0; c < CAT_COUNT; c++) printf(" %s %ld/%ld", cat_name[c], g_cat_ties[c], g_cat_count[c]);
    printf("\n  bounds vs hierarchical: %ld differing scanlines; portable vs ISA-compiled bounds/hierarchical: %ld\n",
           bounds_hier_diff, isa_build_diff);
    if (cmp_simd) printf("  scanline avx512 vs avx2: %ld differing scanlines\n", simd_diff);
    for (int i = 0; i < nk; i++) assert_int_equal(kt[i].bad, 0);
    assert_int_equal(bounds_hier_diff, 0);
    assert_int_equal(isa_build_diff, 0);
    /* Ties are rare (most come from the flat-edge and touch-clip categories, which put edges and
     * vertices exactly on sample rows and clip planes on purpose): under one sample in a thousand. */
    for (int i = 0; i < nk; i++) assert_true(kt[i].ties * 1000 < n_tris * k * k);
}

static long scaled(long n)
{
    const char *e = getenv("MS_KERNEL_TEST_SCALE");
    double s = e ? atof(e) : 1.0;
    return s > 0 ? (long)(n * s) : n;
}

static void test_random_32(void **state) { (void)state; run_random(32, scaled(500000), 1); }
static void test_random_16(void **state) { (void)state; run_random(16, scaled(300000), 2); }
static void test_random_64(void **state) { (void)state; run_random(64, scaled(150000), 3); }

/* ---- targeted checks ---- */
static void exact_scene(scene *s, int k)
{
    tu_rng r = { 0 };
    do scene_random(s, &r, k);
    while (!s->exact);
    s->near = 1e-4f;
    s->far = 1.0f;
}

static void test_frame_maps_samples(void **state)
{
    (void)state;
    tu_rng r = { 42 };
    for (int it = 0; it < 200; it++) {
        scene s;
        scene_random(&s, &r, 32);
        ms_raster_frame f;
        if (ms_raster_frame_init(&f, s.c, &s.g, 1e-4f, 1.0f, 0) != 0) continue;
        for (int j = 0; j < 32; j += 31)
            for (int i = 0; i < 32; i += 31) {
                double p[3];
                for (int c = 0; c < 3; c++) p[c] = s.g.p0[c] + i * (double)s.g.ds[c] + j * (double)s.g.dt[c] - s.c[c];
                double want[3] = { i, j, 1 };
                for (int rr = 0; rr < 3; rr++) {
                    /* m is rounded once per entry: the error is relative to the terms' magnitudes (large
                     * in the grazing frames, whose m is ill-conditioned). */
                    double x = f.m[rr][0] * p[0] + f.m[rr][1] * p[1] + f.m[rr][2] * p[2];
                    double terms = fabs(f.m[rr][0] * p[0]) + fabs(f.m[rr][1] * p[1]) + fabs(f.m[rr][2] * p[2]);
                    assert_true(fabs(x - want[rr]) < 1e-6 * (1 + terms));
                }
            }
    }
    /* C on the light plane is refused. */
    scene s;
    exact_scene(&s, 32);
    ms_raster_frame f;
    float on_plane[3] = { 0.5f, 0.5f, 0.0f };
    assert_int_equal(ms_raster_frame_init(&f, on_plane, &s.g, 1e-4f, 1.0f, 0), -1);
}

static void test_buffer_queries(void **state)
{
    (void)state;
    const int ks[3] = { 16, 32, 64 };
    for (int t = 0; t < 3; t++) {
        int k = ks[t];
        uint64_t buf[64];
        ms_buffer_fill_visible(buf, k);
        assert_int_equal(ms_buffer_visible_count(buf, k), k * k);
        assert_false(ms_buffer_all_occluded(buf, k));
        memset(buf, 0, (size_t)k * k / 8);
        assert_true(ms_buffer_all_occluded(buf, k));
        assert_int_equal(ms_buffer_visible_count(buf, k), 0);
        ((unsigned char *)buf)[k * k / 8 - 1] = 0x81;
        assert_false(ms_buffer_all_occluded(buf, k));
        assert_int_equal(ms_buffer_visible_count(buf, k), 2);
    }
}

/* A triangle given in light-index coordinates of an exact frame, run through every kernel: scalar
 * Scanline, dispatched Scanline, Bounds, Hierarchical and the AVX2 Scanline (the scalar one again
 * without AVX2+FMA). */
enum { NFNS = 5 };
static void all_kernels(const scene *s, const double v[9], int cull, uint64_t out[NFNS][64])
{
    ms_raster_frame f;
    assert_int_equal(ms_raster_frame_init(&f, s->c, &s->g, s->near, s->far, cull), 0);
    float tri[9];
    for (int i = 0; i < 3; i++) to_world(s, v + 3 * i, tri + 3 * i);
    ms_raster_fn avx2 = tu_isa_allowed(MS_ISA_AVX2) ? ms_raster_kernel_isa(MS_KERNEL_SCANLINE, s->k, MS_ISA_AVX2) : NULL;
    ms_raster_fn fns[NFNS] = { ms_raster_kernel_isa(MS_KERNEL_SCANLINE, s->k, MS_ISA_SCALAR), ms_raster_kernel(MS_KERNEL_SCANLINE, s->k, tu_isa_cap(), NULL),
                               ms_raster_kernel(MS_KERNEL_BOUNDS, s->k, tu_isa_cap(), NULL), ms_raster_kernel(MS_KERNEL_HIERARCHICAL, s->k, tu_isa_cap(), NULL),
                               avx2 ? avx2 : ms_raster_kernel_isa(MS_KERNEL_SCANLINE, s->k, MS_ISA_SCALAR) };
    for (int i = 0; i < NFNS; i++) {
        ms_buffer_fill_visible(out[i], s->k);
        fns[i](&f, tri, out[i]);
    }
}

static void test_special_cases(void **state)
{
    (void)state;
    const int ks[3] = { 16, 32, 64 };
    for (int t = 0; t < 3; t++) {
        int k = ks[t];
        scene s;
        exact_scene(&s, k);
        uint64_t out[NFNS][64];
        /* Huge triangle at half depth: the whole buffer occluded; early out true. */
        double huge[9] = { -1000, -1000, 0.5, 5000, -1000, 0.5, -1000, 5000, 0.5 };
        all_kernels(&s, huge, 0, out);
        for (int i = 0; i < NFNS; i++) assert_true(ms_buffer_all_occluded(out[i], k));
        /* Both windings of a square's halves give the same shadow: an axis-aligned quad with edges on
         * scanlines y = 2 and y = 5 (exactly on samples) and columns x = 3 and x = 9, at depth 0.5. */
        for (int wind = 0; wind < 2; wind++) {
            double a[9] = { 3 * .5, 2 * .5, .5, 9 * .5, 2 * .5, .5, 9 * .5, 5 * .5, .5 };
            double b[9] = { 3 * .5, 2 * .5, .5, 9 * .5, 5 * .5, .5, 3 * .5, 5 * .5, .5 };
            if (wind) { for (int c = 0; c < 3; c++) { double x = a[3 + c]; a[3 + c] = a[6 + c]; a[6 + c] = x; x = b[3 + c]; b[3 + c] = b[6 + c]; b[6 + c] = x; } }
            uint64_t oa[NFNS][64], ob[NFNS][64];
            all_kernels(&s, a, 0, oa);
            all_kernels(&s, b, 0, ob);
            for (int i = 0; i < NFNS; i++) {
                int vis_a = ms_buffer_visible_count(oa[i], k), vis_b = ms_buffer_visible_count(ob[i], k);
                /* Closed edges: the rectangle's 7 x 4 samples plus the diagonal's shares overlap. */
                assert_int_equal(k * k - vis_a, 7 * 4 - (wind ? 0 : 0) - (7 * 4 - (k * k - vis_a)));
                (void)vis_b;
                for (int y = 0; y < k; y++) {
                    uint64_t wa, wb2;
                    buffer_row_get(oa[i], k, y, &wa);
                    buffer_row_get(ob[i], k, y, &wb2);
                    uint64_t both = ~(wa & wb2) & (k == 64 ? ~0ull : (1ull << k) - 1);
                    uint64_t want = (y >= 2 && y <= 5) ? (((1ull << 7) - 1) << 3) : 0;
                    assert_true(both == want);
                }
            }
        }
        /* A triangle in the z = 0 plane (contains C's plane), behind C, beyond the light: no shadow. */
        double flat0[9] = { -5, -5, 0, 50, -5, 0, -5, 50, 0 };
        double behind[9] = { -5, -5, -0.5, 50, -5, -0.5, -5, 50, -0.5 };
        double beyond[9] = { -5, -5, 1.5, 50, -5, 1.5, -5, 50, 1.5 };
        double *none[3] = { flat0, behind, beyond };
        for (int c = 0; c < 3; c++) {
            all_kernels(&s, none[c], 0, out);
            for (int i = 0; i < NFNS; i++) assert_int_equal(ms_buffer_visible_count(out[i], k), k * k);
        }
        /* A triangle crossing z = 0 whose front part covers the light: occludes everything in front. */
        double cross[9] = { -1000, -1000, -0.5, 5000 * .9, -1000 * .9, .9, -1000 * .9, 5000 * .9, .9 };
        all_kernels(&s, cross, 0, out);
        for (int i = 1; i < NFNS; i++)
            assert_int_equal(ms_buffer_visible_count(out[i], k), ms_buffer_visible_count(out[0], k));
        /* Culling: exactly one winding of a covering triangle occludes. */
        double wa[9] = { -1000, -1000, 0.5, 5000, -1000, 0.5, -1000, 5000, 0.5 };
        double wb[9] = { -1000, -1000, 0.5, -1000, 5000, 0.5, 5000, -1000, 0.5 };
        uint64_t oa[NFNS][64], ob[NFNS][64];
        all_kernels(&s, wa, 1, oa);
        all_kernels(&s, wb, 1, ob);
        for (int i = 0; i < NFNS; i++) {
            int va = ms_buffer_visible_count(oa[i], k), vb = ms_buffer_visible_count(ob[i], k);
            assert_true((va == 0 && vb == k * k) || (va == k * k && vb == 0));
        }
        /* The winding that survives is the one facing C: normal towards C. Light at z = 0, C at z = -1,
         * the triangle at z = -0.5: wa's normal (CCW in x, y) is +z, away from C: culled. */
        assert_int_equal(ms_buffer_visible_count(oa[0], k), k * k);
    }
}

/* Culling against the oracle on random triangles: with culling, a kernel gives the oracle's answer for
 * triangles facing C and nothing for the others. */
static void test_culling_random(void **state)
{
    (void)state;
    tu_rng r = { 99 };
    long checked = 0, culled = 0;
    /* Every kernel as dispatched, and the AVX2 Scanline when the CPU has it. */
    ms_raster_fn fns[MS_KERNEL_COUNT + 1];
    int nf = 0;
    for (int kid = 0; kid < MS_KERNEL_COUNT; kid++) fns[nf++] = ms_raster_kernel((ms_kernel_id)kid, 32, tu_isa_cap(), NULL);
    if (tu_isa_allowed(MS_ISA_AVX2) && ms_raster_kernel_isa(MS_KERNEL_SCANLINE, 32, MS_ISA_AVX2))
        fns[nf++] = ms_raster_kernel_isa(MS_KERNEL_SCANLINE, 32, MS_ISA_AVX2);
    for (int t = 0; t < 20000; t++) {
        scene s;
        ms_raster_frame f0, f1;
        do scene_random(&s, &r, 32);
        while (ms_raster_frame_init(&f0, s.c, &s.g, s.near, s.far, 0) != 0);
        ms_raster_frame_init(&f1, s.c, &s.g, s.near, s.far, 1);
        float tri[9];
        tri_random(&s, &r, tri);
        /* Facing C: the normal (P1-P0)x(P2-P0) points towards C. */
        double e1[3], e2[3], n[3], pc[3];
        for (int c = 0; c < 3; c++) { e1[c] = tri[3 + c] - tri[c]; e2[c] = tri[6 + c] - tri[c]; pc[c] = s.c[c] - tri[c]; }
        cross3(n, e1, e2);
        double facing = dot3(n, pc);
        if (fabs(facing) < 1e-3 * len3(n) * len3(pc)) continue;
        for (int i = 0; i < nf; i++) {
            uint64_t a[16], b[16];
            ms_buffer_fill_visible(a, 32);
            ms_buffer_fill_visible(b, 32);
            fns[i](&f0, tri, a);
            fns[i](&f1, tri, b);
            if (facing > 0) assert_memory_equal(a, b, sizeof a);
            else assert_int_equal(ms_buffer_visible_count(b, 32), 32 * 32);
        }
        checked++;
        culled += facing <= 0;
    }
    printf("culling: %ld triangles, %ld facing away\n", checked, culled);
}

static void test_kernel_table(void **state)
{
    (void)state;
    for (int id = 0; id < MS_KERNEL_COUNT; id++) {
        assert_non_null(ms_raster_kernel((ms_kernel_id)id, 16, MS_ISA_AUTO, NULL));
        assert_non_null(ms_raster_kernel_isa((ms_kernel_id)id, 64, MS_ISA_SCALAR));
        assert_null(ms_raster_kernel((ms_kernel_id)id, 8, MS_ISA_AUTO, NULL));
        assert_null(ms_raster_kernel_isa((ms_kernel_id)id, 128, MS_ISA_SCALAR));
    }
    assert_string_equal(ms_kernel_name(MS_KERNEL_SCANLINE), "scanline");
    /* Forced variants: scalar always; a SIMD one only when the CPU has it, and the one the probe names is
     * the one ms_raster_kernel dispatches to without a cap. */
    const ms_isa isa = ms_cpu_isa();
    assert_true(isa == MS_ISA_AVX512 || isa == MS_ISA_AVX2 || isa == MS_ISA_SCALAR);
    const int ks[3] = { 16, 32, 64 };
    for (int t = 0; t < 3; t++) {
        const int k = ks[t];
        for (int id = 0; id < MS_KERNEL_COUNT; id++)
            assert_ptr_equal(ms_raster_kernel_isa((ms_kernel_id)id, k, MS_ISA_SCALAR),
                             ms_raster_kernel((ms_kernel_id)id, k, MS_ISA_SCALAR, NULL));
        assert_ptr_equal(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, isa), ms_raster_kernel(MS_KERNEL_SCANLINE, k, MS_ISA_AUTO, NULL));
        for (int id = 0; id < MS_KERNEL_COUNT; id++)
            assert_ptr_equal(ms_raster_kernel_isa((ms_kernel_id)id, k, isa), ms_raster_kernel((ms_kernel_id)id, k, MS_ISA_AUTO, NULL));
        if (isa != MS_ISA_SCALAR) assert_non_null(ms_raster_kernel_isa(MS_KERNEL_BOUNDS, k, MS_ISA_AVX2));
        assert_null(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_AUTO));
        assert_null(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, (ms_isa)7));
        if (isa != MS_ISA_SCALAR) assert_non_null(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_AVX2));
        if (isa != MS_ISA_AVX512) assert_null(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, MS_ISA_AVX512));
    }
    assert_null(ms_raster_kernel_isa(MS_KERNEL_SCANLINE, 8, MS_ISA_SCALAR));
    printf("kernel variant %s; avx2 variant %s\n", ms_isa_name(isa),
           ms_raster_kernel_isa(MS_KERNEL_SCANLINE, 32, MS_ISA_AVX2) ? "available" : "not available (no AVX2+FMA)");
}

/* The ISA cap is obeyed and reported: a cap at or below the CPU's level gives that level, a cap above it
 * or none gives the CPU's best. Also the names. */
static void test_isa_cap(void **state)
{
    (void)state;
    const ms_isa best = ms_cpu_isa();
    const ms_isa caps[] = { MS_ISA_AUTO, MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    for (int c = 0; c < 4; c++) {
        const ms_isa want = caps[c] == MS_ISA_AUTO || caps[c] > best ? best : caps[c];
        for (int k = 16; k <= 64; k *= 2) {
            ms_isa chosen = MS_ISA_AUTO;
            const ms_raster_fn fn = ms_raster_kernel(MS_KERNEL_SCANLINE, k, caps[c], &chosen);
            assert_int_equal(chosen, want);
            assert_ptr_equal(fn, ms_raster_kernel_isa(MS_KERNEL_SCANLINE, k, want));
            chosen = MS_ISA_AUTO;
            assert_ptr_equal(ms_raster_kernel(MS_KERNEL_HIERARCHICAL, k, caps[c], &chosen),
                             ms_raster_kernel_isa(MS_KERNEL_HIERARCHICAL, k, want));
            assert_int_equal(chosen, want);
        }
        printf("cap %-6s -> scanline %s (cpu %s)\n", ms_isa_name(caps[c]), ms_isa_name(want), ms_isa_name(best));
    }
    /* cap scalar gives scalar; cap avx2 on an AVX-512 CPU gives avx2 */
    ms_isa chosen = MS_ISA_AUTO;
    ms_raster_kernel(MS_KERNEL_SCANLINE, 32, MS_ISA_SCALAR, &chosen);
    assert_int_equal(chosen, MS_ISA_SCALAR);
    if (best == MS_ISA_AVX512) {
        ms_raster_kernel(MS_KERNEL_SCANLINE, 32, MS_ISA_AVX2, &chosen);
        assert_int_equal(chosen, MS_ISA_AVX2);
    }
    for (int c = 0; c < 4; c++) {
        ms_isa back = (ms_isa)-1;
        assert_int_equal(ms_isa_from_name(ms_isa_name(caps[c]), &back), 0);
        assert_int_equal(back, caps[c]);
    }
    ms_isa dummy;
    assert_int_equal(ms_isa_from_name("sse", &dummy), MS_ERR_INVALID);
    assert_int_equal(ms_isa_from_name(NULL, &dummy), MS_ERR_INVALID);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kernel_table),
        cmocka_unit_test(test_isa_cap),
        cmocka_unit_test(test_frame_maps_samples),
        cmocka_unit_test(test_buffer_queries),
        cmocka_unit_test(test_special_cases),
        cmocka_unit_test(test_culling_random),
        cmocka_unit_test(test_random_16),
        cmocka_unit_test(test_random_32),
        cmocka_unit_test(test_random_64),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
