/* Smooth irradiance on smooth surfaces: the bake's cosine takes the interpolated shading normal (as frames
 * shade), its visibility the triangle's plane. A unit icosphere (1280 faces, about 9 degrees between
 * neighbours) under a rect light, baked once with vertex normals (OBJ vn = the vertex's direction from the
 * centre) and once without:
 *   - every texel whose point lies inside its triangle equals an oracle of the test's own: its own barycentric
 *     interpolation of the vertex directions (not the scene's normals) for ms_light_irradiance, times S from
 *     ms_visibility_points at the texel's point with the triangle as receiver and the texel as key; and the
 *     face-normal oracle is far from it (so the comparison can tell them apart);
 *   - on the shared edges between charts (UV seams), the texels whose points lie on the edge (edge texels are
 *     carried to the nearest point of their triangle: on the edge) from one side agree with the other side's,
 *     linearly interpolated along the edge, within 0.3% of the largest irradiance with vertex normals, where
 *     the faceted bake of the same sphere differs by several percent. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 256
#define SAMPLES 256

static const char *k_light = "\"light\":{\"corner\":[-1.5,2.5,-0.5],\"edge_s\":[2,0,0],\"edge_t\":[0,0.6,1.6],\"emission\":[1,1,1]}";

/* The icosphere as an OBJ (with vn lines when normals), its scene file at json. */
static void write_sphere(const char *dir, const char *name, int normals, char *json, size_t n)
{
    double *v;
    int *t;
    size_t nv, nt;
    tu_unit_icosphere(3, &v, &nv, &t, &nt);
    size_t cap = 64 * (nv * 2 + nt) + 64, len = 0;
    char *obj = malloc(cap);
    assert_non_null(obj);
    for (size_t i = 0; i < nv; i++) len += (size_t)snprintf(obj + len, cap - len, "v %.9g %.9g %.9g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    for (size_t i = 0; normals && i < nv; i++)
        len += (size_t)snprintf(obj + len, cap - len, "vn %.9g %.9g %.9g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    for (size_t i = 0; i < nt; i++) {
        const int a = t[3 * i] + 1, b = t[3 * i + 1] + 1, c = t[3 * i + 2] + 1;
        if (normals) len += (size_t)snprintf(obj + len, cap - len, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
        else len += (size_t)snprintf(obj + len, cap - len, "f %d %d %d\n", a, b, c);
    }
    char p[1024], file[256], text[2048];
    snprintf(file, sizeof file, "%s.obj", name);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, file), obj), 0);
    snprintf(text, sizeof text, "{\"meshes\":[{\"file\":\"%s\"}],\"camera\":{\"eye\":[0,1,4],\"target\":[0,0,0],\"up\":[0,1,0],"
             "\"fov_y\":45,\"width\":64,\"height\":64},%s}", file, k_light);
    snprintf(file, sizeof file, "%s.json", name);
    assert_int_equal(tu_write_file(tu_path(json, n, dir, file), text), 0);
    free(obj);
    free(v);
    free(t);
}

static void bake(const ms_scene *sc, ms_lightmap *lm)
{
    ms_bake_options bo;
    tu_bake_options(&bo, SIZE, -1, SAMPLES);
    /* the baked texels themselves: the seam stitch moves those its lookups read (test_bake_seams checks it) */
    bo.no_seam_stitch = 1;
    char err[512] = "";
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

static double largest(const ms_lightmap *lm)
{
    double m = 0.0;
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++)
        if (lm->triangle[i] != MS_NO_TRIANGLE) m = fmax(m, lm->frame.rgb[3 * i]);
    return m;
}

/* Barycentrics of p in the triangle t (9 doubles), by areas in the triangle's plane. */
static void bary(const double *t, const double p[3], double w[3])
{
    double e1[3], e2[3], d[3], n[3];
    for (int k = 0; k < 3; k++) { e1[k] = t[3 + k] - t[k]; e2[k] = t[6 + k] - t[k]; d[k] = p[k] - t[k]; }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    double c1[3], c2[3];
    c1[0] = d[1] * e2[2] - d[2] * e2[1]; c1[1] = d[2] * e2[0] - d[0] * e2[2]; c1[2] = d[0] * e2[1] - d[1] * e2[0];
    c2[0] = e1[1] * d[2] - e1[2] * d[1]; c2[1] = e1[2] * d[0] - e1[0] * d[2]; c2[2] = e1[0] * d[1] - e1[1] * d[0];
    w[1] = (c1[0] * n[0] + c1[1] * n[1] + c1[2] * n[2]) / nn;
    w[2] = (c2[0] * n[0] + c2[1] * n[1] + c2[2] * n[2]) / nn;
    w[0] = 1.0 - w[1] - w[2];
}

/* The bake against the oracle at the texels inside their triangles: worst |dE| / E_max with the interpolated
 * vertex directions (*smooth) and with the face normal (*faceted). */
