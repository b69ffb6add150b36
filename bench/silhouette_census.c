/* What an edge-based visibility in the manner of soft shadow volumes (Laine, Aila, Assarsson, Lehtinen,
 * Akenine-Moller, "Soft Shadow Volumes for Ray Tracing", SIGGRAPH 2005) would have to process on a scene,
 * against what the triangles are, and how often its answer differs from the reference sample for sample:
 * the measurement that decides whether the scanline method should rasterize edges instead of triangles
 * (issue 46; docs/notebook/2026-11-29-silhouette-census.md). A bench program: nothing of it is in the library.
 *
 * For a point P, the number D of triangles a segment from P to a light sample crosses changes only where
 * the sample crosses the projection (from P onto the light's plane) of an edge: each face of the edge adds
 * 1 on the side its third vertex projects to. A manifold edge whose two faces lie on either side (not a
 * silhouette seen from P) changes nothing; a silhouette edge changes D by 2, a boundary edge by 1. The paper
 * takes closed meshes; this form needs no orientation or closedness, only triangles wholly in the occlusion
 * range [1e-4, 1 - 1e-4] of the segments (the others are counted as triangles). So D at every sample of a
 * row follows from D at the row's first sample (one counted ray) and the edges crossing the row; the sample
 * is occluded when D > 0. A two-face edge can change D over the light only if some point of the light sees
 * the faces fold (P and that point lie on either side of both faces' planes), which a corner test finds once
 * per light.
 *
 * Per visible pixel of the scene's camera (our BVH for the primary hit), on a k x k grid of sample centres
 * on light 0 (a parallelogram), it counts: the reference occlusion of every front sample (our watertight
 * segment test, every crossing); the pixel's class; for penumbra pixels, the triangles that occlude some
 * sample (a lower bound of what a triangle method rasterizes), the edges that change D over the light and
 * the candidate edges a traversal would test; and the samples where the edge answer (projections in double,
 * the row's reference counted by the float watertight test) differs from the reference: ties between two
 * predicates, which an exact method must detect and re-decide.
 *
 * usage: silhouette_census SCENE.json [SIZE [K]]   (SIZE: square frame, default 128; K: 16 = 256 samples) */
#include "microshadow.h"
#include "accel/bvh.h"
#include "accel/closed.h"
#include "camera/camera.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NEAR 1e-4f
#define FAR (1.0f - 1e-4f)
#define MAXK 64

typedef struct edge_rec { float key[6]; uint32_t tri; uint8_t e; } edge_rec;

static int cmp_edge(const void *pa, const void *pb)
{
    const edge_rec *a = pa, *b = pb;
    int c = memcmp(a->key, b->key, sizeof a->key);
    return c ? c : (a->tri > b->tri) - (a->tri < b->tri);
}

/* Orders the endpoints so both triangles of an edge give the same key. */
static void edge_key(const float *p, const float *q, float key[6])
{
    if (memcmp(p, q, 3 * sizeof(float)) < 0) { memcpy(key, p, 12); memcpy(key + 3, q, 12); }
    else { memcpy(key, q, 12); memcpy(key + 3, p, 12); }
}

/* An edge and its faces: each face by its source index and its third vertex. */
typedef struct sil_face { uint32_t tri; float c[3]; } sil_face;
typedef struct sil_edge { float a[3], b[3]; uint32_t first, count; } sil_edge;

static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3d(const float a[3], const float b[3]) { return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]; }

/* The light's plane: P + lambda (X - P) meets it at lambda; (s, t) in the light's parameters. 0 when X - P is
 * parallel to the plane. */
typedef struct light_frame { float c0[3], es[3], et[3], nl[3]; double ds[3], dt[3]; } light_frame;

static int project(const light_frame *L, const float P[3], const float X[3], double *lambda, double st[2])
{
    double d[3] = { (double)X[0] - P[0], (double)X[1] - P[1], (double)X[2] - P[2] };
    double den = L->nl[0] * d[0] + L->nl[1] * d[1] + L->nl[2] * d[2];
    double num = L->nl[0] * ((double)L->c0[0] - P[0]) + L->nl[1] * ((double)L->c0[1] - P[1]) + L->nl[2] * ((double)L->c0[2] - P[2]);
    if (den == 0.0) return 0;
    *lambda = num / den;
    double y[3];
    for (int i = 0; i < 3; i++) y[i] = P[i] + *lambda * d[i] - L->c0[i];
    st[0] = y[0] * L->ds[0] + y[1] * L->ds[1] + y[2] * L->ds[2];
    st[1] = y[0] * L->dt[0] + y[1] * L->dt[1] + y[2] * L->dt[2];
    return 1;
}

