/* The leaf-card scene of the alpha-tested occluders' tests (test_alpha.c, test_alpha_frames.c) and its oracle:
 * a leaf-shaped alpha mask with an off-centre hole, written as PNG by a minimal writer here; a ground and three
 * leaf cards written as glTF 2.0 and as OBJ/MTL; a brute-force double-precision ray tracer over its own triangle
 * list with its own bilinear alpha lookup; the frame's queries and every method's masks against the oracle. */
#include "alpha_leaves.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/bvh.h"
#include "light/pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the texture: a leaf (an ellipse) with a round hole off its centre, on a transparent border ---- */

#define TW 64
#define TH 48
static uint8_t mask_tex[TH][TW];   /* 255 opaque, 0 transparent; row 0 at v = 0 (the top of the image) */

static void make_mask(void)
{
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++) {
            const double u = (x + 0.5) / TW, v = (y + 0.5) / TH;
            const double eu = (u - 0.5) / 0.42, ev = (v - 0.5) / 0.32;
            const double hu = u - 0.62, hv = v - 0.42;
            const int leaf = eu * eu + ev * ev < 1.0, hole = hu * hu + hv * hv < 0.09 * 0.09;
            mask_tex[y][x] = leaf && !hole ? 255 : 0;
        }
}

/* The oracle's alpha: bilinear with repeat, texel centres at (i + 0.5) / size; (u, v) with v = 0 at the top. */
double al_oracle_alpha(double u, double v)
{
    const double x = u * TW - 0.5, y = v * TH - 0.5;
    const double x0 = floor(x), y0 = floor(y), fx = x - x0, fy = y - y0;
    int xi = (int)fmod(x0, TW), yi = (int)fmod(y0, TH);
    if (xi < 0) xi += TW;
    if (yi < 0) yi += TH;
    const int xj = (xi + 1) % TW, yj = (yi + 1) % TH;
    return ((1 - fx) * (1 - fy) * mask_tex[yi][xi] + fx * (1 - fy) * mask_tex[yi][xj] + (1 - fx) * fy * mask_tex[yj][xi] +
            fx * fy * mask_tex[yj][xj]) / 255.0;
}

/* ---- a minimal PNG writer (stored deflate blocks), so that the test needs no image library ---- */

static uint32_t crc_table[256];
static void crc_init(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}
static uint32_t crc(const uint8_t *b, size_t n, uint32_t c)
{
    c = ~c;
    for (size_t i = 0; i < n; i++) c = crc_table[(c ^ b[i]) & 0xFF] ^ (c >> 8);
    return ~c;
}
static void be32(uint8_t *p, uint32_t v) { p[0] = (uint8_t)(v >> 24); p[1] = (uint8_t)(v >> 16); p[2] = (uint8_t)(v >> 8); p[3] = (uint8_t)v; }
static void chunk(FILE *f, const char *type, const uint8_t *data, uint32_t n)
{
    uint8_t h[8];
    be32(h, n);
    memcpy(h + 4, type, 4);
    fwrite(h, 1, 8, f);
    if (n) fwrite(data, 1, n, f);
    uint32_t c = crc((const uint8_t *)type, 4, 0);
    c = crc(data, n, c);
    be32(h, c);
    fwrite(h, 1, 4, f);
}

