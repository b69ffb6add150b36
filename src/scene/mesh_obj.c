/* Wavefront OBJ: v (3, 4 homogeneous, or 6-7 with a colour), vt (1-3), vn, f with any mix of v, v/vt,
 * v//vn, v/vt/vn and negative (relative) indices, polygons triangulated as assimp did (mesh_reader.c);
 * usemtl names resolved in the MTL files of the mtllib lines (mtl.c, relative to the OBJ); line
 * continuations, comments anywhere, o/g/s/mg and unknown statements skipped; l and p cast no shadow;
 * free-form geometry (cstype ... end) skipped with a warning.
 *
 * Bounded: a counting pass sizes the v/vt/vn arrays (each line at least 2 bytes), a face is at most
 * MS_MAX_POLYGON vertices, triangles at most MS_MAX_TRIS_PER_BYTE per byte. */
#include "mesh_reader.h"
#include "microshadow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The line [b, e) with the comment cut off. */
static const char *uncomment(const char *b, const char *e)
{
    const char *h = memchr(b, '#', (size_t)(e - b));
    return h ? h : e;
}

/* The rest of the line after the first token, trimmed (usemtl and mtllib take names with blanks). */
static void rest_of_line(const char *p, const char *e, const char **rb, const char **re)
{
    while (p < e && ms_is_blank(*p)) p++;
    while (e > p && ms_is_blank(e[-1])) e--;
    *rb = p;
    *re = e;
}

/* An index field of a face vertex: nonzero integer, resolved against the `count` defined so far
 * (negative) or all of them (positive, forward references allowed); 0-based, or -1 when it is not an
 * integer, -2 when it is out of range. */
static long obj_index(const char *s, size_t n, uint64_t so_far, uint64_t total)
{
    int64_t v;
    if (ms_parse_int(s, n, &v)) return -1;
    if (v > 0) return (uint64_t)v <= total ? (long)(v - 1) : -2;
    if (v == 0) return -2;
    return (uint64_t)(-v) <= so_far ? (long)((int64_t)so_far + v) : -2;
}

static const char *index_problem(long r) { return r == -1 ? "is not an integer" : "is not"; }

/* The MTL files of the mtllib lines, read relative to the OBJ before the faces (mtl.c). A path leading
 * outside the OBJ's folder is an error unless outside paths are allowed (ms_scene_load_options); a
 * missing or unreadable MTL file is a warning (the materials are left out). */
static int obj_mtllib(const char *rb, const char *re, const char *path, ms_tri_soup *soup, ms_mtl_lib *mtl, char *err,
                      size_t errlen)
{
    if (re == rb) return 0;
    char ref[4096];
    if ((size_t)(re - rb) >= sizeof ref) MS_FAIL("%s: an mtllib path of more than %zu bytes", path, sizeof ref - 1);
    snprintf(ref, sizeof ref, "%.*s", (int)(re - rb), rb);
    /* mtl.c resolves it inside the OBJ's folder (or refuses it: a downloaded asset reads only its own files) */
    return ms_mtl_load(path, ref, soup, mtl, err, errlen);
}

/* Joins continuation lines ('\' at the end of a line) in a copy: the backslash becomes a blank and the
 * line end \x01, a blank to the tokenizer that still counts as a line for messages. NULL: none. */
static char *join_continuations(const char *buf, size_t len, int *oom)
{
    *oom = 0;
    const char *q = buf;
    int any = 0;
    while ((q = memchr(q, '\\', (size_t)(buf + len - q))) != NULL) {
        if (q + 1 < buf + len && (q[1] == '\n' || q[1] == '\r')) { any = 1; break; }
        q++;
    }
    if (!any) return NULL;
    char *c = malloc(len + 1);
    if (!c) { *oom = 1; return NULL; }
    memcpy(c, buf, len + 1);
    for (size_t i = 0; i + 1 < len; i++)
        if (c[i] == '\\' && (c[i + 1] == '\n' || c[i + 1] == '\r')) {
            c[i] = ' ';
            if (c[i + 1] == '\r' && i + 2 < len && c[i + 2] == '\n') { c[i + 1] = ' '; c[i + 2] = '\x01'; }
            else c[i + 1] = '\x01';
        }
    return c;
}

