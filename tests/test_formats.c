/* Mesh formats (#30 items 1 and 5, #32 item 1): a corpus generated here from known vertex and polygon
 * arrays, written in every legal variant of OBJ, PLY, OFF and STL, each loaded through ms_scene_load and
 * compared with what the arrays say (triangle count: n - 2 per polygon, strips counted here; bounding box
 * of the vertices the faces use); malformed variants through the CLI (exit 2, one line naming the file);
 * per-mesh transforms against hand-computed boxes, the matrix form against the equivalent TRS, mirrors
 * keeping outward winding, a file listed twice read once, bad transforms refused. */
#include "testutil.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char g_dir[4096];

static const char *in(const char *name)
{
    static char p[8][4096];
    static int k;
    k = (k + 1) % 8;
    return tu_path(p[k], sizeof p[k], g_dir, name);
}

/* ---------------------------------------------------------------- the known geometry */

/* 12 vertices: coordinates exact in binary (multiples of 1/8), so every format stores them exactly. */
static const double V[12][3] = {
    { -1.5, 0, -2 }, { 2.25, 0, -2 }, { 2.25, 0.5, 1.75 }, { -1.5, 0.5, 1.75 },   /* a quad */
    { 0, 1, 0 }, { 1, 1, 0 }, { 1.5, 1.5, 0 }, { 1, 2, 0 }, { 0, 2, 0 }, { -0.5, 1.5, 0 },   /* a hexagon */
    { 3, -0.75, 4.5 }, { -2.5, 3.125, -3 },   /* a triangle with 4 (0, 1) and the far corners */
};
/* Polygons: a quad, a hexagon, two triangles, a pentagon (convex, in the hexagon's plane). */
static const int F[][7] = { { 4, 0, 1, 2, 3 }, { 6, 4, 5, 6, 7, 8, 9 }, { 3, 10, 4, 0 }, { 3, 11, 1, 5 },
                            { 5, 4, 5, 6, 7, 8 } };
#define NF ((int)(sizeof F / sizeof F[0]))

static int expected_tris(void)
{
    int n = 0;
    for (int f = 0; f < NF; f++) n += F[f][0] - 2;
    return n;
}

static void expected_box(double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++) { lo[c] = INFINITY; hi[c] = -INFINITY; }
    for (int f = 0; f < NF; f++)
        for (int k = 1; k <= F[f][0]; k++)
            for (int c = 0; c < 3; c++) {
                lo[c] = fmin(lo[c], V[F[f][k]][c]);
                hi[c] = fmax(hi[c], V[F[f][k]][c]);
            }
}

/* ---------------------------------------------------------------- loading */

static const char *scene_for(const char *name, const char *meshes_json)
{
    char text[8192];
    snprintf(text, sizeof text,
             "{ \"meshes\": [ %s ],\n"
             "  \"camera\": { \"eye\": [0, 10, 12], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60,"
             " \"width\": 16, \"height\": 16 },\n"
             "  \"light\": { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2] } }\n", meshes_json);
    const char *p = in(name);
    assert_int_equal(tu_write_file(p, text), 0);
    return p;
}

static void load(const char *mesh, const char *transform, ms_scene *sc)
{
    char m[1024], js[512];
    snprintf(m, sizeof m, "{ \"file\": \"%s\"%s%s }", mesh, transform ? ", \"transform\": " : "", transform ? transform : "");
    snprintf(js, sizeof js, "%s.json", mesh);
    char err[1024];
    memset(sc, 0, sizeof *sc);
    if (ms_scene_load(scene_for(js, m), sc, err, sizeof err)) fail_msg("%s: %s", mesh, err);
}

static void box_of(const ms_scene *sc, double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++) { lo[c] = INFINITY; hi[c] = -INFINITY; }
    for (size_t i = 0; i < 3 * sc->n_tris; i++)
        for (int c = 0; c < 3; c++) {   /* in the world: the scene's frame may have moved it (world = local + origin) */
            lo[c] = fmin(lo[c], sc->tri[3 * i + c] + sc->origin[c]);
            hi[c] = fmax(hi[c], sc->tri[3 * i + c] + sc->origin[c]);
        }
}