/* channels 4: RGBA (green leaf, alpha = mask); 1: grey = mask. */
static void write_png(const char *path, int channels)
{
    const size_t row = 1 + (size_t)TW * channels, raw_n = row * TH;
    uint8_t *raw = malloc(raw_n);
    assert_non_null(raw);
    for (int y = 0; y < TH; y++) {
        uint8_t *r = raw + row * y;
        r[0] = 0;
        for (int x = 0; x < TW; x++) {
            uint8_t *p = r + 1 + (size_t)x * channels;
            if (channels == 4) { p[0] = 40; p[1] = 160; p[2] = 50; p[3] = mask_tex[y][x]; }
            else p[0] = mask_tex[y][x];
        }
    }
    const size_t nblocks = (raw_n + 65534) / 65535, z_n = 2 + raw_n + 5 * nblocks + 4;
    uint8_t *z = malloc(z_n), *o = z;
    assert_non_null(z);
    *o++ = 0x78; *o++ = 0x01;
    uint32_t s1 = 1, s2 = 0;
    for (size_t i = 0; i < raw_n; i++) { s1 = (s1 + raw[i]) % 65521; s2 = (s2 + s1) % 65521; }
    for (size_t b = 0; b < nblocks; b++) {
        const size_t off = b * 65535, len = raw_n - off < 65535 ? raw_n - off : 65535;
        *o++ = b + 1 == nblocks;
        *o++ = (uint8_t)len; *o++ = (uint8_t)(len >> 8); *o++ = (uint8_t)~len; *o++ = (uint8_t)(~len >> 8);
        memcpy(o, raw + off, len);
        o += len;
    }
    be32(o, (s2 << 16) | s1);
    o += 4;
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    static const uint8_t sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    fwrite(sig, 1, 8, f);
    uint8_t ihdr[13];
    be32(ihdr, TW);
    be32(ihdr + 4, TH);
    ihdr[8] = 8;
    ihdr[9] = channels == 4 ? 6 : 0;
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    chunk(f, "IHDR", ihdr, 13);
    chunk(f, "IDAT", z, (uint32_t)(o - z));
    chunk(f, "IEND", NULL, 0);
    assert_int_equal(fclose(f), 0);
    free(raw);
    free(z);
}

/* ---- the geometry, as the oracle knows it ---- */

otri al_tris[MAX_TRIS];
int al_n_tris;

/* A card: centre c, unit axes a (u grows along it) and b (v grows along it), half sizes ha, hb; the UVs span
 * [0, rep]^2. Two triangles sharing the diagonal. */
static void add_card(const double c[3], const double a[3], const double b[3], double ha, double hb, double rep)
{
    double p[4][3];
    const double su[4] = { -1, 1, 1, -1 }, sv[4] = { -1, -1, 1, 1 };
    const double uv[4][2] = { { 0, 0 }, { rep, 0 }, { rep, rep }, { 0, rep } };
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < 3; i++) p[k][i] = c[i] + su[k] * ha * a[i] + sv[k] * hb * b[i];
    static const int idx[2][3] = { { 0, 2, 1 }, { 0, 3, 2 } };   /* wound to face +b x a (up for the flat cards) */
    for (int t = 0; t < 2; t++) {
        otri *T = &al_tris[al_n_tris++];
        T->alpha = 1;
        for (int k = 0; k < 3; k++) {
            memcpy(T->v[k], p[idx[t][k]], sizeof T->v[k]);
            memcpy(T->uv[k], uv[idx[t][k]], sizeof T->uv[k]);
        }
    }
}

static void make_geometry(void)
{
    al_n_tris = 0;
    const double g[4][3] = { { -4, 0, -4 }, { 4, 0, -4 }, { 4, 0, 4 }, { -4, 0, 4 } };
    static const int gi[2][3] = { { 0, 2, 1 }, { 0, 3, 2 } };   /* facing up: bake takes the winding's normal */
    for (int t = 0; t < 2; t++) {
        otri *T = &al_tris[al_n_tris++];
        memset(T, 0, sizeof *T);
        for (int k = 0; k < 3; k++) memcpy(T->v[k], g[gi[t][k]], sizeof T->v[k]);
    }
    /* A: horizontal at y = 3, 1 x 1, u along +x, v along +z (the leaf-fraction and hole tests use it). */
    const double ca[3] = { 0, 3, 0 }, ax[3] = { 1, 0, 0 }, az[3] = { 0, 0, 1 };
    add_card(ca, ax, az, 0.5, 0.5, 1.0);
    /* B: tilted 35 degrees about x. */
    const double cb[3] = { 1.3, 2.0, 0.7 }, bb[3] = { 0, sin(0.61), cos(0.61) };
    add_card(cb, ax, bb, 0.45, 0.4, 1.0);
    /* C: steep (60 degrees), the texture repeated twice each way. */
    const double cc[3] = { -1.4, 1.6, -0.6 }, bc[3] = { 0, sin(1.05), cos(1.05) }, ac[3] = { cos(0.3), 0, -sin(0.3) };
    add_card(cc, ac, bc, 0.7, 0.6, 2.0);
}

