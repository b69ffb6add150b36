/* Alpha-tested occluders (issue 15, item 6): a cut-out leaf texture casts its leaf-shaped shadow in every
 * method. The scene is generated here (into the test's temp dir): a ground plane and three leaf cards (one
 * horizontal, two tilted, one with its UVs repeating the texture twice), textured with a leaf-shaped alpha
 * mask with an off-centre hole, written as a glTF 2.0 file (alphaMode MASK, the texture's alpha channel) and
 * as OBJ/MTL (map_d, a grey mask, OBJ's bottom-up v). The oracle is a brute-force ray tracer written here:
 * its own double-precision segment/triangle test over its own triangle list, its own barycentrics, its own
 * bilinear alpha lookup in the mask it generated. Every method (and ISA, traversal, pattern, Embree mode)
 * must give the oracle's visible mask sample for sample, except samples where the oracle's alpha is within
 * 1e-3 of the cutoff or its segment passes within 1e-6 (barycentric) of a triangle's edge at an opaque texel,
 * which are counted, printed and bounded. Also: the shadow has the leaf's shape (a point below the horizontal
 * card sees the light through exactly the card's transparent fraction; a point below the hole is lit, one
 * below the leaf is not), camera rays pass through transparent texels to the ground (primary methods
 * against the oracle), and whole frames of every method equal raytrace's. */
#include "testutil.h"
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
static double oracle_alpha(double u, double v)
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

#define MAX_TRIS 16
typedef struct otri {
    double v[3][3];
    double uv[3][2];   /* image coordinates: v = 0 at the top row */
    int alpha;         /* 1: a leaf card (alpha-tested), 0: the ground */
} otri;
static otri tris[MAX_TRIS];
static int n_tris;

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
        otri *T = &tris[n_tris++];
        T->alpha = 1;
        for (int k = 0; k < 3; k++) {
            memcpy(T->v[k], p[idx[t][k]], sizeof T->v[k]);
            memcpy(T->uv[k], uv[idx[t][k]], sizeof T->uv[k]);
        }
    }
}

