/* PLY 1.0, ascii and binary (both byte orders): the vertex element's x, y, z (any numeric type), nx, ny,
 * nz and u/v (or s/t, texture_u/texture_v, texture_s/texture_t); the face element's vertex_indices (or
 * vertex_index) list, polygons triangulated as assimp did; the tristrips element's strips (-1 restarts,
 * alternating winding, degenerate stitching triangles dropped). Every other element and property is
 * read past. List counts and indices may have any integer type.
 *
 * Bounded: each element's count is checked against the bytes after the header (its smallest instance
 * times its count) before anything is allocated; list lengths against the bytes left; faces at most
 * MS_MAX_POLYGON vertices. */
#include "mesh_reader.h"
#include "microshadow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;
static const struct { const char *name; ply_type t; } ply_types[] = {
    { "char", T_I8 }, { "int8", T_I8 }, { "uchar", T_U8 }, { "uint8", T_U8 }, { "short", T_I16 }, { "int16", T_I16 },
    { "ushort", T_U16 }, { "uint16", T_U16 }, { "int", T_I32 }, { "int32", T_I32 }, { "uint", T_U32 },
    { "uint32", T_U32 }, { "float", T_F32 }, { "float32", T_F32 }, { "double", T_F64 }, { "float64", T_F64 } };
static const int ply_size[] = { 0, 1, 1, 2, 2, 4, 4, 4, 8 };

static ply_type type_of(const char *s, size_t n)
{
    for (size_t i = 0; i < sizeof ply_types / sizeof ply_types[0]; i++)
        if (ms_tok_is(s, n, ply_types[i].name)) return ply_types[i].t;
    return T_NONE;
}

#define PLY_MAX_ELEMENTS 64
#define PLY_MAX_PROPS 256
/* role of a property: what it feeds */
enum { R_NONE, R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_U, R_V, R_INDICES };
typedef struct ply_prop { ply_type t, count_t; int is_list, role; } ply_prop;
typedef struct ply_elem {
    char name[64];
    uint64_t count;
    int np, kind;   /* kind: 0 other, 1 vertex, 2 face, 3 tristrips */
    ply_prop p[PLY_MAX_PROPS];
} ply_elem;
enum { PLY_ASCII, PLY_LE, PLY_BE };

typedef struct ply_body {
    const unsigned char *p, *end;
    int fmt;
    const char *path;
    double precise;   /* the last value read, ASCII reals in double (positions: scene_frame.c) */
} ply_body;

/* One value: integers into *iv (and *dv), reals into *dv; -1 when truncated or malformed. */
static int read_value(ply_body *r, ply_type t, int64_t *iv, double *dv)
{
    if (r->fmt == PLY_ASCII) {
        const char *s = (const char *)r->p, *e = (const char *)r->end;
        while (s < e && (ms_is_blank(*s) || *s == '\n' || *s == '\r' || *s == '\f')) s++;
        const char *tb = s;
        while (s < e && !(ms_is_blank(*s) || *s == '\n' || *s == '\r' || *s == '\f')) s++;
        r->p = (const unsigned char *)s;
        size_t tn = (size_t)(s - tb);
        if (tn == 0) return -1;
        if (t == T_F32) {
            float f;
            if (ms_parse_real_f(tb, tn, &f)) return -1;
            *dv = f;
            if (ms_parse_real_d(tb, tn, &r->precise)) r->precise = f;
            return 0;
        }
        if (t == T_F64) {
            if (ms_parse_real_d(tb, tn, dv)) return -1;
            r->precise = *dv;
            return 0;
        }
        if (ms_parse_int(tb, tn, iv)) return -1;
        *dv = (double)*iv;
        r->precise = *dv;
        return 0;
    }
    const size_t n = (size_t)ply_size[t];
    if ((size_t)(r->end - r->p) < n) return -1;
    uint64_t u = 0;
    for (size_t i = 0; i < n; i++) {
        const unsigned char byte = r->fmt == PLY_LE ? r->p[i] : r->p[n - 1 - i];
        u |= (uint64_t)byte << (8 * i);
    }
    r->p += n;
    switch (t) {
    case T_I8: *iv = (int8_t)u; break;
    case T_U8: case T_U16: case T_U32: *iv = (int64_t)u; break;
    case T_I16: *iv = (int16_t)u; break;
    case T_I32: *iv = (int32_t)u; break;
    case T_F32: { uint32_t w = (uint32_t)u; float f; memcpy(&f, &w, 4); *dv = f; return 0; }
    case T_F64: { double d; memcpy(&d, &u, 8); *dv = d; return 0; }
    default: return -1;
    }
    *dv = (double)*iv;
    return 0;
}