static void against_oracle(const ms_scene *sc, const ms_lightmap *lm, double *smooth, double *faceted)
{
    const size_t nt = (size_t)SIZE * SIZE;
    size_t m = 0;
    for (size_t i = 0; i < nt; i++) m += lm->triangle[i] != MS_NO_TRIANGLE;
    float *pos = malloc(m * 3 * sizeof *pos), *nor = malloc(m * 3 * sizeof *nor), *S = malloc(m * sizeof *S);
    uint32_t *tri = malloc(m * sizeof *tri), *key = malloc(m * 2 * sizeof *key);
    size_t *where = malloc(m * sizeof *where);
    assert_true(pos && nor && S && tri && key && where);
    size_t j = 0;
    for (size_t i = 0; i < nt; i++) {
        if (lm->triangle[i] == MS_NO_TRIANGLE) continue;
        memcpy(pos + 3 * j, lm->position + 3 * i, 3 * sizeof(float));
        memcpy(nor + 3 * j, lm->normal + 3 * i, 3 * sizeof(float));
        tri[j] = lm->triangle[i];
        key[2 * j] = (uint32_t)(i % SIZE);
        key[2 * j + 1] = (uint32_t)(i / SIZE);
        where[j++] = i;
    }
    ms_accel *acc;
    char err[512] = "";
    assert_int_equal(ms_accel_build(sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = { m, pos, nor, tri, key };
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = SAMPLES;
    po.isa = tu_isa_cap();
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, NULL, S, NULL, NULL, err, sizeof err), MS_OK);
    const double emax = largest(lm);
    assert_true(emax > 0.0);
    double worst_s = 0.0, worst_f = 0.0;
    size_t inside = 0;
    for (size_t k = 0; k < m; k++) {
        const size_t i = where[k];
        double t[9], p[3], w[3];
        for (int c = 0; c < 9; c++) t[c] = (double)sc->tri[9 * (size_t)tri[k] + c] + sc->origin[c % 3];
        for (int c = 0; c < 3; c++) p[c] = (double)pos[3 * k + c] + sc->origin[c];
        bary(t, p, w);
        if (w[0] < 1e-6 || w[1] < 1e-6 || w[2] < 1e-6) continue;   /* edge texels: their points were moved */
        inside++;
        float ns[3] = { 0, 0, 0 };
        for (int v = 0; v < 3; v++) {   /* the sphere's vertex normal is the vertex's direction from the centre */
            const double len = sqrt(t[3 * v] * t[3 * v] + t[3 * v + 1] * t[3 * v + 1] + t[3 * v + 2] * t[3 * v + 2]);
            for (int c = 0; c < 3; c++) ns[c] += (float)(w[v] * t[3 * v + c] / len);
        }
        const float l = sqrtf(ns[0] * ns[0] + ns[1] * ns[1] + ns[2] * ns[2]);
        for (int c = 0; c < 3; c++) ns[c] /= l;
        const double es = (double)ms_light_irradiance(&sc->light, pos + 3 * k, ns) * S[k];
        const double ef = (double)ms_light_irradiance(&sc->light, pos + 3 * k, nor + 3 * k) * S[k];
        worst_s = fmax(worst_s, fabs(lm->frame.rgb[3 * i] - es) / emax);
        worst_f = fmax(worst_f, fabs(lm->frame.rgb[3 * i] - ef) / emax);
    }
    printf("oracle: %zu texels inside their triangles of %zu, worst |dE|/E_max %.2e with interpolated normals, %.4f "
           "with face normals\n", inside, m, worst_s, worst_f);
    assert_true(inside > m / 2);
    *smooth = worst_s;
    *faceted = worst_f;
    ms_accel_free(acc);
    free(pos); free(nor); free(S); free(tri); free(key); free(where);
}

/* One texel on a shared edge: the edge, its parameter along it (from the lower vertex key), its irradiance,
 * the side (the edge's first or second triangle). */
typedef struct edge_sample { size_t edge; double s, e; int side; } edge_sample;

static int cmp_sample(const void *pa, const void *pb)
{
    const edge_sample *a = pa, *b = pb;
    if (a->edge != b->edge) return a->edge < b->edge ? -1 : 1;
    if (a->side != b->side) return a->side - b->side;
    return (a->s > b->s) - (a->s < b->s);
}