static void expect_box(const char *what, const ms_scene *sc, const double lo[3], const double hi[3], double tol)
{
    double l[3], h[3];
    box_of(sc, l, h);
    for (int c = 0; c < 3; c++)
        if (fabs(l[c] - lo[c]) > tol || fabs(h[c] - hi[c]) > tol)
            fail_msg("%s: box (%g %g %g)-(%g %g %g), want (%g %g %g)-(%g %g %g)", what, l[0], l[1], l[2], h[0], h[1],
                     h[2], lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
}

/* The known geometry's count and box. */
static void expect_known(const char *mesh)
{
    ms_scene sc;
    load(mesh, NULL, &sc);
    if (sc.n_tris != (size_t)expected_tris()) fail_msg("%s: %zu triangles, want %d", mesh, sc.n_tris, expected_tris());
    double lo[3], hi[3];
    expected_box(lo, hi);
    expect_box(mesh, &sc, lo, hi, 0.0);
    print_message("%s: %zu triangles, box as written\n", mesh, sc.n_tris);
    ms_scene_free(&sc);
}

/* ---------------------------------------------------------------- OBJ */

static void test_obj_variants(void **st)
{
    (void)st;
    char t[16384];
    size_t n = 0;
    /* Plain. */
    n = 0;
    for (int i = 0; i < 12; i++) n += (size_t)snprintf(t + n, sizeof t - n, "v %g %g %g\n", V[i][0], V[i][1], V[i][2]);
    for (int f = 0; f < NF; f++) {
        n += (size_t)snprintf(t + n, sizeof t - n, "f");
        for (int k = 1; k <= F[f][0]; k++) n += (size_t)snprintf(t + n, sizeof t - n, " %d", F[f][k] + 1);
        n += (size_t)snprintf(t + n, sizeof t - n, "\n");
    }
    tu_write_file(in("plain.obj"), t);
    expect_known("plain.obj");

    /* T-Rex style (3ds Max): groups with texture coordinates and groups without, so faces mix v/vt/vn and
     * v//vn in one file; plus v/vt and bare v, negative indices, o/g/s lines, comments anywhere, a
     * continued line, CRLF ends, a 4-number (w) vertex, 6-number (colour) vertices, 3-number vt. */
    n = 0;
    n += (size_t)snprintf(t + n, sizeof t - n, "# 3ds Max Wavefront OBJ Exporter\r\n# File Created: today\r\n\r\n");
    for (int i = 0; i < 12; i++) {
        if (i == 3) n += (size_t)snprintf(t + n, sizeof t - n, "v %g %g %g 2\r\n", 2 * V[i][0], 2 * V[i][1], 2 * V[i][2]);
        else if (i == 7) n += (size_t)snprintf(t + n, sizeof t - n, "v %g \\\r\n  %g %g   # continued\r\n", V[i][0], V[i][1], V[i][2]);
        else if (i % 4 == 1) n += (size_t)snprintf(t + n, sizeof t - n, "v  %g %g %g 0.5 0.25 1\r\n", V[i][0], V[i][1], V[i][2]);
        else n += (size_t)snprintf(t + n, sizeof t - n, "v %g\t%g %g\r\n", V[i][0], V[i][1], V[i][2]);
    }
    n += (size_t)snprintf(t + n, sizeof t - n, "# %d vertices\r\nvt 0 0 0\r\nvt 1 0 0\r\nvt 1 1 0\r\nvt 0 1\r\n"
                                             "vn 0 1 0\r\nvn 0 0 1\r\n\r\no trex\r\ng Body\r\ns 1\r\nusemtl Material #25\r\n", 12);
    /* quad: v/vt/vn, absolute indices */
    n += (size_t)snprintf(t + n, sizeof t - n, "f 1/1/1 2/2/1 3/3/1 4/4/1 # the quad\r\n");
    /* hexagon: v//vn, negative indices (12 vertices, 2 normals so far) */
    n += (size_t)snprintf(t + n, sizeof t - n, "g Teeth\r\ns off\r\nf -8//-1 -7//-1 -6//-1 \\\r\n -5//-1 -4//-1 -3//-1\r\n");
    /* triangles: v/vt and bare v */
    n += (size_t)snprintf(t + n, sizeof t - n, "g Claws\r\nf 11/1 5/2 1/3\r\n\r\nf 12 2 6\r\n");
    /* pentagon: mixed within a face */
    n += (size_t)snprintf(t + n, sizeof t - n, "g\r\nf 5/1/2 6//2 7/3 8 9/4/1\r\nl 1 2\r\np 3\r\n# end\r\n");
    tu_write_file(in("trex.obj"), t);
    expect_known("trex.obj");

    /* A face naming a vertex defined after it (positive index), and free-form geometry skipped. */
    tu_write_file(in("forward.obj"), "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3\nend\n");
    ms_scene sc;
    load("forward.obj", NULL, &sc);
    assert_int_equal(sc.n_tris, 1);
    ms_scene_free(&sc);
}

/* ---------------------------------------------------------------- PLY */

typedef enum { I8, U8, I16, U16, I32, U32, F32, F64 } ptype;
static const char *const pname[] = { "char", "uchar", "short", "ushort", "int", "uint", "float", "double" };
static const int psize[] = { 1, 1, 2, 2, 4, 4, 4, 8 };

typedef struct wbuf { unsigned char *b; size_t n, cap; int fmt; } wbuf;   /* fmt 0 ascii, 1 LE, 2 BE */

static void put(wbuf *w, const void *p, size_t n)
{
    if (w->n + n > w->cap) { w->cap = 2 * (w->n + n) + 1024; w->b = realloc(w->b, w->cap); assert_non_null(w->b); }
    memcpy(w->b + w->n, p, n);
    w->n += n;
}
static void puts_(wbuf *w, const char *s) { put(w, s, strlen(s)); }

static void val(wbuf *w, ptype t, double v, int last)
{
    if (w->fmt == 0) {
        char s[64];
        snprintf(s, sizeof s, t >= F32 ? "%.17g%s" : "%.0f%s", v, last ? "\n" : " ");
        puts_(w, s);
        return;
    }
    unsigned char b[8] = { 0 };
    switch (t) {
    case I8: { int8_t x = (int8_t)v; memcpy(b, &x, 1); break; }
    case U8: { uint8_t x = (uint8_t)v; memcpy(b, &x, 1); break; }
    case I16: { int16_t x = (int16_t)v; memcpy(b, &x, 2); break; }
    case U16: { uint16_t x = (uint16_t)v; memcpy(b, &x, 2); break; }
    case I32: { int32_t x = (int32_t)v; memcpy(b, &x, 4); break; }
    case U32: { uint32_t x = (uint32_t)v; memcpy(b, &x, 4); break; }
    case F32: { float x = (float)v; memcpy(b, &x, 4); break; }
    case F64: { memcpy(b, &v, 8); break; }
    }
    if (w->fmt == 2)
        for (int i = 0; i < psize[t] / 2; i++) { unsigned char c = b[i]; b[i] = b[psize[t] - 1 - i]; b[psize[t] - 1 - i] = c; }
    put(w, b, (size_t)psize[t]);
}

static void write_buf(const char *name, const wbuf *w)
{
    FILE *f = fopen(in(name), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(w->b, 1, w->n, f), w->n);
    fclose(f);
}

/* The known geometry as PLY: coordinate type ct, list count type lt, index type it, with extra
 * properties and elements around it; faces (strips = 0) or, for strips = 1, the triangles only. */
static void write_ply(const char *name, int fmt, ptype ct, ptype lt, ptype it)
{
    static const char *const fmts[] = { "ascii", "binary_little_endian", "binary_big_endian" };
    wbuf w = { NULL, 0, 0, fmt };
    char h[2048];
    snprintf(h, sizeof h,
             "ply\nformat %s 1.0\ncomment made by test_formats\nobj_info anything\n"
             "element material 2\nproperty uchar ambient_red\nproperty float shininess\n"
             "element vertex 12\nproperty %s x\nproperty uchar red\nproperty %s y\nproperty %s z\nproperty list uchar int extra\n"
             "element face %d\nproperty uchar flags\nproperty list %s %s vertex_indices\nproperty int material_index\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n",
             fmts[fmt], pname[ct], pname[ct], pname[ct], NF, pname[lt], pname[it]);
    puts_(&w, h);
    for (int m = 0; m < 2; m++) { val(&w, U8, 7, 0); val(&w, F32, 0.5, 1); }
    for (int i = 0; i < 12; i++) {
        val(&w, ct, V[i][0], 0); val(&w, U8, 200, 0); val(&w, ct, V[i][1], 0); val(&w, ct, V[i][2], 0);
        val(&w, U8, 2, 0); val(&w, I32, -1, 0); val(&w, I32, 5, 1);
    }
    for (int f = 0; f < NF; f++) {
        val(&w, U8, 1, 0);
        val(&w, lt, F[f][0], 0);
        for (int k = 1; k <= F[f][0]; k++) val(&w, it, F[f][k], 0);
        val(&w, I32, 0, 1);
    }
    val(&w, I32, 0, 0); val(&w, I32, 1, 1);
    write_buf(name, &w);
    free(w.b);
}

static void test_ply_variants(void **st)
{
    (void)st;
    static const struct { const char *name; int fmt; ptype ct, lt, it; } v[] = {
        { "a.ply", 0, F32, U8, I32 }, { "le.ply", 1, F32, U8, I32 }, { "be.ply", 2, F32, U8, I32 },
        { "le_double_ushort_uint.ply", 1, F64, U16, U32 }, { "be_double_int_short.ply", 2, F64, I32, I16 },
        { "le_uint_count_uchar_idx.ply", 1, F32, U32, U8 }, { "a_double_char_ushort.ply", 0, F64, I8, U16 },
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        write_ply(v[i].name, v[i].fmt, v[i].ct, v[i].lt, v[i].it);
        expect_known(v[i].name);
    }
    /* Integer coordinates (short, int, uchar): the vertices scaled by 8 into integers. */
    static const ptype it[] = { I16, I32 };
    for (int k = 0; k < 2; k++) {
        wbuf w = { NULL, 0, 0, 1 };
        char h[512];
        snprintf(h, sizeof h, "ply\nformat binary_little_endian 1.0\nelement vertex 12\nproperty %s x\nproperty %s y\n"
                 "property %s z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n",
                 pname[it[k]], pname[it[k]], pname[it[k]], NF);
        puts_(&w, h);
        for (int i = 0; i < 12; i++)
            for (int c = 0; c < 3; c++) val(&w, it[k], 8 * V[i][c], 0);
        for (int f = 0; f < NF; f++) {
            val(&w, U8, F[f][0], 0);
            for (int q = 1; q <= F[f][0]; q++) val(&w, I32, F[f][q], 0);
        }
        char name[32];
        snprintf(name, sizeof name, "int%d.ply", k);
        write_buf(name, &w);
        free(w.b);
        ms_scene sc;
        load(name, NULL, &sc);
        assert_int_equal(sc.n_tris, expected_tris());
        double lo[3], hi[3];
        expected_box(lo, hi);
        for (int c = 0; c < 3; c++) { lo[c] *= 8; hi[c] *= 8; }
        expect_box(name, &sc, lo, hi, 0.0);
        ms_scene_free(&sc);
    }
}

/* Strips as scanned PLY files carry them: one list per element instance, -1 restarts. */
static void test_ply_tristrips(void **st)
{
    (void)st;
    /* A 5 x 3 grid of vertices, two strips along its rows, then a strip of one degenerate stitch. */
    double g[15][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 5; c++) { g[5 * r + c][0] = c; g[5 * r + c][1] = 0.25 * r * c; g[5 * r + c][2] = r; }
    const int strip[] = { 0, 5, 1, 6, 2, 7, 3, 8, 4, 9, -1, 5, 10, 6, 11, 7, 12, 8, 13, 9, 14, -1, 0, 1, 1, 2 };
    const int ns = (int)(sizeof strip / sizeof strip[0]);
    /* Oracle: triangles of each run, minus those with a repeated vertex. */
    int want = 0, run = 0;
    for (int k = 0; k < ns; k++) {
        if (strip[k] < 0) { run = 0; continue; }
        if (++run >= 3 && strip[k] != strip[k - 1] && strip[k] != strip[k - 2] && strip[k - 1] != strip[k - 2]) want++;
    }
    for (int fmt = 0; fmt < 3; fmt++) {
        static const char *const fmts[] = { "ascii", "binary_little_endian", "binary_big_endian" };
        wbuf w = { NULL, 0, 0, fmt };
        char h[512];
        snprintf(h, sizeof h, "ply\nformat %s 1.0\nelement vertex 15\nproperty float x\nproperty float y\n"
                 "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n", fmts[fmt]);
        puts_(&w, h);
        for (int i = 0; i < 15; i++)
            for (int c = 0; c < 3; c++) val(&w, F32, g[i][c], c == 2);
        val(&w, I32, ns, 0);
        for (int k = 0; k < ns; k++) val(&w, I32, strip[k], k == ns - 1);
        char name[32];
        snprintf(name, sizeof name, "strips%d.ply", fmt);
        write_buf(name, &w);
        free(w.b);
        ms_scene sc;
        load(name, NULL, &sc);
        if (sc.n_tris != (size_t)want) fail_msg("%s: %zu triangles, want %d", name, sc.n_tris, want);
        const double lo[3] = { 0, 0, 0 }, hi[3] = { 4, 2, 2 };
        expect_box(name, &sc, lo, hi, 0.0);
        /* Alternating winding: every triangle of the grid faces the same way (+y side of the grid's
         * z-x plane: the normal's y component has one sign). */
        int up = 0, down = 0;
        for (size_t t = 0; t < sc.n_tris; t++) {
            const float *p = sc.tri + 9 * t;
            const float e1[3] = { p[3] - p[0], p[4] - p[1], p[5] - p[2] }, e2[3] = { p[6] - p[0], p[7] - p[1], p[8] - p[2] };
            const float ny = e1[2] * e2[0] - e1[0] * e2[2];
            up += ny > 0;
            down += ny < 0;
        }
        if (up && down) fail_msg("%s: strip winding not alternated (%d up, %d down)", name, up, down);
        print_message("%s: %zu triangles from strips\n", name, sc.n_tris);
        ms_scene_free(&sc);
    }
}

/* ---------------------------------------------------------------- OFF */

static void write_off(const char *name, const char *keyword, int hom, int nrm, int col, int st, int ndim, int counts_on_keyword_line)
{
    char t[16384];
    size_t n = 0;
    if (keyword) n += (size_t)snprintf(t + n, sizeof t - n, "%s%s", keyword, counts_on_keyword_line ? " " : "\n# a comment\n");
    if (ndim) n += (size_t)snprintf(t + n, sizeof t - n, "3 ");
    n += (size_t)snprintf(t + n, sizeof t - n, "12 %d 0\n\n", NF);
    for (int i = 0; i < 12; i++) {
        const double w = hom ? 4 : 1;
        n += (size_t)snprintf(t + n, sizeof t - n, "%g %g %g", w * V[i][0], w * V[i][1], w * V[i][2]);
        if (hom) n += (size_t)snprintf(t + n, sizeof t - n, " 4");
        if (nrm) n += (size_t)snprintf(t + n, sizeof t - n, " 0 1 0");
        if (col) n += (size_t)snprintf(t + n, sizeof t - n, i % 2 ? " 255 128 0" : " 0.5 0.5 0.5 1");
        if (st) n += (size_t)snprintf(t + n, sizeof t - n, " 0.25 0.75");
        n += (size_t)snprintf(t + n, sizeof t - n, i == 5 ? "  # vertex 5\n" : "\n");
    }
    for (int f = 0; f < NF; f++) {
        n += (size_t)snprintf(t + n, sizeof t - n, "%d", F[f][0]);
        for (int k = 1; k <= F[f][0]; k++) n += (size_t)snprintf(t + n, sizeof t - n, " %d", F[f][k]);
        n += (size_t)snprintf(t + n, sizeof t - n, f == 1 ? " 1 0 0\n" : f == 2 ? " 0.2 0.3 0.4 1\n" : "\n");
    }
    tu_write_file(in(name), t);
}

static void test_off_variants(void **st)
{
    (void)st;
    write_off("plain.off", "OFF", 0, 0, 0, 0, 0, 0);
    expect_known("plain.off");
    write_off("c.off", "COFF", 0, 0, 1, 0, 0, 0);
    expect_known("c.off");
    write_off("n.off", "NOFF", 0, 1, 0, 0, 0, 0);
    expect_known("n.off");
    write_off("st.off", "STOFF", 0, 0, 0, 1, 0, 0);
    expect_known("st.off");
    write_off("cn.off", "CNOFF", 0, 1, 1, 0, 0, 0);
    expect_known("cn.off");
    write_off("stcn4.off", "STCN4OFF", 1, 1, 1, 1, 0, 0);
    expect_known("stcn4.off");
    write_off("ndim.off", "nOFF", 0, 0, 0, 0, 1, 0);
    expect_known("ndim.off");
    write_off("sameline.off", "OFF", 0, 0, 0, 0, 0, 1);
    expect_known("sameline.off");
    write_off("nokeyword.off", NULL, 0, 0, 0, 0, 0, 0);
    expect_known("nokeyword.off");
    ms_scene sc;
    load("n.off", NULL, &sc);
    assert_non_null(sc.tri_normal);
    assert_true(sc.tri_normal[1] == 1.0f);
    ms_scene_free(&sc);
}

/* ---------------------------------------------------------------- STL */

static void test_stl_variants(void **st)
{
    (void)st;
    /* The known polygons fanned here (STL holds triangles): the count is the same. */
    char t[32768];
    size_t n = 0;
    for (int s = 0; s < 2; s++) {
        n += (size_t)snprintf(t + n, sizeof t - n, "solid part%d exported\n", s);
        for (int f = s; f < NF; f += 2)
            for (int k = 2; k < F[f][0]; k++) {
                const int c[3] = { F[f][1], F[f][k], F[f][k + 1] };
                n += (size_t)snprintf(t + n, sizeof t - n, "  facet normal 0 0 0\n\touter loop\n");
                for (int q = 0; q < 3; q++)
                    n += (size_t)snprintf(t + n, sizeof t - n, "      vertex %g %g %g\n", V[c[q]][0], V[c[q]][1], V[c[q]][2]);
                n += (size_t)snprintf(t + n, sizeof t - n, "    endloop\n  endfacet\n");
            }
        n += (size_t)snprintf(t + n, sizeof t - n, "endsolid part%d\n", s);
    }
    tu_write_file(in("a.stl"), t);
    expect_known("a.stl");
    for (size_t i = 0; t[i]; i++) t[i] = (char)toupper((unsigned char)t[i]);   /* keywords in capitals */
    tu_write_file(in("upper.stl"), t);
    expect_known("upper.stl");
    for (int solid = 0; solid < 2; solid++) {
        wbuf w = { NULL, 0, 0, 1 };
        unsigned char hdr[80];
        memset(hdr, ' ', sizeof hdr);
        if (solid) memcpy(hdr, "solid binary STL whose header says solid", 40);
        put(&w, hdr, 80);
        const uint32_t cnt = (uint32_t)expected_tris();
        put(&w, &cnt, 4);
        for (int f = 0; f < NF; f++)
            for (int k = 2; k < F[f][0]; k++) {
                const int c[3] = { F[f][1], F[f][k], F[f][k + 1] };
                float x[12] = { 0, 0, 1 };
                for (int q = 0; q < 3; q++)
                    for (int d = 0; d < 3; d++) x[3 + 3 * q + d] = (float)V[c[q]][d];
                put(&w, x, sizeof x);
                put(&w, "\0\0", 2);
            }
        const char *name = solid ? "solid_header.stl" : "b.stl";
        write_buf(name, &w);
        free(w.b);
        expect_known(name);
    }
}

/* ---------------------------------------------------------------- malformed: one line, exit 2 */

static void expect_refused(const char *mesh, const char *needle)
{
    char m[512], js[512], err[4096], png[4096];
    snprintf(m, sizeof m, "{ \"file\": \"%s\" }", mesh);
    snprintf(js, sizeof js, "bad-%s.json", mesh);
    const char *scene = scene_for(js, m);
    const char *args[] = { scene, "--quiet", "-o", tu_path(png, sizeof png, g_dir, "never.png"), NULL };
    tu_run_result r;
    const int rc = tu_run_cli_ex(args, NULL, err, sizeof err, &r);
    if (rc != 2 || r.lines != 1 || !strstr(err, mesh) || !strstr(err, needle))
        fail_msg("%s: exit %d, %d lines: '%s' (want exit 2, one line naming it and '%s')", mesh, rc, r.lines, err, needle);
    print_message("refused: %s", err);
}

static void test_malformed(void **st)
{
    (void)st;
    static const struct { const char *name, *text, *needle; } t[] = {
        { "idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: vertex index '4' is not in 1..3" },
        { "neg.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", "line 3: vertex index '-3'" },
        { "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "malformed" },
        { "nan.obj", "v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n", "line 2: a vertex coordinate is not a number" },
        { "two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "line 3: a face needs at least 3 vertices" },
        { "vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", "texture index '2'" },
        { "slashes.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "malformed face vertex" },
        { "w0.obj", "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "w = 0" },
        { "count.off", "OFF\n3000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "declares 3000 vertices" },
        { "idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "not in 0..2" },
        { "short.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "ends after 1 of 2 faces" },
        { "binary.off", "OFF BINARY\n", "binary OFF is not supported" },
        { "dim.off", "nOFF\n5\n1 1 0\n0 0 0 0 0\n1 0\n", "5-dimensional" },
        { "count.ply", "ply\nformat ascii 1.0\nelement vertex 300\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
          "declares 300 instances" },
        { "idx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
          "vertex index 7 is not in 0..2" },
        { "more.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 5\n",
          "more values than the PLY header declares" },
        { "nohdr.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header" },
        { "fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format" },
        { "xyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n", "lacks an x, y or z" },
        { "cut.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n", "malformed ASCII STL" },
        { "word.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n", "expected a number" },
        { "short.stl", "not an stl", "not an STL file" },
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        tu_write_file(in(t[i].name), t[i].text);
        expect_refused(t[i].name, t[i].needle);
    }
    /* Over a documented limit: a face of 257 vertices (OBJ, OFF, PLY). */
    char big[16384];
    size_t n = 0;
    for (int i = 0; i < 257; i++) n += (size_t)snprintf(big + n, sizeof big - n, "v %d %d 0\n", i, i * i);
    n += (size_t)snprintf(big + n, sizeof big - n, "f");
    for (int i = 1; i <= 257; i++) n += (size_t)snprintf(big + n, sizeof big - n, " %d", i);
    snprintf(big + n, sizeof big - n, "\n");
    tu_write_file(in("poly257.obj"), big);
    expect_refused("poly257.obj", "over the limit");
    n = (size_t)snprintf(big, sizeof big, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n257");
    for (int i = 0; i < 257; i++) n += (size_t)snprintf(big + n, sizeof big - n, " %d", i % 3);
    snprintf(big + n, sizeof big - n, "\n");
    tu_write_file(in("poly257.off"), big);
    expect_refused("poly257.off", "over the limit");
    /* Binary STL whose count does not match its size; binary PLY cut short. */
    wbuf w = { NULL, 0, 0, 1 };
    unsigned char hdr[84] = { 0 };
    hdr[80] = 3;
    put(&w, hdr, 84);
    put(&w, hdr, 50);
    write_buf("count.stl", &w);
    free(w.b);
    expect_refused("count.stl", "binary STL declares 3 triangles");
    wbuf p = { NULL, 0, 0, 1 };
    puts_(&p, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n");
    for (int i = 0; i < 9; i++) val(&p, F32, i, 0);
    val(&p, U8, 3, 0);
    val(&p, I32, 0, 0);
    write_buf("cut.ply", &p);
    free(p.b);
    expect_refused("cut.ply", "face 0: truncated");
}

/* ---------------------------------------------------------------- transforms */

static const char *cube_obj(void)
{
    /* The unit cube [0,1]^3, outward winding, a normal per vertex. */
    tu_write_file(in("cube.obj"),
                  "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                  "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n"
                  "f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1//3 2//3 6//3 5//3\nf 4//4 8//4 7//4 3//4\n"
                  "f 1//5 5//5 8//5 4//5\nf 2//6 3//6 7//6 6//6\n");
    return "cube.obj";
}

/* Every triangle's geometric normal points away from the centre c, and so does each vertex normal. */
static void expect_outward(const char *what, const ms_scene *sc, const double c[3])
{
    for (size_t t = 0; t < sc->n_tris; t++) {
        const float *p = sc->tri + 9 * t;
        double e1[3], e2[3], nn[3], m[3];
        for (int d = 0; d < 3; d++) {
            e1[d] = p[3 + d] - p[d];
            e2[d] = p[6 + d] - p[d];
            m[d] = (p[d] + p[3 + d] + p[6 + d]) / 3 + sc->origin[d] - c[d];   /* world = local + origin */
        }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        if (nn[0] * m[0] + nn[1] * m[1] + nn[2] * m[2] <= 0) fail_msg("%s: triangle %zu winds inward", what, t);
        assert_non_null(sc->tri_normal);
        for (int k = 0; k < 3; k++) {
            const float *vn = sc->tri_normal + 9 * t + 3 * k;
            const double dd = vn[0] * nn[0] + vn[1] * nn[1] + vn[2] * nn[2];
            const double len = sqrt(vn[0] * vn[0] + vn[1] * vn[1] + vn[2] * vn[2]);
            if (dd <= 0 || fabs(len - 1) > 1e-5) fail_msg("%s: triangle %zu: vertex normal %d inward or not unit", what, t, k);
        }
    }
}

static void test_transform_trs(void **st)
{
    (void)st;
    const char *cube = cube_obj();
    ms_scene sc;
    /* scale 2: [0,2]^3; rotate 90 degrees about y: (x, z) -> (z, -x): x in [0,2], z in [-2,0];
     * translate (1, 2, 3): x [1,3], y [2,4], z [1,3]. */
    load(cube, "{\"translate\": [1, 2, 3], \"rotate_deg\": [0, 90, 0], \"scale\": 2}", &sc);
    assert_int_equal(sc.n_tris, 12);
    const double lo[3] = { 1, 2, 1 }, hi[3] = { 3, 4, 3 };
    expect_box("trs", &sc, lo, hi, 1e-5);
    const double c1[3] = { 2, 3, 2 };
    expect_outward("trs", &sc, c1);
    ms_scene_free(&sc);
    /* Non-uniform scale and x then z rotation: (x,y,z) scaled (1,2,3); Rx 90: (x,y,z) -> (x,-z,y);
     * Rz 90: (x,y,z) -> (-y,x,z). Cube [0,1]x[0,2]x[0,3] -> Rx: x[0,1] y[-3,0] z[0,2] -> Rz: x[0,3] y[0,1] z[0,2]. */
    load(cube, "{\"rotate_deg\": [90, 0, 90], \"scale\": [1, 2, 3]}", &sc);
    const double lo2[3] = { 0, 0, 0 }, hi2[3] = { 3, 1, 2 };
    expect_box("xz", &sc, lo2, hi2, 1e-5);
    const double c2[3] = { 1.5, 0.5, 1 };
    expect_outward("xz", &sc, c2);
    ms_scene_free(&sc);
}

static void test_transform_matrix_equals_trs(void **st)
{
    (void)st;
    const char *cube = cube_obj();
    ms_scene a, b;
    load(cube, "{\"translate\": [-4, 0.5, 7], \"rotate_deg\": [0, 0, 90], \"scale\": [2, 3, 0.5]}", &a);
    /* The same as one column-major matrix: Rz(90) S = [[0,-3,0],[2,0,0],[0,0,0.5]], T in the last column. */
    load(cube, "{\"matrix\": [0, 2, 0, 0,  -3, 0, 0, 0,  0, 0, 0.5, 0,  -4, 0.5, 7, 1]}", &b);
    assert_int_equal(a.n_tris, b.n_tris);
    for (size_t i = 0; i < 9 * a.n_tris; i++)
        if (fabsf(a.tri[i] - b.tri[i]) > 1e-5f) fail_msg("coordinate %zu: TRS %g, matrix %g", i, a.tri[i], b.tri[i]);
    for (size_t i = 0; i < 9 * a.n_tris; i++)
        if (fabsf(a.tri_normal[i] - b.tri_normal[i]) > 1e-5f) fail_msg("normal %zu: TRS %g, matrix %g", i, a.tri_normal[i], b.tri_normal[i]);
    ms_scene_free(&a);
    ms_scene_free(&b);
}

static void test_transform_mirror(void **st)
{
    (void)st;
    const char *cube = cube_obj();
    ms_scene sc;
    load(cube, "{\"scale\": [-1, 1, 1]}", &sc);
    const double lo[3] = { -1, 0, 0 }, hi[3] = { 0, 1, 1 };
    expect_box("mirror", &sc, lo, hi, 0);
    const double c[3] = { -0.5, 0.5, 0.5 };
    expect_outward("mirror (negative determinant)", &sc, c);
    ms_scene_free(&sc);
    load(cube, "{\"matrix\": [1, 0, 0, 0,  0, 0, 1, 0,  0, 1, 0, 0,  0, 0, 0, 1]}", &sc);   /* swaps y and z */
    const double c2[3] = { 0.5, 0.5, 0.5 };
    expect_outward("swap y z", &sc, c2);
    ms_scene_free(&sc);
}

static int g_warnings;
static void count_warning(void *user, const char *msg)
{
    (void)user;
    if (strstr(msg, "nosuch.mtl")) g_warnings++;
}

static void test_same_file_twice(void **st)
{
    (void)st;
    tu_write_file(in("tri_mtl.obj"), "mtllib nosuch.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    char err[1024];
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    ms_set_warning_handler(count_warning, NULL);
    ms_set_warning_verbose(1);
    g_warnings = 0;
    const char *scene = scene_for("twice.json",
        "{\"file\": \"tri_mtl.obj\", \"transform\": {\"translate\": [10, 0, 0]}},"
        "{\"file\": \"tri_mtl.obj\", \"transform\": {\"scale\": 3}}, {\"file\": \"tri_mtl.obj\"}");
    const int rc = ms_scene_load(scene, &sc, err, sizeof err);
    ms_set_warning_verbose(0);
    ms_set_warning_handler(NULL, NULL);
    if (rc) fail_msg("%s", err);
    assert_int_equal(sc.n_tris, 3);
    assert_int_equal(sc.n_meshes, 3);
    /* the file was read once: its missing MTL file warned about once */
    assert_int_equal(g_warnings, 1);
    const double lo[3] = { 0, 0, 0 }, hi[3] = { 11, 3, 0 };
    expect_box("twice", &sc, lo, hi, 0);
    const float want[3][9] = { { 10, 0, 0, 11, 0, 0, 10, 1, 0 }, { 0, 0, 0, 3, 0, 0, 0, 3, 0 }, { 0, 0, 0, 1, 0, 0, 0, 1, 0 } };
    for (int t = 0; t < 3; t++) {
        assert_int_equal(sc.tri_mesh[t], t);
        for (int i = 0; i < 9; i++) assert_true(sc.tri[9 * t + i] == want[t][i]);
    }
    ms_scene_free(&sc);
}

static void test_bad_transforms(void **st)
{
    (void)st;
    tu_write_file(in("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    static const struct { const char *t, *needle; } b[] = {
        { "{\"rotate\": [0, 90, 0]}", "unknown key \"rotate\"" },
        { "{\"translate\": [1, 2]}", "translate must have 3 numbers" },
        { "{\"translate\": [1, 2, \"x\"]}", "translate[2] must be a finite number" },
        { "{\"scale\": 1e999}", "scale must be a finite number" },
        { "{\"scale\": \"big\"}", "scale must be a number or an array" },
        { "{\"scale\": 0}", "singular" },
        { "{\"scale\": [1, 1e-300, 1]}", "singular" },
        { "{\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0]}", "matrix must have 16 numbers" },
        { "{\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 1]}", "singular" },
        { "{\"matrix\": [1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}", "last row" },
        { "{\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], \"scale\": 2}", "either" },
        { "[1, 2, 3]", "transform must be an object" },
    };
    for (size_t i = 0; i < sizeof b / sizeof b[0]; i++) {
        char m[512], js[64], err[4096], png[4096];
        snprintf(m, sizeof m, "{ \"file\": \"tri.obj\", \"transform\": %s }", b[i].t);
        snprintf(js, sizeof js, "badxf%zu.json", i);
        const char *scene = scene_for(js, m);
        const char *args[] = { scene, "--quiet", "-o", tu_path(png, sizeof png, g_dir, "never.png"), NULL };
        tu_run_result r;
        const int rc = tu_run_cli_ex(args, NULL, err, sizeof err, &r);
        if (rc != 2 || r.lines != 1 || !strstr(err, js) || !strstr(err, "meshes[0]") || !strstr(err, b[i].needle))
            fail_msg("%s: exit %d, %d lines: '%s' (want exit 2, one line with '%s')", b[i].t, rc, r.lines, err, b[i].needle);
        print_message("refused: %s", err);
    }
}

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("formats"));
    return 0;
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_variants),
        cmocka_unit_test(test_ply_variants),
        cmocka_unit_test(test_ply_tristrips),
        cmocka_unit_test(test_off_variants),
        cmocka_unit_test(test_stl_variants),
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_transform_trs),
        cmocka_unit_test(test_transform_matrix_equals_trs),
        cmocka_unit_test(test_transform_mirror),
        cmocka_unit_test(test_same_file_twice),
        cmocka_unit_test(test_bad_transforms),
    };
    return tu_run_group_tests(tests, setup, NULL, argc, argv);
}
