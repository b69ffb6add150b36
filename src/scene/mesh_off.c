/* Object File Format (Geomview's OFF): the header keyword [ST][C][N][4][n]OFF (optional: a file may
 * start with its counts), then for nOFF the dimension, then NVertices NFaces [NEdges] (on the keyword's
 * line or the next); one vertex per line: the coordinates (3, or Ndim; one more, w, for 4OFF: divided
 * out), the normal (N), a colour (C: any count) and texture coordinates (ST: the last two numbers); one
 * face per line: its vertex count, 0-based indices, an optional colour. '#' starts a comment anywhere.
 * Polygons are triangulated as assimp did; faces of 1 or 2 vertices have no area. Binary OFF is refused.
 *
 * Bounded: the counts are checked against the bytes after them (a vertex line takes at least 6 bytes, a
 * face line 2) before the vertex array is allocated; faces at most MS_MAX_POLYGON vertices. */
#include "mesh_reader.h"
#include "microshadow.h"
#include <stdlib.h>
#include <string.h>

/* The next line with something on it before any '#': [*b, *e) with the comment cut. */
static int data_line(ms_text *c, const char **b, const char **e)
{
    while (ms_text_line(c, b, e)) {
        const char *h = memchr(*b, '#', (size_t)(*e - *b));
        if (h) *e = h;
        const char *p = *b, *tb;
        size_t tn;
        if (ms_text_token(&p, *e, &tb, &tn)) return 1;
    }
    return 0;
}