/* ---- the scene files ---- */

static void write_gltf(const char *dir)
{
    char path[4096];
    /* Buffer: per triangle three vertices (position, texcoord), no sharing; ground first (mesh 0). */
    const int nv = 3 * al_n_tris;
    float *pos = malloc((size_t)nv * 3 * sizeof *pos), *tc = malloc((size_t)nv * 2 * sizeof *tc);
    assert_non_null(pos);
    assert_non_null(tc);
    float lo[2][3] = { { 1e9f, 1e9f, 1e9f }, { 1e9f, 1e9f, 1e9f } }, hi[2][3] = { { -1e9f, -1e9f, -1e9f }, { -1e9f, -1e9f, -1e9f } };
    for (int t = 0; t < al_n_tris; t++)
        for (int k = 0; k < 3; k++) {
            const int m = al_tris[t].alpha;
            for (int i = 0; i < 3; i++) {
                const float x = (float)al_tris[t].v[k][i];
                pos[(3 * t + k) * 3 + i] = x;
                lo[m][i] = x < lo[m][i] ? x : lo[m][i];
                hi[m][i] = x > hi[m][i] ? x : hi[m][i];
            }
            tc[(3 * t + k) * 2] = (float)al_tris[t].uv[k][0];
            tc[(3 * t + k) * 2 + 1] = (float)al_tris[t].uv[k][1];
        }
    FILE *f = fopen(tu_path(path, sizeof path, dir, "leaves.bin"), "wb");
    assert_non_null(f);
    fwrite(pos, sizeof *pos, (size_t)nv * 3, f);
    fwrite(tc, sizeof *tc, (size_t)nv * 2, f);
    assert_int_equal(fclose(f), 0);
    const size_t pos_bytes = (size_t)nv * 12, tc_bytes = (size_t)nv * 8, ground_v = 6, leaf_v = (size_t)nv - 6;
    char json[8192];
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":1}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]},"
             "{\"primitives\":[{\"attributes\":{\"POSITION\":1,\"TEXCOORD_0\":2},\"material\":0}]}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0,"
             "\"roughnessFactor\":0.8},\"alphaMode\":\"MASK\",\"alphaCutoff\":0.5,\"doubleSided\":true}],"
             "\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":[{\"wrapS\":10497,\"wrapT\":10497}],"
             "\"images\":[{\"uri\":\"leaf.png\"}],"
             "\"buffers\":[{\"uri\":\"leaves.bin\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\","
             "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\","
             "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
             "{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"}]}",
             pos_bytes + tc_bytes, ground_v * 12, ground_v * 12, leaf_v * 12, pos_bytes + ground_v * 8, leaf_v * 8,
             ground_v, lo[0][0], lo[0][1], lo[0][2], hi[0][0], hi[0][1], hi[0][2], leaf_v, lo[1][0], lo[1][1], lo[1][2],
             hi[1][0], hi[1][1], hi[1][2], leaf_v);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.gltf"), json), 0);
    free(pos);
    free(tc);
}

static void write_obj(const char *dir)
{
    char path[4096];
    FILE *f = fopen(tu_path(path, sizeof path, dir, "leaves.obj"), "w");
    assert_non_null(f);
    fprintf(f, "mtllib leaves.mtl\n");
    for (int t = 0; t < al_n_tris; t++)
        for (int k = 0; k < 3; k++) fprintf(f, "v %.9g %.9g %.9g\n", (float)al_tris[t].v[k][0], (float)al_tris[t].v[k][1], (float)al_tris[t].v[k][2]);
    /* OBJ's v grows upwards: the image's v (0 at the top row) becomes 1 - v. */
    for (int t = 0; t < al_n_tris; t++)
        for (int k = 0; k < 3; k++) fprintf(f, "vt %.9g %.9g\n", (float)al_tris[t].uv[k][0], (float)(1.0 - al_tris[t].uv[k][1]));
    for (int t = 0; t < al_n_tris; t++) {
        fprintf(f, "usemtl %s\n", al_tris[t].alpha ? "leaf" : "ground");
        fprintf(f, "f %d/%d %d/%d %d/%d\n", 3 * t + 1, 3 * t + 1, 3 * t + 2, 3 * t + 2, 3 * t + 3, 3 * t + 3);
    }
    assert_int_equal(fclose(f), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.mtl"),
                                   "newmtl ground\nKd 0.8 0.8 0.8\n\n"
                                   "newmtl leaf\nKd 0.2 0.6 0.2\nd 1\nmap_Kd leaf.png\nmap_d leaf_mask.png\n"), 0);
}