/* Bytes left (binary) or an upper bound on the values left (ascii: each takes 2 bytes but the last). */
static uint64_t values_left(const ply_body *r, ply_type t)
{
    const uint64_t b = (uint64_t)(r->end - r->p);
    return r->fmt == PLY_ASCII ? (b + 1) / 2 : b / (uint64_t)ply_size[t];
}

static int header(const char *buf, size_t len, const char *path, ply_elem *el, int *ne, int *fmt, size_t *body,
                  char *err, size_t errlen)
{
    ms_text c = { buf, buf + len, 0 };
    const char *b, *e, *p, *tb = NULL;
    size_t tn = 0;
    if (len < 4 || memcmp(buf, "ply", 3) || (buf[3] != '\n' && buf[3] != '\r')) MS_FAIL("%s: not a PLY file (no 'ply' line)", path);
    ms_text_line(&c, &b, &e);
    *fmt = -1;
    *ne = 0;
    ply_elem *cur = NULL;
    for (;;) {
        if (!ms_text_line(&c, &b, &e)) MS_FAIL("%s: the PLY header has no end_header line (malformed)", path);
        for (const char *q = b; q < e; q++)
            if ((unsigned char)*q < 0x20 && *q != '\t')
                MS_FAIL("%s: line %zu: control character 0x%02x in the PLY header (malformed)", path, c.line,
                        (unsigned char)*q);
        p = b;
        if (!ms_text_token(&p, e, &tb, &tn)) continue;
        if (ms_tok_is(tb, tn, "comment") || ms_tok_is(tb, tn, "obj_info")) continue;
        if (ms_tok_is(tb, tn, "end_header")) break;
        if (ms_tok_is(tb, tn, "format")) {
            if (*fmt >= 0 || !ms_text_token(&p, e, &tb, &tn)) MS_FAIL("%s: line %zu: malformed format line", path, c.line);
            *fmt = ms_tok_is(tb, tn, "ascii") ? PLY_ASCII : ms_tok_is(tb, tn, "binary_little_endian") ? PLY_LE
                 : ms_tok_is(tb, tn, "binary_big_endian") ? PLY_BE : -2;
            if (*fmt == -2) MS_FAIL("%s: line %zu: unknown PLY format '%.*s' (malformed)", path, c.line, MS_TOKQ(tn), tb);
            if (!ms_text_token(&p, e, &tb, &tn) || !ms_tok_is(tb, tn, "1.0"))
                MS_FAIL("%s: line %zu: only PLY version 1.0 exists", path, c.line);
            continue;
        }
        if (ms_tok_is(tb, tn, "element")) {
            if (*ne == PLY_MAX_ELEMENTS) MS_FAIL("%s: line %zu: more than %d PLY elements (over the limit)", path, c.line, PLY_MAX_ELEMENTS);
            cur = &el[(*ne)++];
            memset(cur, 0, sizeof *cur);
            if (!ms_text_token(&p, e, &tb, &tn)) MS_FAIL("%s: line %zu: malformed element line", path, c.line);
            snprintf(cur->name, sizeof cur->name, "%.*s", (int)(tn < sizeof cur->name ? tn : sizeof cur->name - 1), tb);
            int64_t cnt;
            if (!ms_text_token(&p, e, &tb, &tn) || ms_parse_int(tb, tn, &cnt) || cnt < 0)
                MS_FAIL("%s: line %zu: malformed element count", path, c.line);
            cur->count = (uint64_t)cnt;
            cur->kind = !strcmp(cur->name, "vertex") ? 1 : !strcmp(cur->name, "face") ? 2 : !strcmp(cur->name, "tristrips") ? 3 : 0;
            for (int i = 0; i < *ne - 1; i++)
                if (cur->kind && el[i].kind == cur->kind)
                    MS_FAIL("%s: line %zu: element '%s' declared twice (malformed)", path, c.line, cur->name);
            continue;
        }
        if (ms_tok_is(tb, tn, "property")) {
            if (!cur) MS_FAIL("%s: line %zu: a property before any element (malformed)", path, c.line);
            if (cur->np == PLY_MAX_PROPS) MS_FAIL("%s: line %zu: more than %d properties (over the limit)", path, c.line, PLY_MAX_PROPS);
            ply_prop *pr = &cur->p[cur->np++];
            memset(pr, 0, sizeof *pr);
            if (!ms_text_token(&p, e, &tb, &tn)) MS_FAIL("%s: line %zu: malformed property", path, c.line);
            if (ms_tok_is(tb, tn, "list")) {
                pr->is_list = 1;
                if (!ms_text_token(&p, e, &tb, &tn) || (pr->count_t = type_of(tb, tn)) == T_NONE ||
                    pr->count_t == T_F32 || pr->count_t == T_F64)
                    MS_FAIL("%s: line %zu: a list count must have an integer type (malformed)", path, c.line);
                if (!ms_text_token(&p, e, &tb, &tn)) MS_FAIL("%s: line %zu: malformed property", path, c.line);
            }
            if ((pr->t = type_of(tb, tn)) == T_NONE) MS_FAIL("%s: line %zu: unknown property type '%.*s'", path, c.line, MS_TOKQ(tn), tb);
            if (!ms_text_token(&p, e, &tb, &tn)) MS_FAIL("%s: line %zu: property without a name", path, c.line);
            if (cur->kind == 1 && !pr->is_list) {
                static const struct { const char *n; int r; } names[] = {
                    { "x", R_X }, { "y", R_Y }, { "z", R_Z }, { "nx", R_NX }, { "ny", R_NY }, { "nz", R_NZ },
                    { "u", R_U }, { "v", R_V }, { "s", R_U }, { "t", R_V }, { "texture_u", R_U }, { "texture_v", R_V },
                    { "texture_s", R_U }, { "texture_t", R_V } };
                for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
                    if (ms_tok_is(tb, tn, names[i].n)) pr->role = names[i].r;
                for (int i = 0; i < cur->np - 1; i++)
                    if (pr->role && cur->p[i].role == pr->role) pr->role = R_NONE;   /* the first one counts */
            }
            if ((cur->kind == 2 || cur->kind == 3) && pr->is_list &&
                (ms_tok_is(tb, tn, "vertex_indices") || ms_tok_is(tb, tn, "vertex_index"))) {
                if (pr->t == T_F32 || pr->t == T_F64)
                    MS_FAIL("%s: line %zu: vertex indices must have an integer type (malformed)", path, c.line);
                for (int i = 0; i < cur->np - 1; i++)
                    if (cur->p[i].role == R_INDICES) MS_FAIL("%s: line %zu: two vertex index lists (malformed)", path, c.line);
                pr->role = R_INDICES;
            }
            continue;
        }
        MS_FAIL("%s: line %zu: unknown PLY header line '%.*s' (malformed)", path, c.line, MS_TOKQ(tn), tb);
    }
    if (*fmt < 0) MS_FAIL("%s: the PLY header has no format line (malformed)", path);
    *body = (size_t)(c.p - buf);
    /* A binary body starts after end_header's line end: \n, \r\n or \r (ms_text_line took it). */
    return 0;
}