int ms_mesh_off(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen)
{
    *added = 0;
    if (memchr(buf, 0, len)) MS_FAIL("%s: not an OFF text file (it contains a NUL byte)", path);
    ms_text c = { buf, buf + len, 0 };
    const char *b, *e, *p, *tb = NULL;
    size_t tn = 0;
    if (!data_line(&c, &b, &e)) MS_FAIL("%s: the OFF file is empty", path);
    p = b;
    ms_text_token(&p, e, &tb, &tn);
    int st = 0, col = 0, nrm = 0, hom = 0, ndim = 0, dim = 3;
    int64_t cnt[3] = { 0, 0, 0 };
    int ncnt = 0;
    const char *k = tb, *ke = tb + tn;
    if (tn >= 3 && !memcmp(ke - 3, "OFF", 3)) {
        if (ke - k >= 5 && k[0] == 'S' && k[1] == 'T') { st = 1; k += 2; }
        if (k < ke - 3 && *k == 'C') { col = 1; k++; }
        if (k < ke - 3 && *k == 'N') { nrm = 1; k++; }
        if (k < ke - 3 && *k == '4') { hom = 1; k++; }
        if (k < ke - 3 && *k == 'n') { ndim = 1; k++; }
        if (k != ke - 3) MS_FAIL("%s: line %zu: unknown OFF keyword '%.*s' (malformed)", path, c.line, MS_TOKQ(tn), tb);
        if (ms_text_token(&p, e, &tb, &tn) && ms_tok_is(tb, tn, "BINARY"))
            MS_FAIL("%s: binary OFF is not supported", path);
        p = b;
        ms_text_token(&p, e, &tb, &tn);   /* past the keyword again: the counts may follow on its line */
    } else {
        p = b;   /* no keyword: the file starts with its counts */
    }
    /* The numbers of the header: Ndim (nOFF), then the two or three counts. */
    const int need = ndim ? 3 : 2;
    int64_t hv[4];
    int nh = 0;
    for (;;) {
        while (nh < 4 && ms_text_token(&p, e, &tb, &tn)) {
            if (ms_parse_int(tb, tn, &hv[nh]) || hv[nh] < 0)
                MS_FAIL("%s: line %zu: '%.*s' in the OFF header is not a count (malformed)", path, c.line, MS_TOKQ(tn), tb);
            nh++;
        }
        if (nh >= need) break;
        if (!data_line(&c, &b, &e)) MS_FAIL("%s: the OFF header has no counts (malformed)", path);
        p = b;
    }
    if (ndim) {
        dim = (int)hv[0];
        if (dim < 1 || dim > 3) MS_FAIL("%s: %lld-dimensional OFF vertices are not supported (1 to 3)", path, (long long)hv[0]);
    }
    for (int i = ndim; i < nh && ncnt < 3; i++) cnt[ncnt++] = hv[i];
    const int ncoord = dim + hom;
    const size_t rest = len - (size_t)(c.p - buf);
    if ((uint64_t)cnt[0] > rest / 6 || (uint64_t)cnt[1] > rest / 2 || (uint64_t)cnt[0] + (uint64_t)cnt[1] > rest / 2)
        MS_FAIL("%s: declares %lld vertices and %lld faces but only %zu bytes follow (malformed)", path,
                (long long)cnt[0], (long long)cnt[1], rest);
    const size_t nv = (size_t)cnt[0];
    float *pos = malloc((nv ? nv : 1) * 3 * sizeof(float));
    double *posd = malloc((nv ? nv : 1) * 3 * sizeof(double));   /* pos in double (scene_frame.c) */
    float *nor = nrm ? malloc((nv ? nv : 1) * 3 * sizeof(float)) : NULL;
    float *uvs = st ? malloc((nv ? nv : 1) * 2 * sizeof(float)) : NULL;
    int rc = -1;
    if (!pos || !posd || (nrm && !nor) || (st && !uvs)) { snprintf(err, errlen, "%s: out of memory", path); goto done; }
#define OFAIL(...) do { snprintf(err, errlen, __VA_ARGS__); goto done; } while (0)
    for (size_t v = 0; v < nv; v++) {
        if (!data_line(&c, &b, &e)) OFAIL("%s: the file ends after %zu of %zu vertices (malformed)", path, v, nv);
        float f[16];
        double fd[4] = { 0, 0, 0, 1 };
        int n = 0;
        p = b;
        while (ms_text_token(&p, e, &tb, &tn)) {
            float x;
            if (ms_parse_real_f(tb, tn, &x)) OFAIL("%s: line %zu: '%.*s' is not a number (malformed)", path, c.line, MS_TOKQ(tn), tb);
            if (n < 16) f[n] = x;
            if (n < 4 && ms_parse_real_d(tb, tn, &fd[n])) fd[n] = x;
            n++;
        }
        const int want = ncoord + 3 * nrm + 2 * st;
        if (n < want || n > want + 4)
            OFAIL("%s: line %zu: a vertex of %d numbers where %d%s are expected (malformed)", path, c.line, n, want,
                  col ? " and a colour" : "");
        float xyz[3] = { 0, 0, 0 };
        double xyzd[3] = { 0, 0, 0 };
        for (int i = 0; i < dim; i++) { xyz[i] = f[i]; xyzd[i] = fd[i]; }
        if (hom) {
            if (f[dim] == 0.0f) OFAIL("%s: line %zu: a homogeneous vertex with w = 0 (malformed)", path, c.line);
            for (int i = 0; i < 3; i++) xyz[i] /= f[dim];
            for (int i = 0; i < 3; i++) xyzd[i] /= fd[dim];
        }
        memcpy(pos + 3 * v, xyz, sizeof xyz);
        memcpy(posd + 3 * v, xyzd, sizeof xyzd);
        if (nrm) memcpy(nor + 3 * v, f + ncoord, 3 * sizeof(float));
        if (st) memcpy(uvs + 2 * v, f + (n - 2 < 16 ? n - 2 : 14), 2 * sizeof(float));
    }
    ms_emit em;
    ms_emit_init(&em, soup, len, path);
    for (int64_t fi = 0; fi < cnt[1]; fi++) {
        if (!data_line(&c, &b, &e)) OFAIL("%s: the file ends after %lld of %lld faces (malformed)", path, (long long)fi, (long long)cnt[1]);
        p = b;
        int64_t n, idx[MS_MAX_POLYGON];
        if (!ms_text_token(&p, e, &tb, &tn) || ms_parse_int(tb, tn, &n) || n < 0)
            OFAIL("%s: line %zu: a face must start with its vertex count (malformed)", path, c.line);
        if (n > MS_MAX_POLYGON) OFAIL("%s: line %zu: a face of %lld vertices (over the limit of %d)", path, c.line, (long long)n, MS_MAX_POLYGON);
        for (int64_t i = 0; i < n; i++)
            if (!ms_text_token(&p, e, &tb, &tn) || ms_parse_int(tb, tn, &idx[i]) || idx[i] < 0 || (uint64_t)idx[i] >= nv)
                OFAIL("%s: line %zu: the face's index %lld of %lld is missing or not in 0..%lld (malformed)", path, c.line,
                      (long long)i + 1, (long long)n, (long long)nv - 1);
        while (ms_text_token(&p, e, &tb, &tn)) {   /* the face's colour */
            float x;
            if (ms_parse_real_f(tb, tn, &x)) OFAIL("%s: line %zu: '%.*s' is not a number (malformed)", path, c.line, MS_TOKQ(tn), tb);
        }
        if (n < 3) continue;
        float fp[3 * MS_MAX_POLYGON];
        for (int64_t i = 0; i < n; i++) memcpy(fp + 3 * i, pos + 3 * idx[i], 3 * sizeof(float));
        int tri[MS_MAX_POLYGON][3];
        const int nt = ms_triangulate(fp, (int)n, tri);
        for (int t = 0; t < nt; t++) {
            float v[9], uv[6], nn[9];
            double vd[9];
            for (int q = 0; q < 3; q++) {
                const size_t vi = (size_t)idx[tri[t][q]];
                memcpy(v + 3 * q, pos + 3 * vi, 3 * sizeof(float));
                memcpy(vd + 3 * q, posd + 3 * vi, 3 * sizeof(double));
                if (nrm) memcpy(nn + 3 * q, nor + 3 * vi, 3 * sizeof(float));
                if (st) memcpy(uv + 2 * q, uvs + 2 * vi, 2 * sizeof(float));
            }
            if (ms_emit_tri(&em, v, vd, st ? uv : NULL, nrm ? nn : NULL, MS_NO_MATERIAL, err, errlen)) { *added = em.added; goto done; }
        }
    }
    *added = em.added;
    rc = 0;
done:
    free(pos);
    free(posd);
    free(nor);
    free(uvs);
    return rc;
}