static int same3(const float *a, const float *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

/* Across UV seams on the sphere: mean and worst difference |E_a(s) - E_b(s)| / E_max between one side's edge
 * texels and the other side's interpolated at the same points of the edge; *n the points compared. */
static void seam_agreement(const ms_scene *sc, const ms_lightmap *lm, double *mean, double *worst, size_t *n)
{
    const size_t T = sc->n_tris;
    /* edges shared by two triangles (by positions; the icosphere's are exact copies): (t, k) -> neighbour */
    long *nb = malloc(T * 3 * sizeof *nb);
    assert_non_null(nb);
    for (size_t i = 0; i < 3 * T; i++) nb[i] = -1;
    for (size_t a = 0; a < T; a++)
        for (int ka = 0; ka < 3; ka++) {
            const float *p0 = sc->tri + 9 * a + 3 * ka, *p1 = sc->tri + 9 * a + 3 * ((ka + 1) % 3);
            for (size_t b = a + 1; b < T && nb[3 * a + ka] < 0; b++)
                for (int kb = 0; kb < 3; kb++) {
                    const float *q0 = sc->tri + 9 * b + 3 * kb, *q1 = sc->tri + 9 * b + 3 * ((kb + 1) % 3);
                    if (same3(p0, q1) && same3(p1, q0)) { nb[3 * a + ka] = (long)(3 * b + kb); nb[3 * b + kb] = (long)(3 * a + ka); }
                }
        }
    const size_t nt = (size_t)SIZE * SIZE;
    edge_sample *smp = malloc(nt * sizeof *smp);
    assert_non_null(smp);
    size_t ns = 0;
    for (size_t i = 0; i < nt; i++) {
        const uint32_t t = lm->triangle[i];
        if (t == MS_NO_TRIANGLE) continue;
        const float *p = lm->position + 3 * i;
        for (int k = 0; k < 3; k++) {
            const long o = nb[3 * t + k];
            if (o < 0) continue;
            const size_t self = 3 * (size_t)t + (size_t)k, edge = self < (size_t)o ? self : (size_t)o;
            /* the edge from its key's first vertex: (t, k) runs k -> k+1, the neighbour the other way */
            const float *a = sc->tri + 9 * (edge / 3) + 3 * (edge % 3), *b = sc->tri + 9 * (edge / 3) + 3 * ((edge % 3 + 1) % 3);
            double d[3], q[3], dd = 0, s = 0;
            for (int c = 0; c < 3; c++) { d[c] = (double)b[c] - a[c]; dd += d[c] * d[c]; s += ((double)p[c] - a[c]) * d[c]; }
            s /= dd;
            double dist = 0;
            for (int c = 0; c < 3; c++) { q[c] = a[c] + s * d[c] - p[c]; dist += q[c] * q[c]; }
            if (sqrt(dist) > 1e-5 * sqrt(dd) || s < 0.02 || s > 0.98) continue;
            smp[ns].edge = edge;
            smp[ns].s = s;
            smp[ns].e = lm->frame.rgb[3 * i];
            smp[ns++].side = self != edge;
        }
    }
    qsort(smp, ns, sizeof *smp, cmp_sample);
    const double emax = largest(lm);
    double sum = 0.0, mx = 0.0;
    size_t cnt = 0;
    for (size_t a = 0; a < ns;) {
        size_t b = a;
        while (b < ns && smp[b].edge == smp[a].edge && smp[b].side == 0) b++;
        size_t c = b;
        while (c < ns && smp[c].edge == smp[a].edge) c++;
        /* side 0 at a..b, side 1 at b..c: each side-0 point against side 1 interpolated where it brackets it */
        for (size_t i = a; i < b; i++)
            for (size_t j = b; j + 1 < c; j++) {
                if (!(smp[j].s <= smp[i].s && smp[i].s <= smp[j + 1].s) || smp[j + 1].s - smp[j].s <= 0.0) continue;
                const double f = (smp[i].s - smp[j].s) / (smp[j + 1].s - smp[j].s);
                const double eb = smp[j].e + f * (smp[j + 1].e - smp[j].e);
                const double diff = fabs(smp[i].e - eb) / emax;
                sum += diff;
                mx = fmax(mx, diff);
                cnt++;
                break;
            }
        a = c > a ? c : a + 1;
    }
    *mean = cnt ? sum / (double)cnt : 0.0;
    *worst = mx;
    *n = cnt;
    free(smp);
    free(nb);
}

static void test_smooth_sphere(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_smooth");
    char json[1024], err[512] = "";
    write_sphere(dir, "smooth", 1, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_non_null(sc.tri_normal);
    ms_lightmap lm;
    bake(&sc, &lm);
    double smooth, faceted;
    against_oracle(&sc, &lm, &smooth, &faceted);
    assert_true(smooth <= 1e-5);       /* float rounding: the same formula at the same points */
    assert_true(faceted >= 0.01);      /* the face normal's cosine is not what was baked */
    double mean_s, worst_s, mean_f, worst_f;
    size_t n_s, n_f;
    seam_agreement(&sc, &lm, &mean_s, &worst_s, &n_s);

    char json_f[1024];
    write_sphere(dir, "faceted", 0, json_f, sizeof json_f);
    ms_scene scf;
    assert_int_equal(ms_scene_load(json_f, &scf, err, sizeof err), 0);
    ms_lightmap lmf;
    bake(&scf, &lmf);
    seam_agreement(&scf, &lmf, &mean_f, &worst_f, &n_f);
    printf("seam edges, texels on the edge against the other side interpolated: vertex normals %zu points, mean %.5f, "
           "worst %.5f of E_max; face normals %zu points, mean %.5f, worst %.5f\n", n_s, mean_s, worst_s, n_f, mean_f, worst_f);
    assert_true(n_s >= 100 && n_f >= 100);
    assert_true(worst_s <= 0.003);
    assert_true(worst_f >= 0.02);
    assert_true(mean_f >= 10.0 * mean_s);
    ms_lightmap_free(&lmf);
    ms_scene_free(&scf);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_smooth_sphere),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
