/* Per triangle, ahead of the traversal: the culling margin, V_L (and lazily the group volumes V_Gk), and the
 * pairing of triangles that share an edge and a plane into one job. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include "accel/ray_triangle.h"
#include "accel/coplanar.h"
#include <math.h>
#include <string.h>

/* A lower bound on the distance between the triangle and the light: the largest gap between their
 * projections on the separating axes of two convex polygons (the box axes, both normals, and the cross
 * products of their edges); a projection never lengthens a distance. 0 when they may touch. */
static double tri_light_gap(const shared *sh, const float v[9])
{
    double T[3][3], L[4][3], ax[14][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) T[i][a] = v[3 * i + a];
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) L[i][a] = sh->light_poly[3 * i + a];
    int n = 0;
    for (int a = 0; a < 3; a++) { ax[n][0] = a == 0; ax[n][1] = a == 1; ax[n][2] = a == 2; n++; }
    double te[3][3], le[2][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) te[i][a] = T[(i + 1) % 3][a] - T[i][a];
    for (int a = 0; a < 3; a++) { le[0][a] = L[1][a] - L[0][a]; le[1][a] = L[3][a] - L[0][a]; }
#define CROSS(r, x, y) (r[0] = x[1] * y[2] - x[2] * y[1], r[1] = x[2] * y[0] - x[0] * y[2], r[2] = x[0] * y[1] - x[1] * y[0])
    CROSS(ax[n], te[0], te[1]); n++;
    CROSS(ax[n], le[0], le[1]); n++;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 2; j++) { CROSS(ax[n], te[i], le[j]); n++; }
#undef CROSS
    double gap = 0.0;
    for (int k = 0; k < n; k++) {
        const double len = sqrt(ax[k][0] * ax[k][0] + ax[k][1] * ax[k][1] + ax[k][2] * ax[k][2]);
        if (!(len > 0.0)) continue;
        double tmin = INFINITY, tmax = -INFINITY, lmin = INFINITY, lmax = -INFINITY;
        for (int i = 0; i < 3; i++) {
            const double d = (T[i][0] * ax[k][0] + T[i][1] * ax[k][1] + T[i][2] * ax[k][2]) / len;
            tmin = fmin(tmin, d); tmax = fmax(tmax, d);
        }
        for (int i = 0; i < 4; i++) {
            const double d = (L[i][0] * ax[k][0] + L[i][1] * ax[k][1] + L[i][2] * ax[k][2]) / len;
            lmin = fmin(lmin, d); lmax = fmax(lmax, d);
        }
        gap = fmax(gap, fmax(lmin - tmax, tmin - lmax));
    }
    return gap;
}

/* The culling margin for a triangle (see the departures above). The exact test rounds the vertices and the
 * sample relative to the receiver, by ulps of their distance to it (at most sh->reach, the farthest
 * distance from the light's box to the receivers' box); a ray from a sample through the triangle passes it
 * at least D from the sample (D: the larger of tri_light_gap and the gap between the bounding boxes, less
 * a relative 1e-6 for their rounding), so an error at
 * the triangle moves the shadow at the receiver by up to reach / D. The samples' own rounding is absorbed
 * by the polygons (setup_light), the plane evaluation's by ulps of the coordinates. 256 ulps of each for
 * safety; a triangle that may touch the light: infinite (no culling). The coordinates (sc, sh->scale) are
 * the scene frame's (scene_frame.c), within 6 half-extents of the geometry at any distance from the
 * world's origin, so the margin and the volumes' planes cull as they do at home. */
static float tri_margin(const shared *sh, const float v[9])
{
    float sc = sh->scale, box2 = 0.0f;
    for (int a = 0; a < 3; a++) {   /* the gap between the bounding boxes, another lower bound */
        const float lo = ms_minf(v[a], ms_minf(v[3 + a], v[6 + a])), hi = ms_maxf(v[a], ms_maxf(v[3 + a], v[6 + a]));
        const float g = ms_maxf(sh->light_lo[a] - hi, lo - sh->light_hi[a]);
        if (g > 0.0f) box2 += g * g;
        sc = ms_maxf(sc, ms_maxf(fabsf(lo), fabsf(hi)));
    }
    const float D = (float)(fmax(tri_light_gap(sh, v), sqrt((double)box2)) - 1e-6 * sc);
    if (!(D > 1e-6f * sc)) return INFINITY;
    return 256.0f * 1.1920929e-07f * (sc + sh->reach * (1.0f + 4.0f * sh->reach / D));
}