/* A triangle lies wholly between the near plane and the light's plane as seen from P: each vertex X reaches
 * the light's plane at lambda in [1 / (1 - 1e-4), 1e4], i.e. its depth u = 1 / lambda along the segments
 * lies in the occlusion range [1e-4, 1 - 1e-4]. Then every segment from P to the light that meets it does so
 * in range, and its crossings are a matter of topology alone. */
static int lambda_safe(double l) { return l >= 1.0 / (1.0 - 1e-4) && l <= 1e4; }
static int tri_safe(const light_frame *L, const float P[3], const float *v)
{
    for (int k = 0; k < 3; k++) {
        double l, st[2];
        if (!project(L, P, v + 3 * k, &l, st) || !lambda_safe(l)) return 0;
    }
    return 1;
}

/* Every hit of the segment from P along d (near and far ranges), skipping prim `skip`: counted apart for the
 * triangles wholly in range (tri_safe) and the others; hit triangles marked with `stamp` (leaf order). */
static void seg_hits(const ms_bvh *b, const light_frame *L, const float o[3], const float d[3], uint32_t skip,
                     int *n_safe, int *n_unsafe, uint32_t *mark, uint32_t stamp, size_t *n_marked, size_t *n_marked_unsafe)
{
    uint32_t stack[1024];
    int sp = 0;
    stack[sp++] = 0;
    float inv[3] = { 1.0f / d[0], 1.0f / d[1], 1.0f / d[2] };
    *n_safe = 0;
    *n_unsafe = 0;
    while (sp) {
        const ms_bvh_node *nd = &b->nodes[stack[--sp]];
        float t0 = 0.0f, t1 = 1.0f;
        for (int a = 0; a < 3; a++) {
            float ta = (nd->bmin[a] - o[a]) * inv[a], tb = (nd->bmax[a] - o[a]) * inv[a];
            if (ta > tb) { float s = ta; ta = tb; tb = s; }
            if (ta > t0) t0 = ta;
            if (tb < t1) t1 = tb;
        }
        if (!(t0 <= t1 * 1.0000001f + 1e-7f)) continue;
        if (nd->count == 0) {
            if (sp + 2 > 1024) abort();
            stack[sp++] = nd->first; stack[sp++] = nd->first + 1; continue;
        }
        for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
            if (i == skip) continue;
            float t, u, v;
            if (!ms_intersect_triangle(b->tri + 9 * (size_t)i, o, d, NEAR, FAR, &t, &u, &v)) continue;
            const int safe = tri_safe(L, o, b->tri + 9 * (size_t)i);
            if (safe) (*n_safe)++; else (*n_unsafe)++;
            if (mark && mark[i] != stamp) { mark[i] = stamp; (*n_marked)++; *n_marked_unsafe += !safe; }
        }
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) { fprintf(stderr, "usage: silhouette_census SCENE.json [SIZE [K]]\n"); return 2; }
    const int W = argc > 2 ? atoi(argv[2]) : 128, K = argc > 3 ? atoi(argv[3]) : 16;
    if (W < 1 || K < 2 || K > MAXK) { fprintf(stderr, "silhouette_census: bad size or K\n"); return 2; }
    char err[1024];
    ms_scene sc;
    if (ms_scene_load(argv[1], &sc, err, sizeof err)) { fprintf(stderr, "silhouette_census: %s\n", err); return 2; }
    size_t nl;
    const ms_light *light = ms_scene_lights(&sc, &nl);
    light_frame L;
    memcpy(L.c0, &light->corner, 12); memcpy(L.es, &light->edge_s, 12); memcpy(L.et, &light->edge_t, 12);
    cross3(L.es, L.et, L.nl);
    {   /* dual basis of (es, et) in the plane: y . ds = s, y . dt = t */
        double ss = dot3d(L.es, L.es), tt = dot3d(L.et, L.et), st = dot3d(L.es, L.et), det = ss * tt - st * st;
        for (int i = 0; i < 3; i++) {
            L.ds[i] = (tt * L.es[i] - st * L.et[i]) / det;
            L.dt[i] = (ss * L.et[i] - st * L.es[i]) / det;
        }
    }
    const size_t n = sc.n_tris;
    if (!sc.tri) {   /* a procedural scene: its triangles made here */
        sc.tri = malloc(9 * n * sizeof(float));
        if (!sc.tri) return 1;
        ms_procedural_triangles(&sc, 0, n, sc.tri);
    }
    ms_closed cl;
    if (ms_closed_find(sc.tri, n, &cl)) return 1;
    ms_bvh bvh;
    if (ms_bvh_build(&bvh, sc.tri, n, 0)) return 1;

    /* Every edge (endpoints bitwise equal) with its faces, whatever the topology: a boundary has one, a
     * manifold edge two, a fin more. */
    edge_rec *er = malloc(3 * n * sizeof *er);
    if (!er) return 1;
    size_t ne = 0;
    for (size_t t = 0; t < n; t++) {
        const float *v = sc.tri + 9 * t;
        for (int e = 0; e < 3; e++) {
            edge_key(v + 3 * e, v + 3 * ((e + 1) % 3), er[ne].key);
            er[ne].tri = (uint32_t)t;
            er[ne].e = (uint8_t)e;
            ne++;
        }
    }
    qsort(er, ne, sizeof *er, cmp_edge);
    float corners[4][3];
    for (int i = 0; i < 3; i++) {
        corners[0][i] = L.c0[i]; corners[1][i] = L.c0[i] + L.es[i];
        corners[2][i] = L.c0[i] + L.et[i]; corners[3][i] = L.c0[i] + L.es[i] + L.et[i];
    }
    sil_edge *sil = malloc(ne * sizeof *sil);
    sil_face *faces = malloc(ne * sizeof *faces);
    if (!sil || !faces) return 1;
    size_t nsil = 0, n_edges = 0, n_faces = 0, n_boundary = 0, n_fin = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && !memcmp(er[i].key, er[j].key, sizeof er[i].key)) j++;
        n_edges++;
        const size_t m = j - i;
        n_boundary += m == 1;
        n_fin += m > 2;
        const float *a = er[i].key, *b = er[i].key + 3;
        int keep = m != 2;
        if (m == 2) {
            /* Two faces: the edge changes the count only where they fold (their third vertices on one side of
             * the plane through the viewpoint and the edge); skipped when no corner of the light sees a fold
             * and the pattern is the same at every corner (then it is the same over the light). */
            const float *c1 = sc.tri + 9 * (size_t)er[i].tri + 3 * ((er[i].e + 2) % 3);
            const float *c2 = sc.tri + 9 * (size_t)er[i + 1].tri + 3 * ((er[i + 1].e + 2) % 3);
            float ab[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
            float ac1[3] = { c1[0] - a[0], c1[1] - a[1], c1[2] - a[2] }, ac2[3] = { c2[0] - a[0], c2[1] - a[1], c2[2] - a[2] };
            float m1[3], m2[3];
            cross3(ac1, ab, m1);
            cross3(ac2, ab, m2);
            int first = -1, mixed = 0;
            for (int c = 0; c < 4; c++) {
                float x[3] = { corners[c][0] - a[0], corners[c][1] - a[1], corners[c][2] - a[2] };
                const int sgn = (dot3d(m1, x) > 0) * 2 + (dot3d(m2, x) > 0);
                if (first < 0) first = sgn; else if (sgn != first) mixed = 1;
            }
            keep = mixed || first == 0 || first == 3;
        }
        if (keep) {
            sil_edge *s = &sil[nsil++];
            memcpy(s->a, a, 12);
            memcpy(s->b, b, 12);
            s->first = (uint32_t)n_faces;
            s->count = (uint32_t)m;
            for (size_t k = i; k < j; k++) {
                faces[n_faces].tri = er[k].tri;
                memcpy(faces[n_faces].c, sc.tri + 9 * (size_t)er[k].tri + 3 * ((er[k].e + 2) % 3), 12);
                n_faces++;
            }
        }
        i = j;
    }

    ms_camera_basis cam;
    if (ms_camera_basis_init(&cam, &sc.camera, W, W)) { fprintf(stderr, "silhouette_census: camera\n"); return 2; }
    /* Totals. */
    unsigned long long px_vis = 0, px_lit = 0, px_umbra = 0, px_pen = 0, pen_hit_tris = 0, pen_sil = 0;
    unsigned long long ground_pen = 0, ground_pen_sil = 0, ground_pen_tris = 0;
    unsigned long long samples_checked = 0, samples_off = 0, px_off = 0, odd_d = 0, neg_d = 0;
    unsigned long long pen_cand = 0, pen_unsafe = 0, closed_pen = 0, closed_pen_sil = 0, closed_samples = 0, closed_off = 0, closed_px_off = 0;
    double max_tris = 0, max_sil = 0;
