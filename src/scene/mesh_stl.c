/* STL: binary when the file is exactly 84 + 50 * count bytes (whatever its 80-byte header says: many
 * binary files begin with "solid"), else ASCII: solid NAME, facets (facet normal x y z, outer loop,
 * vertex x y z per corner, endloop, endfacet), endsolid, any number of solids, tokens separated by any
 * white space, keywords in any case. The facet normal is each corner's vertex normal (as assimp gave it), unless it is zero or
 * not finite. A loop of more than three vertices is triangulated as a polygon.
 *
 * Bounded: the binary count is compared with the size in 64 bits; ASCII is one walk over the tokens. */
#include "mesh_reader.h"
#include "microshadow.h"
#include <math.h>
#include <string.h>
#include <strings.h>

/* Keywords in any case: some exporters write them in capitals. */
static int kw(const char *s, size_t n, const char *w) { return n == strlen(w) && !strncasecmp(s, w, n); }

static int space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

typedef struct stl_cur { const char *p, *end; size_t line; } stl_cur;

static int tok(stl_cur *s, const char **tb, size_t *tn)
{
    while (s->p < s->end && space(*s->p)) { s->line += *s->p == '\n'; s->p++; }
    *tb = s->p;
    while (s->p < s->end && !space(*s->p)) s->p++;
    *tn = (size_t)(s->p - *tb);
    return *tn > 0;
}

static const float *usable_normal(const float n[3], float n9[9])
{
    if (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2]) || (n[0] == 0 && n[1] == 0 && n[2] == 0)) return NULL;
    for (int k = 0; k < 3; k++) memcpy(n9 + 3 * k, n, 3 * sizeof(float));
    return n9;
}

static int binary(const unsigned char *b, uint32_t count, const char *path, ms_tri_soup *soup, size_t len,
                  size_t *added, char *err, size_t errlen)
{
    ms_emit em;
    ms_emit_init(&em, soup, len, path);
    for (uint32_t i = 0; i < count; i++) {
        const unsigned char *f = b + 84 + 50 * (size_t)i;
        float x[12];
        for (int k = 0; k < 12; k++) {
            const uint32_t u = (uint32_t)f[4 * k] | (uint32_t)f[4 * k + 1] << 8 | (uint32_t)f[4 * k + 2] << 16 |
                               (uint32_t)f[4 * k + 3] << 24;
            memcpy(&x[k], &u, 4);
        }
        float n9[9];
        if (ms_emit_tri(&em, x + 3, NULL, NULL, usable_normal(x, n9), MS_NO_MATERIAL, err, errlen)) { *added = em.added; return -1; }
    }
    *added = em.added;
    return 0;
}

int ms_mesh_stl(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen)
{
    *added = 0;
    uint32_t count = 0;
    if (len >= 84) {
        const unsigned char *u = (const unsigned char *)buf;
        count = (uint32_t)u[80] | (uint32_t)u[81] << 8 | (uint32_t)u[82] << 16 | (uint32_t)u[83] << 24;
        if ((uint64_t)count * 50 + 84 == len) {
            if (!count) MS_FAIL("%s: the binary STL has no triangles", path);
            return binary(u, count, path, soup, len, added, err, errlen);
        }
    }
    stl_cur s = { buf, buf + len, 1 };
    const char *tb;
    size_t tn;
    if (!tok(&s, &tb, &tn) || !kw(tb, tn, "solid")) {
        if (len >= 84 && (uint64_t)count * 50 + 84 > len)
            MS_FAIL("%s: binary STL declares %u triangles, more than its %zu bytes hold (malformed; not ASCII STL "
                    "either)", path, count, len);
        if (len >= 84)
            MS_FAIL("%s: binary STL of %u triangles takes %llu bytes, not %zu (malformed; not ASCII STL either)", path,
                    count, (unsigned long long)count * 50 + 84, len);
        MS_FAIL("%s: not an STL file (too short for binary STL, and not ASCII STL)", path);
    }
    ms_emit em;
    ms_emit_init(&em, soup, len, path);
#define SFAIL(...) do { *added = em.added; snprintf(err, errlen, __VA_ARGS__); return -1; } while (0)
#define EXPECT(w) do { if (!tok(&s, &tb, &tn) || !kw(tb, tn, w)) \
        SFAIL("%s: line %zu: expected '%s' (malformed ASCII STL)", path, s.line, w); } while (0)
#define NUMBER(x) do { if (!tok(&s, &tb, &tn) || ms_parse_real_f(tb, tn, &(x))) \
        SFAIL("%s: line %zu: expected a number (malformed ASCII STL)", path, s.line); } while (0)
    /* a position: also in double (the scene's frame is subtracted from it: scene_frame.c) */
#define COORD(x, xd) do { NUMBER(x); if (ms_parse_real_d(tb, tn, &(xd))) (xd) = (x); } while (0)
    for (;;) {
        /* solid NAME: the name is the rest of the line */
        while (s.p < s.end && *s.p != '\n' && *s.p != '\r') s.p++;
        for (;;) {
            if (!tok(&s, &tb, &tn)) SFAIL("%s: the file ends before 'endsolid' (malformed ASCII STL)", path);
            if (kw(tb, tn, "endsolid")) {
                while (s.p < s.end && *s.p != '\n' && *s.p != '\r') s.p++;
                break;
            }
            if (!kw(tb, tn, "facet")) SFAIL("%s: line %zu: expected 'facet' or 'endsolid' (malformed ASCII STL)", path, s.line);
            float nrm[3], pos[3 * MS_MAX_POLYGON];
            double posd[3 * MS_MAX_POLYGON];
            EXPECT("normal");
            NUMBER(nrm[0]); NUMBER(nrm[1]); NUMBER(nrm[2]);
            EXPECT("outer");
            EXPECT("loop");
            int n = 0;
            for (;;) {
                if (!tok(&s, &tb, &tn)) SFAIL("%s: the file ends inside a facet (malformed ASCII STL)", path);
                if (kw(tb, tn, "endloop")) break;
                if (!kw(tb, tn, "vertex")) SFAIL("%s: line %zu: expected 'vertex' or 'endloop' (malformed ASCII STL)", path, s.line);
                if (n == MS_MAX_POLYGON) SFAIL("%s: line %zu: a facet of more than %d vertices (over the limit)", path, s.line, MS_MAX_POLYGON);
                COORD(pos[3 * n], posd[3 * n]); COORD(pos[3 * n + 1], posd[3 * n + 1]); COORD(pos[3 * n + 2], posd[3 * n + 2]);
                n++;
            }
            EXPECT("endfacet");
            if (n < 3) SFAIL("%s: line %zu: a facet of %d vertices (malformed ASCII STL)", path, s.line, n);
            int tri[MS_MAX_POLYGON][3];
            const int nt = ms_triangulate(pos, n, tri);
            for (int t = 0; t < nt; t++) {
                float v[9], n9[9];
                double vd[9];
                for (int k = 0; k < 3; k++) memcpy(v + 3 * k, pos + 3 * tri[t][k], 3 * sizeof(float));
                for (int k = 0; k < 3; k++) memcpy(vd + 3 * k, posd + 3 * tri[t][k], 3 * sizeof(double));
                if (ms_emit_tri(&em, v, vd, NULL, usable_normal(nrm, n9), MS_NO_MATERIAL, err, errlen)) { *added = em.added; return -1; }
            }
        }
        if (!tok(&s, &tb, &tn)) break;
        if (!kw(tb, tn, "solid")) SFAIL("%s: line %zu: expected 'solid' after 'endsolid' (malformed ASCII STL)", path, s.line);
    }
    *added = em.added;
    return 0;
}
