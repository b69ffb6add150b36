/* glTF's other ways of storing the same triangles are read as the triangles themselves: sparse accessors
 * (the base view's elements, or zeros, with values substituted at indices; as Blender writes shape keys and
 * as any exporter may write attributes), buffer views compressed with EXT_meshopt_compression (gltfpack's
 * output: vertex and index codecs, the exponential filter), primitives compressed with
 * KHR_draco_mesh_compression (positions and UVs, edgebreaker and sequential), and nodes with
 * EXT_mesh_gpu_instancing (every instance drawn, placed by its TRANSLATION, ROTATION and SCALE). Oracle: the
 * grid of triangles the test builds itself, compared float for float (Draco: as a set of triangles, since
 * its encoder reorders faces and corners; instances: against the test's own transform in double); the
 * compressed streams are written by meshoptimizer's and Draco's encoders, independent of the decoders the
 * reader uses. Broken variants (a sparse index past the accessor, sparse values past their view, a
 * compressed view whose count and stride do not make its length, corrupt or cut compressed data, an accessor that
 * does not hold the Draco mesh's points) are refused with one line naming the file. Textures: WebP images
 * (EXT_texture_webp, written by libwebp's encoder) decode to the test's own texels, lossless exactly, lossy
 * with its alpha exact; a texture with both a PNG `source` and a WebP takes the PNG; a cut WebP is refused
 * with one line. */
#include "testutil.h"
#include "draco_encode.h"
#include <math.h>
#include <meshoptimizer.h>
#include <webp/encode.h>
#include "scene/scene_internal.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GN 10                      /* grid vertices per side */
#define NV (GN * GN)
#define NT (2 * (GN - 1) * (GN - 1))

static float g_pos[NV][3], g_uv[NV][2];
static uint32_t g_idx[NT * 3];
static char g_dir[4096];

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("gltf_encodings"));
    /* Multiples of 1/8 below 16: exact in every encoding here (the exponential filter's 24-bit mantissas). */
    for (int j = 0; j < GN; j++)
        for (int i = 0; i < GN; i++) {
            g_pos[j * GN + i][0] = 0.5f * (float)i;
            g_pos[j * GN + i][1] = (float)((i * j) % 5) / 8.0f;
            g_pos[j * GN + i][2] = 0.5f * (float)j + 0.125f;
            g_uv[j * GN + i][0] = (float)i / 9.0f;
            g_uv[j * GN + i][1] = 1.0f - (float)j / 7.0f;
        }
    int t = 0;
    for (int j = 0; j + 1 < GN; j++)
        for (int i = 0; i + 1 < GN; i++) {
            const uint32_t a = (uint32_t)(j * GN + i), b = a + 1, c = a + GN, d = c + 1;
            const uint32_t q[6] = { a, c, b, b, c, d };
            memcpy(g_idx + 6 * t++, q, sizeof q);
        }
    return 0;
}

/* A .bin file as it grows: sections at 4-byte boundaries. */
typedef struct bin { unsigned char b[65536]; size_t n; } bin;

static size_t put(bin *b, const void *p, size_t n)
{
    b->n = (b->n + 3) & ~(size_t)3;
    assert_true(b->n + n <= sizeof b->b);
    memcpy(b->b + b->n, p, n);
    b->n += n;
    return b->n - n;
}

/* Writes name.bin and name.gltf (json: the glTF's text, "%s" where the bin file's byte length goes, given
 * once) and loads it through a scene file; 0, or -1 with err. */