static void write_scene(const char *dir, const char *mesh, const char *name)
{
    char path[4096], json[2048];
    snprintf(json, sizeof json,
             "{\"meshes\":[{\"file\":\"%s\"}],"
             "\"camera\":{\"eye\":[0.3,8,5.5],\"target\":[0,1.2,0],\"up\":[0,1,0],\"fov_y\":40,\"width\":40,\"height\":40},"
             "\"light\":{\"corner\":[-1,6,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[1,1,1]}}",
             mesh);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, name), json), 0);
}

/* The scene of one format, written and loaded. */
void al_load_scene(const char *format, ms_scene *sc, char *dir_out, size_t dn)
{
    crc_init();
    make_mask();
    make_geometry();
    char tmp[64];
    snprintf(tmp, sizeof tmp, "test_alpha_%s", format);
    const char *dir = tu_tmpdir(tmp);
    snprintf(dir_out, dn, "%s", dir);
    char path[4096], err[512];
    write_png(tu_path(path, sizeof path, dir, "leaf.png"), 4);
    write_png(tu_path(path, sizeof path, dir, "leaf_mask.png"), 1);
    if (!strcmp(format, "gltf")) { write_gltf(dir); write_scene(dir, "leaves.gltf", "scene.json"); }
    else { write_obj(dir); write_scene(dir, "leaves.obj", "scene.json"); }
    const int rc = ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), sc, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal((int)sc->n_tris, al_n_tris);
}

/* ---- the oracle ---- */


/* Segment (or ray: tmax infinite) o + t d against oracle triangle T, Moller-Trumbore in double: 1 when it meets
 * the triangle with t in [tmin, tmax]; t, b1, b2 of the line's point on the plane whenever the line is not
 * parallel to it; *near_edge when that point lies within eps (barycentric) of an edge with t in range, or
 * inside with t within eps of a limit: a decision the library's float test may take either way. */
int al_oracle_hit(const otri *T, const double o[3], const double d[3], double tmin, double tmax, double *t, double *b1,
                  double *b2, int *near_edge)
{
    double e1[3], e2[3], p[3], s[3], q[3];
    for (int i = 0; i < 3; i++) { e1[i] = T->v[1][i] - T->v[0][i]; e2[i] = T->v[2][i] - T->v[0][i]; s[i] = o[i] - T->v[0][i]; }
    p[0] = d[1] * e2[2] - d[2] * e2[1]; p[1] = d[2] * e2[0] - d[0] * e2[2]; p[2] = d[0] * e2[1] - d[1] * e2[0];
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    *near_edge = 0;
    *t = *b1 = *b2 = 0.0;   /* defined when the line is parallel to the plane */
    if (fabs(det) < 1e-300) return 0;
    q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det, v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    const double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det, w = 1.0 - u - v;
    const double eps = 1e-6;
    *t = tt; *b1 = u; *b2 = v;
    const int in_range = tt >= tmin - eps && tt <= tmax + eps, inside = u >= -eps && v >= -eps && w >= -eps;
    *near_edge = (in_range && inside && (fabs(u) < eps || fabs(v) < eps || fabs(w) < eps)) ||
                 (inside && (fabs(tt - tmin) < eps || (isfinite(tmax) && fabs(tt - tmax) < eps)));
    return u >= 0 && v >= 0 && w >= 0 && tt >= tmin && tt <= tmax;
}