#pragma omp parallel reduction(+:px_vis,px_lit,px_umbra,px_pen,pen_hit_tris,pen_sil,ground_pen,ground_pen_sil,ground_pen_tris,samples_checked,samples_off,px_off,odd_d,neg_d,closed_pen,closed_pen_sil,closed_samples,closed_off,closed_px_off,pen_unsafe,pen_cand) reduction(max:max_tris,max_sil)
    {
        uint32_t *mark = calloc(n, sizeof *mark);
        uint32_t stamp = 0;
#pragma omp for schedule(dynamic, 16)
        for (int pix = 0; pix < W * W; pix++) {
            float o[3], d[3];
            if (ms_camera_ray(&cam, pix % W, pix / W, o, d)) continue;
            ms_ray r = { { o[0], o[1], o[2] }, { d[0], d[1], d[2] }, 0.0f, INFINITY };
            ms_ray_hit h;
            if (!ms_bvh_closest(&bvh, &r, &h)) continue;
            px_vis++;
            const float P[3] = { o[0] + h.t * d[0], o[1] + h.t * d[1], o[2] + h.t * d[2] };
            float nrm[3];
            memcpy(nrm, bvh.tri_n + 3 * (size_t)h.prim, 12);
            if (dot3d(nrm, d) > 0) { nrm[0] = -nrm[0]; nrm[1] = -nrm[1]; nrm[2] = -nrm[2]; }
            const int on_closed = cl.component[bvh.tri_source[h.prim]] != MS_OPEN_COMPONENT;
            /* Reference: every front sample. */
            static _Thread_local unsigned char occ[MAXK][MAXK], front[MAXK][MAXK];
            static _Thread_local int dref[MAXK];
            int n_front = 0, n_occ = 0;
            stamp++;
            size_t n_marked = 0, n_marked_unsafe = 0;
            for (int j = 0; j < K; j++)
                for (int i = 0; i < K; i++) {
                    float S[3], sd[3];
                    for (int a = 0; a < 3; a++) {
                        S[a] = L.c0[a] + ((float)i + 0.5f) / (float)K * L.es[a] + ((float)j + 0.5f) / (float)K * L.et[a];
                        sd[a] = S[a] - P[a];
                    }
                    front[j][i] = dot3d(sd, nrm) > 0;
                    occ[j][i] = 0;
                    int ns, nu;
                    seg_hits(&bvh, &L, P, sd, h.prim, &ns, &nu, mark, stamp, &n_marked, &n_marked_unsafe);
                    if (i == 0) dref[j] = ns;
                    if (!front[j][i]) continue;
                    n_front++;
                    occ[j][i] = ns + nu > 0;
                    n_occ += occ[j][i];
                }
            if (n_front == 0) continue;
            if (n_occ == 0) { px_lit++; continue; }
            if (n_occ == n_front) { px_umbra++; continue; }
            px_pen++;
            pen_hit_tris += n_marked;
            if ((double)n_marked > max_tris) max_tris = (double)n_marked;
            /* Silhouette edges from P projecting onto the light; D along each row from its first sample. */
            static _Thread_local int dd[MAXK][MAXK];
            for (int j = 0; j < K; j++) for (int i = 0; i < K; i++) dd[j][i] = 0;
            int n_s = 0, n_cand = 0;
            const uint32_t rsrc = bvh.tri_source[h.prim];
            for (size_t e = 0; e < nsil; e++) {
                const sil_edge *s = &sil[e];
                double la, lb, A[2], B[2];
                if (!project(&L, P, s->a, &la, A) || !project(&L, P, s->b, &lb, B)) continue;
                if (!lambda_safe(la) || !lambda_safe(lb)) continue;   /* no face of it is in range */
                const double smin = fmin(A[0], B[0]), smax = fmax(A[0], B[0]), tmin = fmin(A[1], B[1]), tmax = fmax(A[1], B[1]);
                if (smax < 0 || smin > 1 || tmax < 0 || tmin > 1) continue;
                n_cand++;
                const double ex = B[0] - A[0], ey = B[1] - A[1];
                /* Each face in range (not the receiver's): +1 crossing towards +s into the side its third vertex
                 * projects to, -1 leaving it. */
                int delta = 0;
                for (uint32_t f = s->first; f < s->first + s->count; f++) {
                    if (faces[f].tri == rsrc) continue;
                    double lc, C[2];
                    if (!project(&L, P, faces[f].c, &lc, C) || !lambda_safe(lc)) continue;
                    const double side_c = ex * (C[1] - A[1]) - ey * (C[0] - A[0]);
                    delta += ((-ey > 0) == (side_c > 0)) ? 1 : -1;
                }
                if (delta == 0) continue;
                n_s++;
                for (int j = 0; j < K; j++) {
                    const double y = ((double)j + 0.5) / K;
                    if ((A[1] <= y) == (B[1] <= y)) continue;
                    const double xc = A[0] + (y - A[1]) * ex / ey;
                    const double x0 = 0.5 / K;
                    for (int i = 1; i < K; i++) {
                        const double xi = ((double)i + 0.5) / K;
                        if (xc > x0 && xc <= xi) dd[j][i] += delta;
                    }
                }
            }
            pen_unsafe += n_marked_unsafe;
            pen_cand += (unsigned long long)n_cand;
            pen_sil += (unsigned long long)n_s;
            if (n_s > max_sil) max_sil = n_s;
            if (on_closed) { closed_pen++; closed_pen_sil += (unsigned long long)n_s; }
            else { ground_pen++;
            ground_pen_sil += (unsigned long long)n_s;
            ground_pen_tris += n_marked; }
            int off = 0;
            for (int j = 0; j < K; j++)
                for (int i = 0; i < K; i++) {
                    const int D = dref[j] + dd[j][i];
                    if (D < 0) neg_d++;
                    if (!front[j][i]) continue;
                    /* Open triangles: the reference's own any-hit for them is not separable here, so compare
                     * only where the sample's open-triangle answer is recomputed. */
                    float S[3], sd[3];
                    for (int a = 0; a < 3; a++) {
                        S[a] = L.c0[a] + ((float)i + 0.5f) / (float)K * L.es[a] + ((float)j + 0.5f) / (float)K * L.et[a];
                        sd[a] = S[a] - P[a];
                    }
                    int ns, nu;
                    seg_hits(&bvh, &L, P, sd, h.prim, &ns, &nu, NULL, 0, NULL, NULL);
                    const int sil_occ = D + nu > 0;
                    if (D != ns) odd_d++;
                    if (on_closed) { closed_samples++; if (sil_occ != occ[j][i]) { closed_off++; off = 1; } }
                    else { samples_checked++; if (sil_occ != occ[j][i]) { samples_off++; off = 1; } }
                }
            if (on_closed) closed_px_off += (unsigned long long)off; else px_off += (unsigned long long)off;
        }
        free(mark);
    }
    printf("%s: %zu triangles (%zu in closed components), %zu edges (%zu boundary, %zu with 3+ faces); %zu may change "
           "the crossing count seen from light 0's points (%.1f%%)\n", argv[1], n, cl.closed_tris, n_edges, n_boundary,
           n_fin, nsil, n_edges ? 100.0 * (double)nsil / (double)n_edges : 0.0);
    printf("%dx%d, %d samples: %llu visible pixels: lit %llu, umbra %llu, penumbra %llu\n", W, W, K * K, px_vis,
           px_lit, px_umbra, px_pen);
    if (px_pen)
        printf("penumbra pixel, mean: %.1f triangles occlude some sample (max %.0f), %.1f of them not wholly in range; "
               "%.1f edges change the count over the light (max %.0f) of %.1f candidates (in range, projected box on the "
               "light)\n", (double)pen_hit_tris / (double)px_pen,
               max_tris, (double)pen_unsafe / (double)px_pen, (double)pen_sil / (double)px_pen, max_sil,
               (double)pen_cand / (double)px_pen);
    printf("receivers off closed meshes: %llu penumbra pixels (%.1f occluding triangles, %.1f edges): %llu of %llu "
           "samples off the reference in %llu pixels\n", ground_pen,
           ground_pen ? (double)ground_pen_tris / (double)ground_pen : 0.0,
           ground_pen ? (double)ground_pen_sil / (double)ground_pen : 0.0, samples_off, samples_checked, px_off);
    printf("receivers on closed meshes: %llu penumbra pixels (%.1f edges): %llu of %llu samples off in %llu pixels\n",
           closed_pen, closed_pen ? (double)closed_pen_sil / (double)closed_pen : 0.0, closed_off, closed_samples,
           closed_px_off);
    printf("all checked samples: D from the edges differs from the counted crossings at %llu, negative at %llu\n",
           odd_d, neg_d);
    free(er);
    free(sil);
    free(faces);
    ms_bvh_free(&bvh);
    ms_closed_free(&cl);
    ms_scene_free(&sc);
    return 0;
}