static int load(const char *name, const bin *b, const char *json, ms_scene *sc, char *err, size_t n)
{
    char path[4300], file[256], text[16384];
    snprintf(file, sizeof file, "%s.bin", name);
    FILE *f = fopen(tu_path(path, sizeof path, g_dir, file), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b->b, 1, b->n, f), b->n);
    assert_int_equal(fclose(f), 0);
    char len[32];
    snprintf(len, sizeof len, "%zu", b->n);
    snprintf(text, sizeof text, json, file, len);
    snprintf(file, sizeof file, "%s.gltf", name);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, g_dir, file), text), 0);
    char scene[1024];
    snprintf(scene, sizeof scene,
             "{\"meshes\": [{\"file\": \"%s\"}],\n"
             " \"camera\": {\"eye\": [2, 8, 2], \"target\": [2, 0, 2], \"up\": [0, 0, -1], \"fov_y\": 60, \"width\": 16, \"height\": 16},\n"
             " \"light\": {\"corner\": [0, 10, 0], \"edge_s\": [1, 0, 0], \"edge_t\": [0, 0, 1]}}\n", file);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, g_dir, "scene.json"), scene), 0);
    err[0] = 0;
    return ms_scene_load(path, sc, err, n);
}

/* The scene holds the grid's triangles in order, float for float. */
static void assert_grid(const ms_scene *sc)
{
    assert_int_equal(sc->n_tris, NT);
    for (int t = 0; t < NT; t++)
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                if (sc->tri[9 * t + 3 * v + k] != g_pos[g_idx[3 * t + v]][k])
                    fail_msg("triangle %d vertex %d: %g, expected %g", t, v, (double)sc->tri[9 * t + 3 * v + k],
                             (double)g_pos[g_idx[3 * t + v]][k]);
}

static void assert_refused(int rc, const char *err, const char *name, const char *what)
{
    if (rc == 0) fail_msg("%s was read; expected a refusal mentioning '%s'", name, what);
    assert_null(strchr(err, '\n'));
    if (!strstr(err, name) || !strstr(err, what)) fail_msg("message '%s' must name %s and say '%s'", err, name, what);
}

/* The glTF around POSITION accessor 0 and index accessor 1; extra: more accessors, views, buffers and the
 * extensions' declarations, spliced in. */
static void gltf_text(char *out, size_t n, const char *accessors, const char *views, const char *buffers, const char *ext)
{
    snprintf(out, n,
             "{\"asset\": {\"version\": \"2.0\"}%s,\n"
             " \"buffers\": [{\"uri\": \"%%s\", \"byteLength\": %%s}%s],\n"
             " \"bufferViews\": [%s],\n"
             " \"accessors\": [%s],\n"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1}]}],\n"
             " \"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], \"scene\": 0}\n",
             ext, buffers, views, accessors);
}

/* POSITION with every fourth vertex wrong in its base view and put right by a sparse part, indices of the
 * given size; and POSITION with no base view at all (zeros), every vertex sparse. */