static void make_geometry(void)
{
    n_tris = 0;
    const double g[4][3] = { { -4, 0, -4 }, { 4, 0, -4 }, { 4, 0, 4 }, { -4, 0, 4 } };
    static const int gi[2][3] = { { 0, 2, 1 }, { 0, 3, 2 } };   /* facing up: bake takes the winding's normal */
    for (int t = 0; t < 2; t++) {
        otri *T = &tris[n_tris++];
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
    const int nv = 3 * n_tris;
    float *pos = malloc((size_t)nv * 3 * sizeof *pos), *tc = malloc((size_t)nv * 2 * sizeof *tc);
    assert_non_null(pos);
    assert_non_null(tc);
    float lo[2][3] = { { 1e9f, 1e9f, 1e9f }, { 1e9f, 1e9f, 1e9f } }, hi[2][3] = { { -1e9f, -1e9f, -1e9f }, { -1e9f, -1e9f, -1e9f } };
    for (int t = 0; t < n_tris; t++)
        for (int k = 0; k < 3; k++) {
            const int m = tris[t].alpha;
            for (int i = 0; i < 3; i++) {
                const float x = (float)tris[t].v[k][i];
                pos[(3 * t + k) * 3 + i] = x;
                lo[m][i] = x < lo[m][i] ? x : lo[m][i];
                hi[m][i] = x > hi[m][i] ? x : hi[m][i];
            }
            tc[(3 * t + k) * 2] = (float)tris[t].uv[k][0];
            tc[(3 * t + k) * 2 + 1] = (float)tris[t].uv[k][1];
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
    for (int t = 0; t < n_tris; t++)
        for (int k = 0; k < 3; k++) fprintf(f, "v %.9g %.9g %.9g\n", (float)tris[t].v[k][0], (float)tris[t].v[k][1], (float)tris[t].v[k][2]);
    /* OBJ's v grows upwards: the image's v (0 at the top row) becomes 1 - v. */
    for (int t = 0; t < n_tris; t++)
        for (int k = 0; k < 3; k++) fprintf(f, "vt %.9g %.9g\n", (float)tris[t].uv[k][0], (float)(1.0 - tris[t].uv[k][1]));
    for (int t = 0; t < n_tris; t++) {
        fprintf(f, "usemtl %s\n", tris[t].alpha ? "leaf" : "ground");
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
static void load_scene(const char *format, ms_scene *sc, char *dir_out, size_t dn)
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
    assert_int_equal((int)sc->n_tris, n_tris);
}

/* ---- the oracle ---- */

enum { O_CLEAR = 0, O_OCCLUDED = 1, O_AMBIGUOUS = 2 };

/* Segment (or ray: tmax infinite) o + t d against oracle triangle T, Moller-Trumbore in double: 1 when it meets
 * the triangle with t in [tmin, tmax]; t, b1, b2 of the line's point on the plane whenever the line is not
 * parallel to it; *near_edge when that point lies within eps (barycentric) of an edge with t in range, or
 * inside with t within eps of a limit: a decision the library's float test may take either way. */
static int oracle_hit(const otri *T, const double o[3], const double d[3], double tmin, double tmax, double *t, double *b1,
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
static double card_alpha(const otri *T, double b1, double b2)
{
    const double b0 = 1 - b1 - b2;
    return oracle_alpha(b0 * T->uv[0][0] + b1 * T->uv[1][0] + b2 * T->uv[2][0], b0 * T->uv[0][1] + b1 * T->uv[1][1] + b2 * T->uv[2][1]);
}

/* The segment from P to L, every oracle triangle but `self`: O_OCCLUDED when some triangle clearly occludes it,
 * else O_AMBIGUOUS when some triangle decides it within the tolerances (*why: 1 its alpha within 1e-3 of the
 * cutoff, 2 an edge or range limit where it is opaque), else O_CLEAR. */
static int oracle_segment(const float P[3], const float L[3], int self, int *why)
{
    const double o[3] = { P[0], P[1], P[2] }, d[3] = { (double)L[0] - P[0], (double)L[1] - P[1], (double)L[2] - P[2] };
    int amb = 0;
    for (int i = 0; i < n_tris; i++) {
        if (i == self) continue;
        double t, b1, b2;
        int ne;
        const int hit = oracle_hit(&tris[i], o, d, 1e-4, 1.0 - 1e-4, &t, &b1, &b2, &ne);
        if (!hit && !ne) continue;
        const double a = tris[i].alpha ? card_alpha(&tris[i], b1, b2) : 1.0;
        if (hit && tris[i].alpha && fabs(a - 0.5) < 1e-3) { amb = 1; continue; }
        if (ne) { if (a >= 0.5 - 1e-3 && !amb) amb = 2; continue; }
        if (a >= 0.5) return O_OCCLUDED;
    }
    *why = amb;
    return amb ? O_AMBIGUOUS : O_CLEAR;
}

/* The oracle triangle of library triangle tri (by its centroid). */
static int oracle_index(const float *tri)
{
    double c[3] = { 0, 0, 0 };
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) c[i] += tri[3 * k + i] / 3.0;
    int best = -1;
    double bd = INFINITY;
    for (int t = 0; t < n_tris; t++) {
        double d = 0;
        for (int i = 0; i < 3; i++) {
            const double x = (tris[t].v[0][i] + tris[t].v[1][i] + tris[t].v[2][i]) / 3.0 - c[i];
            d += x * x;
        }
        if (d < bd) { bd = d; best = t; }
    }
    assert_true(bd < 1e-10);
    return best;
}

/* ---- the frame's queries ---- */

typedef struct setup {
    ms_scene sc;
    ms_bvh bvh;
    ms_alpha *alpha;
    ms_render_ctx ctx;
    ms_shadow_query *q;
    int nq;
    int *self;          /* oracle index of each query's triangle */
    int *oracle_tri;    /* per leaf-order prim: oracle index */
    char dir[4096];
} setup;

static void setup_make(setup *s, const char *format, int size)
{
    memset(s, 0, sizeof *s);
    load_scene(format, &s->sc, s->dir, sizeof s->dir);
    assert_int_equal(ms_bvh_build(&s->bvh, s->sc.tri, s->sc.n_tris, 1), 0);
    assert_int_equal(ms_alpha_build(&s->sc, &s->bvh, &s->alpha), 0);
    assert_non_null(s->alpha);
    assert_int_equal((int)s->alpha->n_alpha, n_tris - 2);
    s->oracle_tri = malloc(s->bvh.n_tris * sizeof *s->oracle_tri);
    assert_non_null(s->oracle_tri);
    for (uint32_t i = 0; i < s->bvh.n_tris; i++) {
        s->oracle_tri[i] = oracle_index(s->bvh.tri + 9 * (size_t)i);
        assert_int_equal(s->alpha->flag[i], tris[s->oracle_tri[i]].alpha);
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

static void setup_free(setup *s)
{
    free(s->q);
    free(s->self);
    free(s->oracle_tri);
    ms_alpha_free(s->alpha);
    ms_bvh_free(&s->bvh);
    ms_scene_free(&s->sc);
}

/* The oracle's masks for the context's pattern: occluded and ambiguous bits, over the front samples. */
typedef struct oracle_masks {
    uint64_t *front, *vis, *amb;
    long front_n, amb_alpha, amb_geom, occluded_n;
} oracle_masks;

static void oracle_run(const setup *s, const ms_render_ctx *ctx, oracle_masks *om)
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
            const int r = oracle_segment(s->q[i].p, pts + 3 * j, s->self[i], &why);
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

static void oracle_free(oracle_masks *om)
{
    free(om->front);
    free(om->vis);
    free(om->amb);
}

/* A method's masks on the setup's queries, against the oracle: the number of differing samples outside the
 * ambiguous ones. */
static long method_vs_oracle(const setup *s, const ms_render_ctx *ctx, const char *name, const oracle_masks *om,
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

static void every_method(const char *format)
{
    setup s;
    setup_make(&s, format, 40);
    printf("%s: %d visible points\n", format, s.nq);
    static const ms_pattern pats[] = { MS_PATTERN_GRID, MS_PATTERN_STRATIFIED, MS_PATTERN_INTERLEAVED };
    static const char *const pat_names[] = { "grid", "stratified", "interleaved" };
    long total_differ = 0;
    for (int p = 0; p < 3; p++) {
        ms_render_ctx ctx = s.ctx;
        tu_ctx_set_pattern(&ctx, pats[p]);
        oracle_masks om;
        oracle_run(&s, &ctx, &om);
        printf(" %s, %s: %ld front samples, %ld occluded by the oracle; excluded: %ld with alpha within 1e-3 of the cutoff, "
               "%ld within 1e-6 of an edge\n", format, pat_names[p], om.front_n, om.occluded_n, om.amb_alpha, om.amb_geom);
        /* The scene is built so that cards occlude (a real test) and ties are rare. */
        assert_true(om.occluded_n > om.front_n / 50);
        assert_true(om.amb_alpha + om.amb_geom < om.front_n / 1000 + 10);
        const char *const *names = ms_method_names();
        for (int m = 0; names[m]; m++) {
            const ms_shadow_method *sm = ms_find_shadow_method(names[m]);
            if (sm->needs_grid && pats[p] != MS_PATTERN_GRID) continue;
            if (pats[p] == MS_PATTERN_INTERLEAVED && strcmp(names[m], "raytrace") && strcmp(names[m], "mft") &&
                strcmp(names[m], "embree"))
                continue;
            const int micro = !strcmp(names[m], "scanline") || !strcmp(names[m], "bounds") || !strcmp(names[m], "hierarchical");
            const int embree = !strcmp(names[m], "embree");
            for (int cap = embree ? MS_ISA_AUTO : MS_ISA_SCALAR; cap <= (embree ? MS_ISA_AUTO : MS_ISA_AVX512); cap++) {
                if (cap && (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa())) continue;
                for (int v = 0; v < (micro ? 2 : embree ? 2 : 1); v++) {
                    ms_render_ctx c = ctx;
                    c.isa_cap = (ms_isa)cap;
                    if (micro) c.traversal = v ? MS_TRAVERSAL_PIXEL : MS_TRAVERSAL_BLOCK;
                    if (embree) c.embree_mode = v ? MS_EMBREE_STREAM : MS_EMBREE_PACKET16;
                    char label[128];
                    snprintf(label, sizeof label, "%s %s %s%s", names[m], pat_names[p], cap ? ms_isa_name((ms_isa)cap) : "",
                             micro ? (v ? " pixel" : " block") : embree ? (v ? " stream" : " packet16") : "");
                    total_differ += method_vs_oracle(&s, &c, names[m], &om, label);
                }
            }
        }
        oracle_free(&om);
    }
    assert_int_equal(total_differ, 0);
    setup_free(&s);
}

static void test_every_method_gltf(void **state) { (void)state; every_method("gltf"); }
static void test_every_method_obj(void **state) { (void)state; every_method("obj"); }

/* ---- the shadow's shape, through the points API ---- */

/* The fraction of the card's area where the bilinear alpha is >= 0.5, by a fine midpoint grid. */
static double opaque_fraction(void)
{
    const int n = 1024;
    long in = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) in += oracle_alpha((x + 0.5) / n, (y + 0.5) / n) >= 0.5;
    return (double)in / ((double)n * n);
}

static void leaf_shape(const char *format)
{
    ms_scene sc;
    char dir[4096], err[512];
    load_scene(format, &sc, dir, sizeof dir);
    ms_accel *acc = NULL;
    assert_int_equal(ms_accel_build(&sc, 1, &acc, err, sizeof err), MS_OK);
    /* P below card A's centre: seen from P the 2 x 2 light at height 6 projects onto the card's plane at
     * height 3 as exactly the card (scale 3/6 about P), so V = the card's transparent fraction. */
    const double opaque = opaque_fraction();
    /* Below the hole (card uv (0.62, 0.42): world (0.12, 3, -0.08)) and below the leaf body (uv (0.3, 0.55):
     * (-0.2, 3, 0.05)) with a 0.04-wide light centred over the card: the segments cross the card's plane
     * within 0.01 of the points twice as far below... i.e. P = 2 X - light centre. */
    const float pos[9] = { 0, 0, 0, 0.24f, 0, -0.16f, -0.4f, 0, 0.1f };
    const float nrm[9] = { 0, 1, 0, 0, 1, 0, 0, 1, 0 };
    ms_points pts = { 3, pos, nrm, NULL, NULL };
    ms_light small = sc.light;
    small.corner = (ms_vec3){ -0.02f, 6, -0.02f };
    small.edge_s = (ms_vec3){ 0.04f, 0, 0 };
    small.edge_t = (ms_vec3){ 0, 0, 0.04f };
    const char *const *names = ms_method_names();
    for (int m = 0; names[m]; m++) {
        if (!strcmp(names[m], "hpc") || !strcmp(names[m], "hpc-scanline")) continue;   /* frames only */
        ms_points_options po = { 0 };
        po.method = names[m];
        po.samples = 1024;
        po.threads = 1;
        po.isa = tu_isa_cap();
        float v[3], v2[3];
        ms_status rc = ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err);
        if (rc) fprintf(stderr, "%s: %s\n", names[m], err);
        assert_int_equal(rc, MS_OK);
        rc = ms_visibility_points(acc, &small, &pts, &po, v2, NULL, NULL, NULL, err, sizeof err);
        assert_int_equal(rc, MS_OK);
        printf("%s %-13s below card A: V %.4f, the card's transparent fraction %.4f; small light: below the hole V %.3f, "
               "below the leaf V %.3f\n", format, names[m], v[0], 1.0 - opaque, v2[1], v2[2]);
        /* 1024 samples on the card: the edge of the leaf crosses about 2 * 32 * perimeter cells. */
        assert_true(fabs(v[0] - (1.0 - opaque)) < 0.02);
        assert_true(v2[1] == 1.0f);
        assert_true(v2[2] == 0.0f);
    }
    assert_true(opaque > 0.25 && opaque < 0.5);
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

static void test_leaf_shape_gltf(void **state) { (void)state; leaf_shape("gltf"); }
static void test_leaf_shape_obj(void **state) { (void)state; leaf_shape("obj"); }

/* ---- primary rays: through transparent texels to what lies behind ---- */

static void primary(const char *format, const char *pname)
{
    const int size = 48;
    setup s;
    setup_make(&s, format, 8);
    const ms_primary_method *pm = ms_find_primary_method(pname);
    if (!pm) { setup_free(&s); return; }
    ms_render_ctx ctx = s.ctx;
    assert_int_equal(ms_camera_basis_init(&ctx.cam, &s.sc.camera, size, size), 0);
    char err[256];
    void *ps = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    assert_non_null(hits);
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    long through = 0, differ = 0, amb = 0, on_cards = 0;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            float of[3], df[3];
            assert_int_equal(ms_camera_ray(&ctx.cam, x, y, of, df), 0);
            const double o[3] = { of[0], of[1], of[2] }, d[3] = { df[0], df[1], df[2] };
            /* The oracle: the nearest triangle hit where opaque; ambiguous if a hit nearer than it is near the
             * cutoff or an edge. */
            int best = -1, ambiguous = 0, crossed = 0;
            double bt = INFINITY;
            for (int t = 0; t < n_tris; t++) {
                double tt, b1, b2;
                int ne;
                const int hit = oracle_hit(&tris[t], o, d, 0.0, INFINITY, &tt, &b1, &b2, &ne);
                const double a = tris[t].alpha ? card_alpha(&tris[t], b1, b2) : 1.0;
                if (ne && a >= 0.5 - 1e-3) ambiguous = 1;
                if (!hit) continue;
                if (tris[t].alpha && fabs(a - 0.5) < 1e-3) ambiguous = 1;
                if (a < 0.5) { crossed = 1; continue; }
                if (tt < bt) { bt = tt; best = t; }
            }
            const ms_hit *h = &hits[y * size + x];
            const int got = h->prim == UINT32_MAX ? -1 : s.oracle_tri[h->prim];
            if (ambiguous) { amb++; continue; }
            if (got != best) differ++;
            through += crossed && best >= 0 && !tris[best].alpha;
            on_cards += best >= 0 && tris[best].alpha;
        }
    printf("%s primary %s: %ld pixels see the ground through a transparent texel, %ld see a card; %ld differ from the "
           "oracle, %ld ambiguous\n", format, pname, through, on_cards, differ, amb);
    assert_true(through > 20);
    assert_true(on_cards > 20);
    assert_int_equal(differ, 0);
    assert_true(amb < 10);
    free(hits);
    setup_free(&s);
}

static void test_primary_gltf(void **state)
{
    (void)state;
    primary("gltf", "bvh");
    primary("gltf", "embree");
}
static void test_primary_obj(void **state)
{
    (void)state;
    primary("obj", "bvh");
    primary("obj", "embree");
}

/* ---- whole frames: every method's V and S equal raytrace's ---- */

static void test_frames_equal_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096];
    load_scene("gltf", &sc, dir, sizeof dir);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 1024;
    o.width = o.height = 32;
    o.threads = 1;
    ms_frame ref;
    char err[512];
    assert_int_equal(ms_render(&sc, &o, &ref, err, sizeof err), 0);
    const char *const *names = ms_method_names();
    for (int m = 0; names[m]; m++) {
        ms_frame f;
        o.method = names[m];
        const int rc = ms_render(&sc, &o, &f, err, sizeof err);
        if (rc) fprintf(stderr, "%s: %s\n", names[m], err);
        assert_int_equal(rc, 0);
        const tu_agreement a = tu_compare_frames(&f, &ref);
        printf("frame %-13s vs raytrace: %ld of %ld pixels differ in V, %ld in S only\n", names[m], a.differ, a.pixels,
               a.s_differ_same_v);
        assert_int_equal(a.miss_mismatch, 0);
        /* The leaf samples near the cutoff are ties between methods only where the alpha function's inputs
         * differ, and they do not: every method hands it the same floats. */
        assert_int_equal(a.differ, 0);
        assert_int_equal(a.s_differ_same_v, 0);
        ms_frame_free(&f);
    }
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* The 3D-rasterization primaries and bvh --consistent (issue 14) look through the cut-outs as the bvh primary
 * does: the same V and S bit for bit among themselves, and no pixel hit by one and missed by the watertight
 * bvh primary (which would mean a hole seen differently). */
static void test_primaries_through_cutouts(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], err[512];
    load_scene("gltf", &sc, dir, sizeof dir);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 256;
    o.width = o.height = 40;
    o.threads = 1;
    ms_frame wt, ref;
    assert_int_equal(ms_render(&sc, &o, &wt, err, sizeof err), 0);
    o.primary = "bvh";
    o.consistent_primary = 1;
    assert_int_equal(ms_render(&sc, &o, &ref, err, sizeof err), 0);
    o.consistent_primary = 0;
    const tu_agreement w = tu_compare_frames(&ref, &wt);
    printf("bvh --consistent vs bvh through cut-outs: %ld of %ld pixels differ in V, %ld hit by one only\n", w.differ,
           w.pixels, w.miss_mismatch);
    assert_int_equal(w.miss_mismatch, 0);
    static const char *const names[] = { "3dr-bb", "3dr-bin", "3dr-fc", "3dr-fs", "3dr-full" };
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        ms_frame f;
        o.primary = names[i];
        assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
        assert_memory_equal(f.vis, ref.vis, (size_t)40 * 40 * sizeof(float));
        assert_memory_equal(f.shadow, ref.shadow, (size_t)40 * 40 * sizeof(float));
        ms_frame_free(&f);
    }
    ms_frame_free(&ref);
    ms_frame_free(&wt);
    ms_scene_free(&sc);
}

/* Without the alpha table (what an opaque material gives) the cards occlude as whole quads: the alpha test only
 * ever gives samples back, and it does give many. */
static void test_opaque_cards_are_quads(void **state)
{
    (void)state;
    setup s;
    setup_make(&s, "gltf", 24);
    /* The same BVH without the alpha table: every card a full quad. */
    ms_render_ctx ctx = s.ctx;
    ctx.alpha = NULL;
    const ms_shadow_method *sm = ms_find_shadow_method("scanline");
    const size_t mw = (size_t)ctx.mask_words, n = (size_t)s.nq * mw;
    uint64_t *front = calloc(n + 1, 8), *va = calloc(n + 1, 8), *vo = calloc(n + 1, 8), cnt[MS_MAX_COUNTERS] = { 0 };
    assert_non_null(front);
    assert_non_null(va);
    assert_non_null(vo);
    for (int i = 0; i < s.nq; i++) ms_front_mask(&ctx, &s.q[i], NULL, front + i * mw);
    char err[256];
    void *st = NULL;
    assert_int_equal(sm->create(&s.ctx, &st, err, sizeof err), 0);
    assert_int_equal(sm->visibility(st, &s.ctx, s.q, s.nq, front, va, cnt), 0);
    sm->destroy(st);
    assert_int_equal(sm->create(&ctx, &st, err, sizeof err), 0);
    assert_int_equal(sm->visibility(st, &ctx, s.q, s.nq, front, vo, cnt), 0);
    sm->destroy(st);
    long more = 0, fewer = 0;
    for (size_t w = 0; w < n; w++) {
        more += __builtin_popcountll(va[w] & ~vo[w]);
        fewer += __builtin_popcountll(vo[w] & ~va[w]);
    }
    printf("alpha-tested vs opaque cards: %ld samples lit only through the cut-outs, %ld lit only when opaque\n", more, fewer);
    assert_true(more > 1000);
    assert_int_equal(fewer, 0);
    free(front);
    free(va);
    free(vo);
    setup_free(&s);
}

/* Baking goes through the points API, so it honours alpha: the same lightmap with the cards alpha-tested and
 * opaque has every texel at least as visible (the alpha test only gives samples back, on the same samples)
 * and many texels more. */
static void test_bake_honours_alpha(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], err[512];
    load_scene("gltf", &sc, dir, sizeof dir);
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 64;
    bo.uv_set = -1;   /* xatlas for every triangle: the cards' own UVs overlap (and repeat) */
    bo.points.threads = 1;
    bo.points.isa = tu_isa_cap();
    ms_lightmap a, o;
    ms_status rc = ms_bake(&sc, NULL, &bo, &a, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, MS_OK);
    sc.materials[0].alpha_mode = MS_ALPHA_OPAQUE;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &o, err, sizeof err), MS_OK);
    long more = 0, less = 0, texels = 0;
    for (int i = 0; i < 64 * 64; i++) {
        if (a.triangle[i] == MS_NO_TRIANGLE) continue;
        texels++;
        more += a.frame.vis[i] > o.frame.vis[i];
        less += a.frame.vis[i] < o.frame.vis[i];
    }
    printf("bake: %ld texels on triangles, %ld more visible with alpha-tested cards, %ld less\n", texels, more, less);
    assert_true(more > texels / 50);
    assert_int_equal(less, 0);
    ms_lightmap_free(&a);
    ms_lightmap_free(&o);
    ms_scene_free(&sc);
}