typedef struct obj_state {
    float *v, *vt, *vn;
    double *vd;   /* v in double (the scene's frame is subtracted from these: scene_frame.c) */
    uint64_t nv, nvt, nvn, tv, tvt, tvn;   /* defined so far; in the file */
    int warned_cstype;
} obj_state;

static int parse_reals(const char **p, const char *e, float *out, int max, int *k)
{
    const char *tb;
    size_t tn;
    *k = 0;
    while (ms_text_token(p, e, &tb, &tn)) {
        float f;
        if (ms_parse_real_f(tb, tn, &f)) return -1;
        if (*k < max) out[*k] = f;
        (*k)++;
    }
    return 0;
}

/* The same numbers in double (tokens parse_reals accepted). */
static void parse_reals_d(const char *p, const char *e, double *out, int max)
{
    const char *tb;
    size_t tn;
    for (int k = 0; k < max && ms_text_token(&p, e, &tb, &tn); k++)
        if (ms_parse_real_d(tb, tn, &out[k])) out[k] = 0.0;
}

/* One face: its triangles into the soup. */
static int obj_face(obj_state *s, const char *p, const char *e, const char *path, size_t line, uint32_t material,
                    ms_emit *em, char *err, size_t errlen)
{
    int n = 0;
    long vi[MS_MAX_POLYGON], ti[MS_MAX_POLYGON], ni[MS_MAX_POLYGON];
    const char *tb;
    size_t tn;
    while (ms_text_token(&p, e, &tb, &tn)) {
        if (n == MS_MAX_POLYGON)
            MS_FAIL("%s: line %zu: a face of more than %d vertices (over the limit)", path, line, MS_MAX_POLYGON);
        const char *f[3] = { tb, NULL, NULL };
        size_t fl[3] = { tn, 0, 0 };
        int nf = 1;
        for (size_t i = 0; i < tn; i++)
            if (tb[i] == '/') {
                if (nf == 3) MS_FAIL("%s: line %zu: malformed face vertex '%.*s'", path, line, MS_TOKQ(tn), tb);
                fl[nf - 1] = (size_t)(tb + i - f[nf - 1]);
                f[nf] = tb + i + 1;
                fl[nf] = (size_t)(tb + tn - f[nf]);
                nf++;
            }
        vi[n] = obj_index(f[0], fl[0], s->nv, s->tv);
        if (vi[n] < 0)
            MS_FAIL("%s: line %zu: vertex index '%.*s' %s in 1..%llu (or -1..-%llu) (malformed)", path, line,
                    MS_TOKQ(fl[0]), f[0], index_problem(vi[n]), (unsigned long long)s->tv, (unsigned long long)s->nv);
        ti[n] = ni[n] = -1;
        if (nf >= 2 && fl[1]) {
            ti[n] = obj_index(f[1], fl[1], s->nvt, s->tvt);
            if (ti[n] < 0)
                MS_FAIL("%s: line %zu: texture index '%.*s' %s in 1..%llu (malformed)", path, line,
                        MS_TOKQ(fl[1]), f[1], index_problem(ti[n]), (unsigned long long)s->tvt);
        }
        if (nf == 3 && fl[2]) {
            ni[n] = obj_index(f[2], fl[2], s->nvn, s->tvn);
            if (ni[n] < 0)
                MS_FAIL("%s: line %zu: normal index '%.*s' %s in 1..%llu (malformed)", path, line,
                        MS_TOKQ(fl[2]), f[2], index_problem(ni[n]), (unsigned long long)s->tvn);
        }
        n++;
    }
    if (n < 3) MS_FAIL("%s: line %zu: a face needs at least 3 vertices, not %d (malformed)", path, line, n);
    float pos[3 * MS_MAX_POLYGON];
    for (int i = 0; i < n; i++) memcpy(pos + 3 * i, s->v + 3 * vi[i], 3 * sizeof(float));
    int tri[MS_MAX_POLYGON][3];
    const int nt = ms_triangulate(pos, n, tri);
    for (int t = 0; t < nt; t++) {
        float v[9], uv[6], nn[9];
        double vd[9];
        int has_uv = 1, has_n = 1;
        for (int k = 0; k < 3; k++) {
            const int c = tri[t][k];
            memcpy(v + 3 * k, pos + 3 * c, 3 * sizeof(float));
            memcpy(vd + 3 * k, s->vd + 3 * vi[c], 3 * sizeof(double));
            if (ti[c] < 0) has_uv = 0;
            else memcpy(uv + 2 * k, s->vt + 2 * ti[c], 2 * sizeof(float));
            if (ni[c] < 0) has_n = 0;
            else memcpy(nn + 3 * k, s->vn + 3 * ni[c], 3 * sizeof(float));
        }
        if (ms_emit_tri(em, v, vd, has_uv ? uv : NULL, has_n ? nn : NULL, material, err, errlen)) return -1;
    }
    return 0;
}