/* alpha of card T at barycentrics (b1, b2). */
double al_card_alpha(const otri *T, double b1, double b2)
{
    const double b0 = 1 - b1 - b2;
    return al_oracle_alpha(b0 * T->uv[0][0] + b1 * T->uv[1][0] + b2 * T->uv[2][0], b0 * T->uv[0][1] + b1 * T->uv[1][1] + b2 * T->uv[2][1]);
}

/* The segment from P to L, every oracle triangle but `self`: O_OCCLUDED when some triangle clearly occludes it,
 * else O_AMBIGUOUS when some triangle decides it within the tolerances (*why: 1 its alpha within 1e-3 of the
 * cutoff, 2 an edge or range limit where it is opaque), else O_CLEAR. */
int al_oracle_segment(const float P[3], const float L[3], int self, int *why)
{
    const double o[3] = { P[0], P[1], P[2] }, d[3] = { (double)L[0] - P[0], (double)L[1] - P[1], (double)L[2] - P[2] };
    int amb = 0;
    for (int i = 0; i < al_n_tris; i++) {
        if (i == self) continue;
        double t, b1, b2;
        int ne;
        const int hit = al_oracle_hit(&al_tris[i], o, d, 1e-4, 1.0 - 1e-4, &t, &b1, &b2, &ne);
        if (!hit && !ne) continue;
        const double a = al_tris[i].alpha ? al_card_alpha(&al_tris[i], b1, b2) : 1.0;
        if (hit && al_tris[i].alpha && fabs(a - 0.5) < 1e-3) { amb = 1; continue; }
        if (ne) { if (a >= 0.5 - 1e-3 && !amb) amb = 2; continue; }
        if (a >= 0.5) return O_OCCLUDED;
    }
    *why = amb;
    return amb ? O_AMBIGUOUS : O_CLEAR;
}

/* The oracle triangle of library triangle tri (by its centroid). */
int al_oracle_index(const float *tri)
{
    double c[3] = { 0, 0, 0 };
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) c[i] += tri[3 * k + i] / 3.0;
    int best = -1;
    double bd = INFINITY;
    for (int t = 0; t < al_n_tris; t++) {
        double d = 0;
        for (int i = 0; i < 3; i++) {
            const double x = (al_tris[t].v[0][i] + al_tris[t].v[1][i] + al_tris[t].v[2][i]) / 3.0 - c[i];
            d += x * x;
        }
        if (d < bd) { bd = d; best = t; }
    }
    assert_true(bd < 1e-10);
    return best;
}

/* ---- the frame's queries ---- */