static void test_sparse(void **st)
{
    (void)st;
    static const int isize[3] = { 1, 2, 4 }, ictype[3] = { 5121, 5123, 5125 };
    for (int form = 0; form < 4; form++) {
        const int dense_base = form < 3;
        const int is = dense_base ? isize[form] : 2, ict = dense_base ? ictype[form] : 5123;
        bin b = { .n = 0 };
        float base[NV][3];
        memcpy(base, g_pos, sizeof base);
        unsigned char sidx[NV * 4];
        float sval[NV][3];
        int ns = 0;
        for (int v = 0; v < NV; v++) {
            if (dense_base && v % 4 != 1) continue;
            if (dense_base) base[v][0] = base[v][1] = base[v][2] = -7.0f;
            const uint32_t u = (uint32_t)v;
            const uint16_t h = (uint16_t)v;
            const uint8_t c = (uint8_t)v;
            memcpy(sidx + is * ns, is == 1 ? (const void *)&c : is == 2 ? (const void *)&h : (const void *)&u, (size_t)is);
            memcpy(sval[ns++], g_pos[v], sizeof sval[0]);
        }
        const size_t o_pos = put(&b, base, sizeof base), o_idx = put(&b, g_idx, sizeof g_idx);
        const size_t o_si = put(&b, sidx, (size_t)(is * ns)), o_sv = put(&b, sval, sizeof sval[0] * (size_t)ns);
        char views[1024], accessors[1024], text[8192];
        snprintf(views, sizeof views,
                 "{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu},"
                 " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}",
                 o_pos, sizeof base, o_idx, sizeof g_idx, o_si, (size_t)(is * ns), o_sv, sizeof sval[0] * (size_t)ns);
        snprintf(accessors, sizeof accessors,
                 "{%s\"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 1, 5],"
                 " \"sparse\": {\"count\": %d, \"indices\": {\"bufferView\": 2, \"componentType\": %d},"
                 " \"values\": {\"bufferView\": 3}}},"
                 " {\"bufferView\": 1, \"componentType\": 5125, \"count\": %d, \"type\": \"SCALAR\"}",
                 dense_base ? "\"bufferView\": 0, " : "", NV, ns, ict, NT * 3);
        gltf_text(text, sizeof text, accessors, views, "", "");
        ms_scene sc;
        char err[1024], name[32];
        snprintf(name, sizeof name, "sparse%d", form);
        if (load(name, &b, text, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_grid(&sc);
        ms_scene_free(&sc);
        if (form != 1) continue;
        /* Broken: an index past the accessor's elements; values past their view. */
        uint16_t past = NV;
        memcpy(b.b + o_si + 2 * (size_t)(ns - 1), &past, 2);
        assert_refused(load("sparse_past", &b, text, &sc, err, sizeof err), err, "sparse_past.gltf", "sparse");
        memcpy(b.b + o_si + 2 * (size_t)(ns - 1), &(uint16_t){ (uint16_t)(NV - 3) }, 2);
        char text2[8192], acc2[1024];
        snprintf(acc2, sizeof acc2, "%s", accessors);
        char *c = strstr(acc2, "\"count\": ");
        c = strstr(c + 1, "\"count\": ");   /* the sparse count: one more than the values hold */
        char tail[1024];
        snprintf(tail, sizeof tail, "\"count\": %d%s", ns + 1, strchr(c + 9, ','));
        strcpy(c, tail);
        gltf_text(text2, sizeof text2, acc2, views, "", "");
        assert_refused(load("sparse_short", &b, text2, &sc, err, sizeof err), err, "sparse_short.gltf", "sparse");
        /* Broken: the 16-bit indices' view starts one byte early, so they are read from an odd address. */
        char views3[1024], text3[8192];
        snprintf(views3, sizeof views3,
                 "{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu},"
                 " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}",
                 o_pos, sizeof base, o_idx, sizeof g_idx, o_si - 1, (size_t)(is * ns) + 1, o_sv, sizeof sval[0] * (size_t)ns);
        gltf_text(text3, sizeof text3, accessors, views3, "", "");
        assert_refused(load("sparse_odd", &b, text3, &sc, err, sizeof err), err, "sparse_odd.gltf", "aligned");
    }
}

/* Positions and indices compressed with EXT_meshopt_compression (ATTRIBUTES, TRIANGLES; then the positions
 * as four floats through the EXPONENTIAL filter), the views' own buffer a fallback without data. */
static void test_meshopt(void **st)
{
    (void)st;
    for (int form = 0; form < 2; form++) {
        bin b = { .n = 0 };
        unsigned char enc[32768];
        size_t stride = 12, n_pos, n_idx;
        if (form == 0) {
            n_pos = meshopt_encodeVertexBuffer(enc, sizeof enc, g_pos, NV, 12);
        } else {
            static float p4[NV][4];
            static uint32_t e4[NV][4];
            for (int v = 0; v < NV; v++) { memcpy(p4[v], g_pos[v], 12); p4[v][3] = 1.0f; }
            meshopt_encodeFilterExp(e4, NV, 16, 24, &p4[0][0]);
            stride = 16;
            n_pos = meshopt_encodeVertexBuffer(enc, sizeof enc, e4, NV, 16);
        }
        assert_true(n_pos > 0);
        const size_t o_pos = put(&b, enc, n_pos);
        n_idx = meshopt_encodeIndexBuffer(enc, sizeof enc, g_idx, NT * 3);
        assert_true(n_idx > 0);
        const size_t o_idx = put(&b, enc, n_idx);
        char views[1024], accessors[512], text[8192];
        snprintf(views, sizeof views,
                 "{\"buffer\": 1, \"byteLength\": %zu, \"byteStride\": %zu, \"extensions\": {\"EXT_meshopt_compression\":"
                 " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu, \"byteStride\": %zu, \"count\": %d, \"mode\": \"ATTRIBUTES\"%s}}},"
                 " {\"buffer\": 1, \"byteOffset\": %zu, \"byteLength\": %zu, \"extensions\": {\"EXT_meshopt_compression\":"
                 " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu, \"byteStride\": 4, \"count\": %d, \"mode\": \"TRIANGLES\"}}}",
                 stride * NV, stride, o_pos, n_pos, stride, NV, form ? ", \"filter\": \"EXPONENTIAL\"" : "",
                 stride * NV, sizeof g_idx, o_idx, n_idx, NT * 3);
        snprintf(accessors, sizeof accessors,
                 "{\"bufferView\": 0, \"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 1, 5]},"
                 " {\"bufferView\": 1, \"componentType\": 5125, \"count\": %d, \"type\": \"SCALAR\"}", NV, NT * 3);
        char buffers[256];
        snprintf(buffers, sizeof buffers, ", {\"byteLength\": %zu, \"extensions\": {\"EXT_meshopt_compression\": {\"fallback\": true}}}",
                 stride * NV + sizeof g_idx);
        gltf_text(text, sizeof text, accessors, views, buffers,
                  ", \"extensionsUsed\": [\"EXT_meshopt_compression\"], \"extensionsRequired\": [\"EXT_meshopt_compression\"]");
        ms_scene sc;
        char err[1024];
        if (load(form ? "meshopt_exp" : "meshopt", &b, text, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_grid(&sc);
        ms_scene_free(&sc);
        if (form) continue;
        /* Broken: the compressed vertex stream cut short; a count that does not make the view's length. */
        bin cut = b;
        memset(cut.b + o_pos + n_pos / 2, 0xA5, n_pos - n_pos / 2);
        assert_refused(load("meshopt_corrupt", &cut, text, &sc, err, sizeof err), err, "meshopt_corrupt.gltf", "meshopt");
        char *c = strstr(text, "\"count\": ");
        char tail[8192];
        snprintf(tail, sizeof tail, "\"count\": %d%s", NV - 1, strchr(c + 9, ','));
        strcpy(c, tail);
        assert_refused(load("meshopt_count", &b, text, &sc, err, sizeof err), err, "meshopt_count.gltf", "meshopt");
    }
}

/* Three instances of the grid (EXT_mesh_gpu_instancing) under a translated node: each instance's triangles,
 * in instance order, are node x T R S of the grid's (the test's own quaternion rotation, in double). */
static void test_instancing(void **st)
{
    (void)st;
    const float tr[3][3] = { { 0, 0, 0 }, { 10, 0, 0 }, { 0, 3, -4 } };
    const float sc3[3][3] = { { 1, 1, 1 }, { 2, 2, 2 }, { 1, 0.5f, 1 } };
    const double ang[3] = { 0.0, M_PI / 2, M_PI / 3 };   /* about +y */
    float rot[3][4];
    for (int i = 0; i < 3; i++) {
        rot[i][0] = 0.0f; rot[i][1] = (float)sin(ang[i] / 2); rot[i][2] = 0.0f; rot[i][3] = (float)cos(ang[i] / 2);
    }
    bin b = { .n = 0 };
    const size_t o_pos = put(&b, g_pos, sizeof g_pos), o_idx = put(&b, g_idx, sizeof g_idx);
    const size_t o_t = put(&b, tr, sizeof tr), o_r = put(&b, rot, sizeof rot), o_s = put(&b, sc3, sizeof sc3);
    char views[1024], accessors[2048], text[8192];
    snprintf(views, sizeof views,
             "{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu},"
             " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 48},"
             " {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 36}",
             o_pos, sizeof g_pos, o_idx, sizeof g_idx, o_t, o_r, o_s);
    snprintf(accessors, sizeof accessors,
             "{\"bufferView\": 0, \"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 1, 5]},"
             " {\"bufferView\": 1, \"componentType\": 5125, \"count\": %d, \"type\": \"SCALAR\"},"
             " {\"bufferView\": 2, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"},"
             " {\"bufferView\": 3, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC4\"},"
             " {\"bufferView\": 4, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}", NV, NT * 3);
    gltf_text(text, sizeof text, accessors, views, "", ", \"extensionsUsed\": [\"EXT_mesh_gpu_instancing\"]");
    /* The node: translated by (1, 2, 3), with the instances. */
    char *node = strstr(text, "\"nodes\": [{\"mesh\": 0}]");
    assert_non_null(node);
    char tail[8192];
    snprintf(tail, sizeof tail, "\"nodes\": [{\"mesh\": 0, \"translation\": [1, 2, 3], \"extensions\": {\"EXT_mesh_gpu_instancing\":"
             " {\"attributes\": {\"TRANSLATION\": 2, \"ROTATION\": 3, \"SCALE\": 4}}}}]%s", node + strlen("\"nodes\": [{\"mesh\": 0}]"));
    strcpy(node, tail);
    ms_scene sc;
    char err[1024];
    if (load("instances", &b, text, &sc, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(sc.n_tris, 3 * NT);
    double worst = 0.0;
    for (int i = 0; i < 3; i++)
        for (int t = 0; t < NT; t++)
            for (int v = 0; v < 3; v++) {
                const float *p = g_pos[g_idx[3 * t + v]];
                const double x = p[0] * sc3[i][0], y = p[1] * sc3[i][1], z = p[2] * sc3[i][2];
                const double c = cos(ang[i]), s = sin(ang[i]);
                const double w[3] = { c * x + s * z + tr[i][0] + 1, y + tr[i][1] + 2, -s * x + c * z + tr[i][2] + 3 };
                for (int k = 0; k < 3; k++) {
                    const double e = fabs(sc.tri[9 * ((size_t)i * NT + (size_t)t) + 3 * (size_t)v + (size_t)k] - w[k]);
                    worst = e > worst ? e : worst;
                }
            }
    if (worst > 1e-5) fail_msg("instance vertices off by up to %g", worst);
    ms_scene_free(&sc);
    /* Broken: TRANSLATION as VEC2. */
    char *vec = strstr(text, "\"count\": 3, \"type\": \"VEC3\"");
    assert_non_null(vec);
    memcpy(strstr(vec, "VEC3"), "VEC2", 4);
    assert_refused(load("instances_bad", &b, text, &sc, err, sizeof err), err, "instances_bad.gltf", "TRANSLATION");
}

/* A triangle's corners (position, UV) rotated to start at the smallest, winding kept; for sorting. */
typedef struct corner5 { float c[3][5]; } corner5;

static int cmp_corner(const float *a, const float *b)
{
    for (int k = 0; k < 5; k++)
        if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int cmp_tri(const void *a, const void *b)
{
    const corner5 *x = a, *y = b;
    for (int v = 0; v < 3; v++) {
        const int c = cmp_corner(x->c[v], y->c[v]);
        if (c) return c;
    }
    return 0;
}

static void canonical(corner5 *t)
{
    int m = 0;
    for (int v = 1; v < 3; v++)
        if (cmp_corner(t->c[v], t->c[m]) < 0) m = v;
    corner5 r;
    for (int v = 0; v < 3; v++) memcpy(r.c[v], t->c[(v + m) % 3], sizeof r.c[v]);
    *t = r;
}

/* The grid compressed with Draco (edgebreaker, then sequential), POSITION and TEXCOORD_0 in the Draco map. */
static void test_draco(void **st)
{
    (void)st;
    static corner5 want[NT], got[NT];
    for (int t = 0; t < NT; t++) {
        for (int v = 0; v < 3; v++) {
            memcpy(want[t].c[v], g_pos[g_idx[3 * t + v]], 12);
            memcpy(want[t].c[v] + 3, g_uv[g_idx[3 * t + v]], 8);
        }
        canonical(&want[t]);
    }
    qsort(want, NT, sizeof want[0], cmp_tri);
    for (int seq = 0; seq < 2; seq++) {
        bin b = { .n = 0 };
        unsigned char enc[32768];
        uint32_t pid = 0, tid = 0;
        const size_t n = tu_draco_encode(&g_pos[0][0], &g_uv[0][0], NV, g_idx, NT, seq, enc, sizeof enc, &pid, &tid);
        assert_true(n > 0);
        put(&b, enc, n);
        char text[4096];
        const char *form =
            "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_draco_mesh_compression\"],"
            " \"extensionsRequired\": [\"KHR_draco_mesh_compression\"],\n"
            " \"buffers\": [{\"uri\": \"%%s\", \"byteLength\": %%s}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": %zu}],\n"
            " \"accessors\": [{\"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [5, 1, 5]},"
            " {\"componentType\": 5125, \"count\": %d, \"type\": \"SCALAR\"}, {\"componentType\": 5126, \"count\": %d, \"type\": \"VEC2\"}],\n"
            " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 2}, \"indices\": 1,"
            " \"extensions\": {\"KHR_draco_mesh_compression\": {\"bufferView\": 0, \"attributes\": {\"POSITION\": %u, \"TEXCOORD_0\": %u}}}}]}],\n"
            " \"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], \"scene\": 0}\n";
        snprintf(text, sizeof text, form, n, NV, NT * 3, NV, pid, tid);
        ms_scene sc;
        char err[1024];
        if (load(seq ? "draco_seq" : "draco", &b, text, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_int_equal(sc.n_tris, NT);
        assert_non_null(sc.tri_uv[0]);
        for (int t = 0; t < NT; t++) {
            for (int v = 0; v < 3; v++) {
                memcpy(got[t].c[v], sc.tri + 9 * t + 3 * v, 12);
                memcpy(got[t].c[v] + 3, sc.tri_uv[0] + 6 * t + 2 * v, 8);
            }
            canonical(&got[t]);
        }
        qsort(got, NT, sizeof got[0], cmp_tri);
        for (int t = 0; t < NT; t++)
            if (cmp_tri(&got[t], &want[t])) fail_msg("Draco (%s): triangle %d of the sorted sets differs", seq ? "sequential" : "edgebreaker", t);
        ms_scene_free(&sc);
        if (seq) continue;
        /* Broken: the Draco data cut to half its length; accessors one point short of the mesh. */
        snprintf(text, sizeof text, form, n / 2, NV, NT * 3, NV, pid, tid);
        assert_refused(load("draco_cut", &b, text, &sc, err, sizeof err), err, "draco_cut.gltf", "Draco");
        snprintf(text, sizeof text, form, n, NV - 1, NT * 3, NV - 1, pid, tid);
        assert_refused(load("draco_count", &b, text, &sc, err, sizeof err), err, "draco_count.gltf", "Draco");
    }
}

/* A 5 x 3 RGBA image whose texels all differ, alpha included. */
static void webp_texels(unsigned char rgba[5 * 3 * 4])
{
    for (int i = 0; i < 15; i++) {
        rgba[4 * i] = (unsigned char)(17 * i);
        rgba[4 * i + 1] = (unsigned char)(255 - 13 * i);
        rgba[4 * i + 2] = (unsigned char)((i * 97) & 255);
        rgba[4 * i + 3] = (unsigned char)(40 + 10 * i);
    }
}

/* The glTF of one textured triangle whose base colour texture has the given `source` part and an
 * EXT_texture_webp image (image 1, a data URI); image 0 a PNG data URI. */
static void webp_gltf(char *out, size_t n, const char *source, const char *png64, const char *webp64)
{
    /* The buffer: three positions, then their three UVs. */
    static const float b[15] = { 0, 0, 0, 4, 0, 0, 0, 0, 4, 0, 0, 1, 0, 0, 1 };
    char b64[128];
    tu_base64((const unsigned char *)b, sizeof b, b64);
    snprintf(out, n,
             "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"EXT_texture_webp\"],\n"
             " \"buffers\": [{\"uri\": \"data:application/octet-stream;base64,%s\", \"byteLength\": 60}],\n"
             " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 24}],\n"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [4, 0, 4]},"
             " {\"bufferView\": 1, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC2\"}],\n"
             " \"images\": [{\"uri\": \"data:image/png;base64,%s\"}, {\"uri\": \"data:image/webp;base64,%s\"}],\n"
             " \"textures\": [{%s\"extensions\": {\"EXT_texture_webp\": {\"source\": 1}}}],\n"
             " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}],\n"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}, \"material\": 0}]}],\n"
             " \"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], \"scene\": 0}\n",
             b64, png64, webp64, source);
}

static void test_webp(void **st)
{
    (void)st;
    unsigned char rgba[60];
    webp_texels(rgba);
    uint8_t *lossless = NULL, *lossy = NULL;
    const size_t nl = WebPEncodeLosslessRGBA(rgba, 5, 3, 20, &lossless), ny = WebPEncodeRGBA(rgba, 5, 3, 20, 90.0f, &lossy);
    assert_true(nl > 0 && ny > 0);
    ms_texture t;
    char err[512];
    for (int flip = 0; flip < 2; flip++) {   /* lossless: every texel, rows in either order */
        if (ms_texture_decode(lossless, nl, "x.webp", flip, (size_t)1 << 20, &t, err, sizeof err)) fail_msg("%s", err);
        assert_int_equal(t.width, 5);
        assert_int_equal(t.height, 3);
        for (int y = 0; y < 3; y++) assert_memory_equal(t.rgba + 20 * (flip ? 2 - y : y), rgba + 20 * y, 20);
        free(t.rgba);
    }
    if (ms_texture_decode(lossy, ny, "x.webp", 0, (size_t)1 << 20, &t, err, sizeof err)) fail_msg("%s", err);
    for (int i = 0; i < 15; i++) assert_int_equal(t.rgba[4 * i + 3], rgba[4 * i + 3]);   /* its alpha is lossless */
    free(t.rgba);
    /* Cut: one line naming the file; too large for the budget: refused before decoding. */
    assert_int_equal(ms_texture_decode(lossless, nl / 2, "cut.webp", 0, (size_t)1 << 20, &t, err, sizeof err), -1);
    assert_null(strchr(err, '\n'));
    assert_non_null(strstr(err, "cut.webp: "));
    assert_int_equal(ms_texture_decode(lossless, nl, "big.webp", 0, 59, &t, err, sizeof err), -1);
    assert_non_null(strstr(err, "exceed"));
    /* Through a glTF: the WebP where the texture has no source; the PNG source where it has one. */
    static char webp64[512], png64[4096], text[8192];
    tu_base64(lossless, nl, webp64);
    unsigned char grey[15 * 3];
    memset(grey, 200, sizeof grey);
    tu_png_base64(grey, 5, 3, png64, sizeof png64);
    for (int with_source = 0; with_source < 2; with_source++) {
        webp_gltf(text, sizeof text, with_source ? "\"source\": 0, " : "", png64, webp64);
        bin b = { .n = 0 };
        put(&b, "unused", 6);
        ms_scene sc;
        char name[32];
        snprintf(name, sizeof name, "webp%d", with_source);
        assert_null(strchr(text, '%'));   /* load() formats the text with the bin file's name, which this glTF does not use */
        if (load(name, &b, text, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_int_equal((int)sc.n_textures, 1);
        assert_int_equal(sc.textures[0].width, 5);
        assert_int_equal(sc.textures[0].height, 3);
        if (with_source)
            for (int i = 0; i < 15; i++) assert_int_equal(sc.textures[0].rgba[4 * i], 200);
        else
            assert_memory_equal(sc.textures[0].rgba, rgba, 60);
        ms_scene_free(&sc);
    }
    WebPFree(lossless);
    WebPFree(lossy);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sparse),
        cmocka_unit_test(test_meshopt),
        cmocka_unit_test(test_draco),
        cmocka_unit_test(test_instancing),
        cmocka_unit_test(test_webp),
    };
    return tu_run_group_tests(tests, setup, NULL, argc, argv);
}