/* Loading: BLEND is tested as MASK at 0.5 with one warning; `d` without map_d stays opaque; a bad alpha mode or
 * cutoff from a library caller is refused by validation. */
static int n_warnings;
static char last_warning[512];
static void on_warning(void *user, const char *msg)
{
    (void)user;
    n_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

static void test_loading_rules(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], path[4096], err[512];
    load_scene("gltf", &sc, dir, sizeof dir);
    ms_scene_free(&sc);
    /* The same glTF with BLEND instead of MASK (and a cutoff BLEND ignores). */
    FILE *f = fopen(tu_path(path, sizeof path, dir, "leaves.gltf"), "r");
    assert_non_null(f);
    static char text[16384];
    const size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    char *m = strstr(text, "\"alphaMode\":\"MASK\",\"alphaCutoff\":0.5");
    assert_non_null(m);
    memcpy(m, "\"alphaMode\":\"BLEND\",\"alphaCutoff\":0.9", strlen("\"alphaMode\":\"BLEND\",\"alphaCutoff\":0.9"));
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.gltf"), text), 0);
    n_warnings = 0;
    ms_set_warning_handler(on_warning, NULL);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_set_warning_handler(NULL, NULL);
    printf("BLEND: %d warning(s): %s\n", n_warnings, last_warning);
    assert_int_equal(n_warnings, 1);
    assert_non_null(strstr(last_warning, "BLEND"));
    assert_int_equal((int)sc.n_materials, 1);
    assert_int_equal(sc.materials[0].alpha_mode, MS_ALPHA_MASK);
    assert_true(sc.materials[0].alpha_cutoff == 0.5f);
    /* A library caller's bad alpha fields. */
    sc.materials[0].alpha_cutoff = 1.5f;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    printf("refused: %s\n", err);
    sc.materials[0].alpha_cutoff = 0.5f;
    sc.materials[0].alpha_mode = 7;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    sc.materials[0].alpha_mode = MS_ALPHA_MASK_MAP;
    sc.materials[0].alpha_texture = 99;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    ms_scene_free(&sc);
    /* OBJ: d 0.3 without map_d is opaque; with map_d the map decides. */
    load_scene("obj", &sc, dir, sizeof dir);
    ms_scene_free(&sc);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.mtl"),
                                   "newmtl ground\nKd 0.8 0.8 0.8\n\nnewmtl leaf\nKd 0.2 0.6 0.2\nd 0.3\nmap_Kd leaf.png\n"), 0);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    for (size_t i = 0; i < sc.n_materials; i++) assert_int_equal(sc.materials[i].alpha_mode, MS_ALPHA_OPAQUE);
    ms_scene_free(&sc);
    /* A map_d that cannot be read: one warning, opaque. */
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.mtl"),
                                   "newmtl leaf\nmap_d missing.png\n"), 0);
    n_warnings = 0;
    ms_set_warning_handler(on_warning, NULL);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_set_warning_handler(NULL, NULL);
    printf("missing map_d: %d warning(s): %s\n", n_warnings, last_warning);
    assert_int_equal(n_warnings, 1);
    for (size_t i = 0; i < sc.n_materials; i++) assert_int_equal(sc.materials[i].alpha_mode, MS_ALPHA_OPAQUE);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_method_gltf),
        cmocka_unit_test(test_every_method_obj),
        cmocka_unit_test(test_leaf_shape_gltf),
        cmocka_unit_test(test_leaf_shape_obj),
        cmocka_unit_test(test_primary_gltf),
        cmocka_unit_test(test_primary_obj),
        cmocka_unit_test(test_frames_equal_raytrace),
        cmocka_unit_test(test_primaries_through_cutouts),
        cmocka_unit_test(test_opaque_cards_are_quads),
        cmocka_unit_test(test_loading_rules),
        cmocka_unit_test(test_bake_honours_alpha),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