void hpc_group_volumes(const shared *sh, chunk *c, const tri_job *t)
{
    for (int g = 0; g < sh->G; g++) hpc_volume_build(&c->gvol[g], sh->group_poly[g], 4, t->v, t->vl.eps);
    c->gvol_built = 1;
    c->cnt[C_GROUP_VOLUMES_BUILT]++;
}

/* The vertex of triangle b (9 floats) that triangle a lacks when they share exactly one edge (two vertices
 * bit for bit) and lie in nearly one plane (normals within about 0.1 degree); else -1. */
static int pair_vertex(const float *a, const float *b)
{
    int shared_v = 0, other = -1;
    for (int i = 0; i < 3; i++) {
        int found = 0;
        for (int j = 0; j < 3; j++) found |= !memcmp(b + 3 * i, a + 3 * j, 3 * sizeof *b);
        if (found) shared_v++;
        else other = i;
    }
    if (shared_v != 2) return -1;
    double na[3], nb[3], e1[3], e2[3];
    for (int x = 0; x < 3; x++) { e1[x] = (double)a[3 + x] - a[x]; e2[x] = (double)a[6 + x] - a[x]; }
    d3_cross(na, e1, e2);
    for (int x = 0; x < 3; x++) { e1[x] = (double)b[3 + x] - b[x]; e2[x] = (double)b[6 + x] - b[x]; }
    d3_cross(nb, e1, e2);
    const double dot = d3_dot(na, nb), la = d3_dot(na, na), lb = d3_dot(nb, nb);
    return la > 0.0 && lb > 0.0 && dot * dot >= (1.0 - 4e-6) * la * lb ? other : -1;
}

/* Departure from the paper: two triangles that share an edge and a plane (a box's face, a mesh's quad) are
 * cast as one job. Each receiver's exact tests stay per triangle (cast_footprint), so the answers are
 * raytrace's; what they share is the traversal, one V_L (of their four points) and the per-receiver work
 * around the samples' tests, which on a GRIDS-like scene (bars of boxes, each face two long thin triangles
 * with nearly the same footprint) is most of a pair's cost. The batch's triangles are reordered so that a
 * triangle's partner, looked for among the next PAIR_WINDOW, follows it (any order gives the same answer).
 * Returns the number of pairs. */
#define PAIR_WINDOW 16
size_t hpc_pair_batch(float *tri, uint32_t *ids, int8_t *pairs, size_t n)
{
    size_t np = 0;
    memset(pairs, 0, n);
    for (size_t i = 0; i + 1 < n; i++) {
        if (pairs[i]) continue;
        for (size_t j = i + 1; j < n && j <= i + PAIR_WINDOW; j++) {
            if (pair_vertex(tri + 9 * i, tri + 9 * j) < 0) continue;
            if (j != i + 1) {   /* move j next to i */
                float tmp[9];
                memcpy(tmp, tri + 9 * (i + 1), sizeof tmp);
                memcpy(tri + 9 * (i + 1), tri + 9 * j, sizeof tmp);
                memcpy(tri + 9 * j, tmp, sizeof tmp);
                const uint32_t id = ids[i + 1];
                ids[i + 1] = ids[j];
                ids[j] = id;
            }
            pairs[i] = 1;
            pairs[i + 1] = -1;
            np++;
            break;
        }
    }
    return np;
}

void hpc_prepare_batch(const shared *sh, tri_job *jobs, const float *tri, const uint32_t *ids, const int8_t *pairs,
                          size_t n)
{
#pragma omp parallel for schedule(static) num_threads(sh->ctx->threads)
    for (size_t i = 0; i < n; i++) {
        tri_job *t = &jobs[i];
        memcpy(t->v, tri + 9 * i, sizeof t->v);
        ms_wt_normal(t->v, t->N);
        t->self = ids[i];
        t->pair = pairs ? pairs[i] : 0;
        t->rect = 0;
        if (t->pair < 0) continue;   /* the pair's vl, made with the first */
        if (t->pair == 0) {
            hpc_volume_build(&t->vl, sh->light_poly, 4, t->v, tri_margin(sh, t->v));
            continue;
        }
        /* The pair's volume: of its four points, with the larger of the two margins (a relation either
         * triangle's exact test calls blocked lies within its margin of that triangle's shadow, which the
         * pair's contains). */
        const float *b = tri + 9 * (i + 1);
        t->rect = ms_coplanar_rect_pair(t->v, b, t->rc);
        float pts[12];
        memcpy(pts, t->v, sizeof t->v);
        memcpy(pts + 9, b + 3 * pair_vertex(t->v, b), 3 * sizeof *pts);
        hpc_volume_build_points(&t->vl, sh->light_poly, 4, pts, 4, ms_maxf(tri_margin(sh, t->v), tri_margin(sh, b)));
        jobs[i + 1].vl = t->vl;
    }
}