static int obj_read(const char *buf, size_t len, const char *path, ms_tri_soup *soup, ms_mtl_lib *mtl,
                    obj_state *s, ms_emit *em, char *err, size_t errlen)
{
    const char *b, *e, *tb, *p;
    size_t tn;
    /* Pass 0 counts v, vt, vn (and reads the MTL files); pass 1 reads them (so that a face may name a
     * vertex defined after it); pass 2 reads the faces, counting again for relative indices. */
    for (int pass = 0; pass < 3; pass++) {
        if (pass == 1) {
            /* Every such line takes at least 2 bytes: at most 6 floats per byte of file. */
            s->v = malloc((s->tv ? s->tv : 1) * 3 * sizeof(float));
            s->vd = malloc((s->tv ? s->tv : 1) * 3 * sizeof(double));
            s->vt = malloc((s->tvt ? s->tvt : 1) * 2 * sizeof(float));
            s->vn = malloc((s->tvn ? s->tvn : 1) * 3 * sizeof(float));
            if (!s->v || !s->vd || !s->vt || !s->vn) MS_FAIL("%s: out of memory", path);
        }
        /* Faces before any usemtl have assimp's default material name. */
        uint32_t material = mtl->n ? ms_mtl_find(mtl, "DefaultMaterial") : MS_NO_MATERIAL;
        int in_cstype = 0;
        s->nv = s->nvt = s->nvn = 0;
        ms_text c = { buf, buf + len, 0 };
        while (ms_text_line(&c, &b, &e)) {
            const size_t line = c.line;
            for (const char *q = b; q < e; q++) c.line += *q == '\x01';   /* joined continuation lines */
            const char *ue = uncomment(b, e);
            p = b;
            if (!ms_text_token(&p, ue, &tb, &tn)) continue;
            if (in_cstype) {   /* free-form geometry: skipped to its end statement */
                if (ms_tok_is(tb, tn, "end")) in_cstype = 0;
                continue;
            }
            if (ms_tok_is(tb, tn, "v")) {
                if (pass == 0) { s->tv++; continue; }
                if (pass == 2) { s->nv++; continue; }
                float f[7];
                double fd[4] = { 0, 0, 0, 1 };
                int k;
                parse_reals_d(p, ue, fd, 4);
                if (parse_reals(&p, ue, f, 7, &k))
                    MS_FAIL("%s: line %zu: a vertex coordinate is not a number (malformed)", path, line);
                if (k != 3 && k != 4 && k != 6 && k != 7)
                    MS_FAIL("%s: line %zu: a vertex needs 3, 4, 6 or 7 numbers, not %d (malformed)", path, line, k);
                if (k == 4) {
                    if (f[3] == 0.0f) MS_FAIL("%s: line %zu: a homogeneous vertex with w = 0 (malformed)", path, line);
                    for (int i = 0; i < 3; i++) f[i] /= f[3];
                    for (int i = 0; i < 3; i++) fd[i] /= fd[3];
                }
                memcpy(s->vd + 3 * s->nv, fd, 3 * sizeof(double));
                memcpy(s->v + 3 * s->nv++, f, 3 * sizeof(float));
            } else if (ms_tok_is(tb, tn, "vt")) {
                if (pass == 0) { s->tvt++; continue; }
                if (pass == 2) { s->nvt++; continue; }
                float f[3] = { 0, 0, 0 };
                int k;
                if (parse_reals(&p, ue, f, 3, &k) || k < 1 || k > 3)
                    MS_FAIL("%s: line %zu: a texture coordinate needs 1 to 3 numbers (malformed)", path, line);
                if (k < 2) f[1] = 0;
                for (int i = 0; i < 2; i++)
                    if (!isfinite(f[i])) f[i] = 0;   /* as assimp: NaN and infinity read as 0 */
                memcpy(s->vt + 2 * s->nvt++, f, 2 * sizeof(float));
            } else if (ms_tok_is(tb, tn, "vn")) {
                if (pass == 0) { s->tvn++; continue; }
                if (pass == 2) { s->nvn++; continue; }
                float f[3];
                int k;
                if (parse_reals(&p, ue, f, 3, &k) || k != 3)
                    MS_FAIL("%s: line %zu: a normal needs 3 numbers (malformed)", path, line);
                memcpy(s->vn + 3 * s->nvn++, f, 3 * sizeof(float));
            } else if (ms_tok_is(tb, tn, "f")) {
                if (pass == 2 && obj_face(s, p, ue, path, line, material, em, err, errlen)) return -1;
            } else if (ms_tok_is(tb, tn, "usemtl")) {
                const char *rb, *re;
                rest_of_line(p, e, &rb, &re);
                if (pass == 2 && re > rb) {
                    char name[1024];
                    snprintf(name, sizeof name, "%.*s", (int)(re - rb), rb);
                    material = mtl->n ? ms_mtl_find(mtl, name) : MS_NO_MATERIAL;
                }
            } else if (ms_tok_is(tb, tn, "mtllib")) {
                const char *rb, *re;
                rest_of_line(p, e, &rb, &re);
                if (pass == 0 && obj_mtllib(rb, re, path, soup, mtl, err, errlen)) return -1;
            } else if (ms_tok_is(tb, tn, "cstype")) {
                in_cstype = 1;
                if (pass == 2 && !s->warned_cstype)
                    ms_warn("%s: line %zu: free-form geometry (cstype) is not read: left out", path, line);
                s->warned_cstype = 1;
            }
            /* l, p (no area), o, g, s, mg, vp, unknown statements: nothing to do */
        }
    }
    return 0;
}

int ms_mesh_obj(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen)
{
    *added = 0;
    if (memchr(buf, 0, len)) MS_FAIL("%s: not an OBJ text file (it contains a NUL byte)", path);
    int oom;
    char *joined = join_continuations(buf, len, &oom);
    if (oom) MS_FAIL("%s: out of memory", path);
    ms_mtl_lib mtl;
    memset(&mtl, 0, sizeof mtl);
    obj_state s;
    memset(&s, 0, sizeof s);
    ms_emit em;
    ms_emit_init(&em, soup, len, path);
    int rc = obj_read(joined ? joined : buf, len, path, soup, &mtl, &s, &em, err, errlen);
    *added = em.added;
    free(s.v);
    free(s.vd);
    free(s.vt);
    free(s.vn);
    free(joined);
    ms_mtl_lib_free(&mtl);
    return rc;
}