typedef struct ply_data {
    float *pos, *nrm, *uv;
    double *posd;           /* pos as exact as the file gives it (scene_frame.c) */
    uint64_t nv;
    uint32_t *idx;          /* face lists and strips as read: [count, i0, i1, ...] runs */
    size_t nidx, cap;
    int has_n, has_uv;
} ply_data;

static int push_idx(ply_data *d, uint32_t v)
{
    if (d->nidx == d->cap) {
        size_t cap = d->cap ? 2 * d->cap : 4096;
        uint32_t *t = realloc(d->idx, cap * sizeof *t);
        if (!t) return -1;
        d->idx = t;
        d->cap = cap;
    }
    d->idx[d->nidx++] = v;
    return 0;
}

static int body(const char *buf, size_t len, size_t off, const char *path, const ply_elem *el, int ne, int fmt,
                ply_data *d, char *err, size_t errlen)
{
    ply_body r = { (const unsigned char *)buf + off, (const unsigned char *)buf + len, fmt, path, 0.0 };
    const uint64_t bytes = (uint64_t)(len - off);
    /* Counts against the bytes present: every instance takes at least its smallest size. */
    for (int i = 0; i < ne; i++) {
        uint64_t min = 0;
        for (int j = 0; j < el[i].np; j++)
            min += fmt == PLY_ASCII ? 2 : (uint64_t)ply_size[el[i].p[j].is_list ? el[i].p[j].count_t : el[i].p[j].t];
        if (min == 0) min = 1;
        if (el[i].count > bytes / min)
            MS_FAIL("%s: element '%s' declares %llu instances but only %llu bytes follow the header (malformed)", path,
                    el[i].name, (unsigned long long)el[i].count, (unsigned long long)bytes);
    }
    for (int i = 0; i < ne; i++) {
        const ply_elem *E = &el[i];
        if (E->kind == 1) {
            int roles = 0;
            for (int j = 0; j < E->np; j++) roles |= 1 << E->p[j].role;
            if ((roles & (1 << R_X | 1 << R_Y | 1 << R_Z)) != (1 << R_X | 1 << R_Y | 1 << R_Z))
                MS_FAIL("%s: the PLY vertex element lacks an x, y or z property (malformed)", path);
            d->has_n = (roles & (1 << R_NX | 1 << R_NY | 1 << R_NZ)) == (1 << R_NX | 1 << R_NY | 1 << R_NZ);
            d->has_uv = (roles & (1 << R_U | 1 << R_V)) == (1 << R_U | 1 << R_V);
            d->nv = E->count;
            const size_t n = E->count ? (size_t)E->count : 1;
            d->pos = malloc(n * 3 * sizeof(float));
            d->posd = malloc(n * 3 * sizeof(double));
            if (d->has_n) d->nrm = malloc(n * 3 * sizeof(float));
            if (d->has_uv) d->uv = malloc(n * 2 * sizeof(float));
            if (!d->pos || !d->posd || (d->has_n && !d->nrm) || (d->has_uv && !d->uv)) MS_FAIL("%s: out of memory", path);
        }
        for (uint64_t k = 0; k < E->count; k++) {
            for (int j = 0; j < E->np; j++) {
                const ply_prop *pr = &E->p[j];
                int64_t iv = 0;
                double dv = 0;
                if (!pr->is_list) {
                    if (read_value(&r, pr->t, &iv, &dv))
                        MS_FAIL("%s: %s %llu: truncated or malformed value", path, E->name, (unsigned long long)k);
                    const float f = (float)dv;
                    switch (pr->role) {
                    case R_X: case R_Y: case R_Z:
                        d->pos[3 * k + (size_t)(pr->role - R_X)] = f;
                        d->posd[3 * k + (size_t)(pr->role - R_X)] = r.fmt == PLY_ASCII ? r.precise : dv;
                        break;
                    case R_NX: case R_NY: case R_NZ: if (d->has_n) d->nrm[3 * k + (size_t)(pr->role - R_NX)] = f; break;
                    case R_U: case R_V: if (d->has_uv) d->uv[2 * k + (size_t)(pr->role - R_U)] = f; break;
                    default: break;
                    }
                    continue;
                }
                int64_t n;
                if (read_value(&r, pr->count_t, &n, &dv))
                    MS_FAIL("%s: %s %llu: truncated or malformed list count", path, E->name, (unsigned long long)k);
                if (n < 0 || (uint64_t)n > values_left(&r, pr->t))
                    MS_FAIL("%s: %s %llu: truncated: a list of %lld entries where %llu bytes are left (malformed)", path, E->name,
                            (unsigned long long)k, (long long)n, (unsigned long long)(r.end - r.p));
                const int keep = pr->role == R_INDICES;
                if (keep && E->kind == 2 && n > MS_MAX_POLYGON)
                    MS_FAIL("%s: face %llu: a face of %lld vertices (over the limit of %d)", path, (unsigned long long)k,
                            (long long)n, MS_MAX_POLYGON);
                if (keep && push_idx(d, (uint32_t)n)) MS_FAIL("%s: out of memory", path);
                for (int64_t m = 0; m < n; m++) {
                    if (read_value(&r, pr->t, &iv, &dv))
                        MS_FAIL("%s: %s %llu: truncated or malformed value", path, E->name, (unsigned long long)k);
                    if (!keep) continue;
                    /* -1 (or the largest value of an unsigned type) restarts a strip */
                    const int restart = E->kind == 3 &&
                        (iv == -1 || (pr->t == T_U8 && iv == 0xff) || (pr->t == T_U16 && iv == 0xffff) ||
                         (pr->t == T_U32 && iv == 0xffffffffLL));
                    if (!restart && (iv < 0 || iv >= (int64_t)UINT32_MAX))
                        MS_FAIL("%s: %s %llu: vertex index %lld is negative or too large (malformed)", path, E->name,
                                (unsigned long long)k, (long long)iv);
                    if (push_idx(d, restart ? UINT32_MAX : (uint32_t)iv)) MS_FAIL("%s: out of memory", path);
                }
                if (keep && E->kind == 3) {   /* strips: the count marks the run; keep it apart from faces */
                    d->idx[d->nidx - (size_t)n - 1] = (uint32_t)n | 0x80000000u;
                }
            }
        }
    }
    if (fmt == PLY_ASCII) {
        const char *s = (const char *)r.p, *e = (const char *)r.end;
        while (s < e && (ms_is_blank(*s) || *s == '\n' || *s == '\r' || *s == '\f')) s++;
        if (s < e) MS_FAIL("%s: more values than the PLY header declares (malformed)", path);
    }
    if (!d->pos) MS_FAIL("%s: the PLY file has no vertex element (malformed)", path);
    return 0;
}