void al_setup_make(setup *s, const char *format, int size)
{
    memset(s, 0, sizeof *s);
    al_load_scene(format, &s->sc, s->dir, sizeof s->dir);
    assert_int_equal(ms_bvh_build(&s->bvh, s->sc.tri, s->sc.n_tris, 1), 0);
    assert_int_equal(ms_alpha_build(&s->sc, &s->bvh, &s->alpha), 0);
    assert_non_null(s->alpha);
    assert_int_equal((int)s->alpha->n_alpha, al_n_tris - 2);
    s->oracle_tri = malloc(s->bvh.n_tris * sizeof *s->oracle_tri);
    assert_non_null(s->oracle_tri);
    for (uint32_t i = 0; i < s->bvh.n_tris; i++) {
        s->oracle_tri[i] = al_oracle_index(s->bvh.tri + 9 * (size_t)i);
        assert_int_equal(s->alpha->flag[i], al_tris[s->oracle_tri[i]].alpha);
    }
    tu_ctx_init(&s->ctx, &s->sc, &s->bvh, size, size, 32);
    s->ctx.alpha = s->alpha;
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    char err[256];
    void *ps = NULL;
    assert_int_equal(pm->create(&s->ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    s->q = malloc((size_t)size * size * sizeof *s->q);
    s->self = malloc((size_t)size * size * sizeof *s->self);
    assert_non_null(hits);
    assert_non_null(s->q);
    assert_non_null(s->self);
    pm->trace(ps, &s->ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    for (int i = 0; i < size * size; i++)
        if (hits[i].prim != UINT32_MAX) {
            s->self[s->nq] = s->oracle_tri[hits[i].prim];
            tu_query_from_hit(&s->q[s->nq++], &hits[i], i % size, i / size);
        }
    free(hits);
}

void al_setup_free(setup *s)
{
    free(s->q);
    free(s->self);
    free(s->oracle_tri);
    ms_alpha_free(s->alpha);
    ms_bvh_free(&s->bvh);
    ms_scene_free(&s->sc);
}


void al_oracle_run(const setup *s, const ms_render_ctx *ctx, oracle_masks *om)
{
    const size_t mw = (size_t)ctx->mask_words, n = (size_t)s->nq * mw;
    om->front = calloc(n + 1, sizeof *om->front);
    om->vis = calloc(n + 1, sizeof *om->vis);
    om->amb = calloc(n + 1, sizeof *om->amb);
    assert_non_null(om->front);
    assert_non_null(om->vis);
    assert_non_null(om->amb);
    om->front_n = om->amb_alpha = om->amb_geom = om->occluded_n = 0;
    float *pts = malloc((size_t)ctx->samples * 3 * sizeof *pts);
    assert_non_null(pts);
    for (int i = 0; i < s->nq; i++) {
        ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, s->q[i].px, s->q[i].py, ctx->seed, pts);
        uint64_t *fm = om->front + i * mw;
        ms_front_mask(ctx, &s->q[i], ctx->pattern == MS_PATTERN_GRID ? NULL : pts, fm);
        for (int j = 0; j < ctx->samples; j++) {
            if (!(fm[j >> 6] >> (j & 63) & 1)) continue;
            om->front_n++;
            int why = 0;
            const int r = al_oracle_segment(s->q[i].p, pts + 3 * j, s->self[i], &why);
            if (r == O_CLEAR) om->vis[i * mw + (j >> 6)] |= UINT64_C(1) << (j & 63);
            else if (r == O_OCCLUDED) om->occluded_n++;
            else {
                om->amb[i * mw + (j >> 6)] |= UINT64_C(1) << (j & 63);
                if (why == 1) om->amb_alpha++;
                else om->amb_geom++;
            }
        }
    }
    free(pts);
}

void al_oracle_free(oracle_masks *om)
{
    free(om->front);
    free(om->vis);
    free(om->amb);
}

/* A method's masks on the setup's queries, against the oracle: the number of differing samples outside the
 * ambiguous ones. */
long al_method_vs_oracle(const setup *s, const ms_render_ctx *ctx, const char *name, const oracle_masks *om,
                         const char *label)
{
    const ms_shadow_method *sm = ms_find_shadow_method(name);
    assert_non_null(sm);
    const size_t mw = (size_t)ctx->mask_words, n = (size_t)s->nq * mw;
    uint64_t *vis = calloc(n + 1, sizeof *vis), cnt[MS_MAX_COUNTERS] = { 0 };
    assert_non_null(vis);
    char err[256];
    void *st = NULL;
    const int rc = sm->create(ctx, &st, err, sizeof err);
    if (rc) fprintf(stderr, "%s: %s\n", name, err);
    assert_int_equal(rc, 0);
    if (sm->visibility_all) assert_int_equal(sm->visibility_all(st, ctx, s->q, (size_t)s->nq, om->front, vis, cnt), 0);
    else assert_int_equal(sm->visibility(st, ctx, s->q, s->nq, om->front, vis, cnt), 0);
    sm->destroy(st);
    long differ = 0, not_front = 0, occl = 0;
    for (size_t w = 0; w < n; w++) {
        differ += __builtin_popcountll((vis[w] ^ om->vis[w]) & ~om->amb[w]);
        not_front += __builtin_popcountll(vis[w] & ~om->front[w]);
        occl += __builtin_popcountll(om->front[w] & ~vis[w] & ~om->amb[w]);
    }
    printf("  %-34s %ld samples differ from the oracle (of %ld front; the method occludes %ld)\n", label, differ, om->front_n, occl);
    assert_int_equal(not_front, 0);
    free(vis);
    return differ;
}