static int corner(const ply_data *d, uint32_t v, float *p, float *uv, float *n)
{
    memcpy(p, d->pos + 3 * (size_t)v, 3 * sizeof(float));
    if (d->has_uv) memcpy(uv, d->uv + 2 * (size_t)v, 2 * sizeof(float));
    if (d->has_n) memcpy(n, d->nrm + 3 * (size_t)v, 3 * sizeof(float));
    return 0;
}

static int emit(const ply_data *d, const uint32_t *c, ms_emit *em, char *err, size_t errlen)
{
    float v[9], uv[6], n[9];
    double vd[9];
    for (int k = 0; k < 3; k++) corner(d, c[k], v + 3 * k, uv + 2 * k, n + 3 * k);
    for (int k = 0; k < 3; k++) memcpy(vd + 3 * k, d->posd + 3 * (size_t)c[k], 3 * sizeof(double));
    return ms_emit_tri(em, v, vd, d->has_uv ? uv : NULL, d->has_n ? n : NULL, MS_NO_MATERIAL, err, errlen);
}

static int triangles(const ply_data *d, const char *path, ms_emit *em, char *err, size_t errlen)
{
    size_t i = 0, face = 0;
    while (i < d->nidx) {
        const uint32_t head = d->idx[i++];
        const size_t n = head & 0x7fffffffu;
        const uint32_t *l = d->idx + i;
        i += n;
        for (size_t k = 0; k < n; k++)
            if (l[k] != UINT32_MAX && l[k] >= d->nv)
                MS_FAIL("%s: %s %zu: vertex index %u is not in 0..%llu (malformed)", path, head >> 31 ? "strip" : "face",
                        face, l[k], (unsigned long long)(d->nv ? d->nv - 1 : 0));
        if (head >> 31) {   /* a strip list: runs between restarts, every other triangle turned */
            size_t run = 0;
            for (size_t k = 0; k < n; k++) {
                if (l[k] == UINT32_MAX) { run = 0; continue; }
                if (++run < 3) continue;
                const uint32_t a = l[k - 2], b = l[k - 1], c = l[k];
                if (a == b || b == c || a == c) continue;   /* stitching between strips */
                const uint32_t t[3] = { run % 2 ? a : b, run % 2 ? b : a, c };
                if (emit(d, t, em, err, errlen)) return -1;
            }
        } else if (n >= 3) {
            float pos[3 * MS_MAX_POLYGON];
            for (size_t k = 0; k < n; k++) memcpy(pos + 3 * k, d->pos + 3 * (size_t)l[k], 3 * sizeof(float));
            int tri[MS_MAX_POLYGON][3];
            const int nt = ms_triangulate(pos, (int)n, tri);
            for (int t = 0; t < nt; t++) {
                const uint32_t c[3] = { l[tri[t][0]], l[tri[t][1]], l[tri[t][2]] };
                if (emit(d, c, em, err, errlen)) return -1;
            }
        }
        face++;
    }
    return 0;
}

int ms_mesh_ply(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen)
{
    *added = 0;
    ply_elem *el = malloc(PLY_MAX_ELEMENTS * sizeof *el);
    if (!el) MS_FAIL("%s: out of memory", path);
    int ne, fmt, rc;
    size_t off;
    ply_data d;
    memset(&d, 0, sizeof d);
    rc = header(buf, len, path, el, &ne, &fmt, &off, err, errlen);
    if (!rc) rc = body(buf, len, off, path, el, ne, fmt, &d, err, errlen);
    if (!rc) {
        ms_emit em;
        ms_emit_init(&em, soup, len, path);
        rc = triangles(&d, path, &em, err, errlen);
        *added = em.added;
    }
    free(el);
    free(d.pos);
    free(d.posd);
    free(d.nrm);
    free(d.uv);
    free(d.idx);
    return rc;
}
