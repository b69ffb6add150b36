/* Structural checks before assimp: a strict grammar for each text format and a full walk of binary
 * PLY/STL bodies, so that assimp only ever sees files whose declared counts match the bytes present,
 * whose indices are in range and whose polygons are small. Stricter than the formats allow in places
 * (no OBJ line continuations, plain OFF only): what is refused gets a line naming file, line and cause. */
#include "scene_internal.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define FAIL(...) do { snprintf(err, errlen, __VA_ARGS__); return -1; } while (0)

/* A line of text: [b, e), 1-based number. */
typedef struct text_cursor { const char *p, *end; size_t line; } text_cursor;

static int is_eol(char c) { return c == '\n' || c == '\r' || c == '\f'; }
static int is_blank(char c) { return c == ' ' || c == '\t'; }

/* Next line, split at \n, \r or \f (as assimp's text readers do); empty lines are returned too. */
static int next_line(text_cursor *c, const char **b, const char **e)
{
    if (c->p >= c->end) return 0;
    *b = c->p;
    while (c->p < c->end && !is_eol(*c->p)) c->p++;
    *e = c->p;
    if (c->p < c->end) {
        if (*c->p == '\r' && c->p + 1 < c->end && c->p[1] == '\n') c->p++;
        c->p++;
    }
    c->line++;
    return 1;
}

/* Next blank-separated token of [*p, e); 0 at the end of the line. */
static int next_token(const char **p, const char *e, const char **tb, size_t *tn)
{
    const char *s = *p;
    while (s < e && is_blank(*s)) s++;
    if (s == e) { *p = s; return 0; }
    *tb = s;
    while (s < e && !is_blank(*s)) s++;
    *tn = (size_t)(s - *tb);
    *p = s;
    return 1;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* A decimal number as every assimp reader parses it alike: [+-]digits[.digits][e[+-]digits], or
 * nan/inf (the loader reports those as non-finite). */
static int number_token(const char *s, size_t n)
{
    size_t i = 0;
    if (n >= 3 && n <= 4) {
        size_t k = (s[0] == '-' || s[0] == '+') && n == 4;
        if ((n - k) == 3 && (!strncasecmp(s + k, "nan", 3) || !strncasecmp(s + k, "inf", 3))) return 1;
    }
    if (i < n && (s[i] == '+' || s[i] == '-')) i++;
    size_t d = 0;
    while (i < n && is_digit(s[i])) { i++; d++; }
    if (d == 0) return 0;
    if (i < n && s[i] == '.') {
        i++;
        while (i < n && is_digit(s[i])) i++;
    }
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-')) i++;
        size_t ed = 0;
        while (i < n && is_digit(s[i])) { i++; ed++; }
        if (ed == 0 || ed > 4) return 0;
    }
    return i == n;
}

/* An unsigned decimal of at most 10 digits, no sign, no leading zeros beyond "0"; *v its value. */
static int uint_token(const char *s, size_t n, uint64_t *v)
{
    if (n == 0 || n > 10 || (n > 1 && s[0] == '0')) return 0;
    uint64_t x = 0;
    for (size_t i = 0; i < n; i++) {
        if (!is_digit(s[i])) return 0;
        x = 10 * x + (uint64_t)(s[i] - '0');
    }
    *v = x;
    return 1;
}

static int tok_is(const char *s, size_t n, const char *word) { return n == strlen(word) && !memcmp(s, word, n); }

static int has_nul(const char *buf, size_t len) { return memchr(buf, 0, len) != NULL; }

/* ---------------------------------------------------------------- OBJ
 * Mirrors the dispatch of assimp's ObjFileParser (first character of the line, no leading blanks),
 * requiring every statement it acts on to be well-formed. */

/* One index of an f/l/p token: -?[1-9][0-9]{0,8}, resolved against count (negative: relative). */
static int obj_index(const char *s, size_t n, uint64_t count)
{
    size_t i = n && s[0] == '-';   /* -k is the k-th last: the same range */
    if (i >= n || n - i > 9 || s[i] == '0') return 0;
    uint64_t v = 0;
    for (; i < n; i++) {
        if (!is_digit(s[i])) return 0;
        v = 10 * v + (uint64_t)(s[i] - '0');
    }
    return v <= count;   /* 1..count, or -1..-count */
}

int ms_preflight_obj(const char *buf, size_t len, const char *path, char *err, size_t errlen)
{
    if (has_nul(buf, len)) FAIL("%s: not an OBJ text file (it contains a NUL byte)", path);
    text_cursor c = { buf, buf + len, 0 };
    const char *b, *e;
    uint64_t nv = 0, nvt = 0, nvn = 0;
    int file_form = -1;   /* assimp indexes normals and texture coordinates of every face alike */
    while (next_line(&c, &b, &e)) {
        if (b == e) continue;
        if (e[-1] == '\\') FAIL("%s: line %zu: line continuations ('\\' at the end) are not supported", path, c.line);
        const char *p = b, *tb = b;
        size_t tn = 0;
        switch (*b) {
        case 'v': {
            if (!next_token(&p, e, &tb, &tn)) break;
            int kind = tok_is(tb, tn, "v") ? 0 : tok_is(tb, tn, "vt") ? 1 : tok_is(tb, tn, "vn") ? 2 : -1;
            if (kind < 0) {
                /* assimp reads "v<blank>", "vt" and "vn" by their first two characters. */
                if (tn >= 2 && (tb[1] == 't' || tb[1] == 'n'))
                    FAIL("%s: line %zu: unknown statement '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
                break;
            }
            int k = 0;
            while (next_token(&p, e, &tb, &tn)) {
                if (!number_token(tb, tn)) FAIL("%s: line %zu: '%.*s' is not a number", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
                k++;
            }
            if (kind == 0 && k != 3 && k != 4 && k != 6) FAIL("%s: line %zu: a vertex needs 3, 4 or 6 numbers, not %d", path, c.line, k);
            if (kind == 1 && k != 2 && k != 3) FAIL("%s: line %zu: a texture coordinate needs 2 or 3 numbers, not %d", path, c.line, k);
            if (kind == 2 && k != 3) FAIL("%s: line %zu: a normal needs 3 numbers, not %d", path, c.line, k);
            if (kind == 0) nv++; else if (kind == 1) nvt++; else nvn++;
            break;
        }
        case 'f': case 'l': case 'p': {
            next_token(&p, e, &tb, &tn);
            if (!tok_is(tb, tn, "f") && !tok_is(tb, tn, "l") && !tok_is(tb, tn, "p"))
                FAIL("%s: line %zu: unknown statement '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
            char kind = *b;
            int n = 0, form = -1;   /* form: which of v, v/vt, v//vn, v/vt/vn every vertex uses */
            while (next_token(&p, e, &tb, &tn)) {
                const char *s1 = memchr(tb, '/', tn);
                const char *s2 = s1 ? memchr(s1 + 1, '/', (size_t)(tb + tn - s1 - 1)) : NULL;
                if (s2 && memchr(s2 + 1, '/', (size_t)(tb + tn - s2 - 1))) FAIL("%s: line %zu: malformed vertex '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
                size_t n0 = s1 ? (size_t)(s1 - tb) : tn;
                size_t n1 = s1 ? (size_t)((s2 ? s2 : tb + tn) - s1 - 1) : 0;
                size_t n2 = s2 ? (size_t)(tb + tn - s2 - 1) : 0;
                int f = !s1 ? 0 : !s2 ? 1 : n1 == 0 ? 2 : 3;
                if ((s1 && !s2 && n1 == 0) || (s2 && n2 == 0) || (kind == 'p' && s1))
                    FAIL("%s: line %zu: malformed vertex '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
                if (form >= 0 && f != form) FAIL("%s: line %zu: the vertices of a face mix index forms", path, c.line);
                form = f;
                if (!obj_index(tb, n0, nv)) FAIL("%s: line %zu: vertex index '%.*s' is not in 1..%llu (or -1..-%llu)", path, c.line, (int)(n0 > 32 ? 32 : n0), tb, (unsigned long long)nv, (unsigned long long)nv);
                if ((f == 1 || f == 3) && !obj_index(s1 + 1, n1, nvt)) FAIL("%s: line %zu: texture index '%.*s' is not in 1..%llu", path, c.line, (int)(n1 > 32 ? 32 : n1), s1 + 1, (unsigned long long)nvt);
                if ((f == 2 || f == 3) && !obj_index(s2 + 1, n2, nvn)) FAIL("%s: line %zu: normal index '%.*s' is not in 1..%llu", path, c.line, (int)(n2 > 32 ? 32 : n2), s2 + 1, (unsigned long long)nvn);
                if (++n > MS_MAX_POLYGON) FAIL("%s: line %zu: a face with more than %d vertices", path, c.line, MS_MAX_POLYGON);
            }
            if (file_form >= 0 && form >= 0 && form != file_form)
                FAIL("%s: line %zu: faces mix index forms (v, v/vt, v//vn, v/vt/vn) within the file", path, c.line);
            if (form >= 0) file_form = form;
            int need = kind == 'f' ? 3 : kind == 'l' ? 2 : 1;
            if (n < need) FAIL("%s: line %zu: '%c' needs at least %d vertices, not %d", path, c.line, kind, need, n);
            break;
        }
        case 'c':
            if (next_token(&p, e, &tb, &tn) && tok_is(tb, tn, "cstype"))
                FAIL("%s: line %zu: free-form geometry (cstype) is not supported", path, c.line);
            break;
        default:
            break;   /* comments, names, groups, materials: assimp skips or just records them */
        }
    }
    return 0;
}

/* ---------------------------------------------------------------- PLY */

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;
static const struct { const char *name; ply_type t; } ply_types[] = {
    { "char", T_I8 }, { "int8", T_I8 }, { "uchar", T_U8 }, { "uint8", T_U8 }, { "short", T_I16 }, { "int16", T_I16 },
    { "ushort", T_U16 }, { "uint16", T_U16 }, { "int", T_I32 }, { "int32", T_I32 }, { "uint", T_U32 },
    { "uint32", T_U32 }, { "float", T_F32 }, { "float32", T_F32 }, { "double", T_F64 }, { "float64", T_F64 } };
static const int ply_size[] = { 0, 1, 1, 2, 2, 4, 4, 4, 8 };

static ply_type ply_type_of(const char *s, size_t n)
{
    for (size_t i = 0; i < sizeof ply_types / sizeof ply_types[0]; i++)
        if (tok_is(s, n, ply_types[i].name)) return ply_types[i].t;
    return T_NONE;
}

#define PLY_MAX_ELEMENTS 16
#define PLY_MAX_PROPS 64
typedef struct ply_prop { ply_type t, count_t; int is_list, is_index; } ply_prop;
typedef struct ply_elem { char name[32]; uint64_t count; int np, is_vertex, is_face, xyz; ply_prop p[PLY_MAX_PROPS]; } ply_elem;

/* The body reader: binary (either byte order) or ASCII tokens, one instance per line. */
typedef struct ply_body { const unsigned char *p, *end; int fmt; text_cursor tc; const char *lb, *le; } ply_body;
enum { PLY_ASCII, PLY_LE, PLY_BE };

static int ply_read(ply_body *r, ply_type t, int64_t *iv)
{
    if (r->fmt == PLY_ASCII) {
        const char *tb = NULL;
        size_t tn = 0;
        if (!next_token(&r->lb, r->le, &tb, &tn)) return -1;
        if (t == T_F32 || t == T_F64) return number_token(tb, tn) ? 0 : -1;
        size_t i = tb[0] == '-';
        uint64_t v;
        if (!uint_token(tb + i, tn - i, &v)) return -1;
        *iv = i ? -(int64_t)v : (int64_t)v;
        return 0;
    }
    size_t n = (size_t)ply_size[t];
    if ((size_t)(r->end - r->p) < n) return -1;
    uint64_t u = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char byte = r->fmt == PLY_LE ? r->p[i] : r->p[n - 1 - i];
        u |= (uint64_t)byte << (8 * i);
    }
    r->p += n;
    switch (t) {
    case T_I8: *iv = (int8_t)u; break;
    case T_U8: case T_U16: case T_U32: *iv = (int64_t)u; break;
    case T_I16: *iv = (int16_t)u; break;
    case T_I32: *iv = (int32_t)u; break;
    default: break;
    }
    return 0;
}

int ms_preflight_ply(const char *buf, size_t len, const char *path, char *err, size_t errlen)
{
    text_cursor c = { buf, buf + len, 0 };
    const char *b, *e, *p, *tb = NULL;
    size_t tn = 0;
    if (len < 4 || memcmp(buf, "ply", 3) || (buf[3] != '\n' && buf[3] != '\r')) FAIL("%s: not a PLY file (no 'ply' line)", path);
    next_line(&c, &b, &e);
    int fmt = -1, ne = 0, crlf = buf[3] == '\r';
    ply_elem el[PLY_MAX_ELEMENTS];
    ply_elem *cur = NULL;
    for (;;) {
        if (!next_line(&c, &b, &e)) FAIL("%s: the PLY header has no end_header line", path);
        p = b;
        if (!next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: empty line in the PLY header", path, c.line);
        if (tok_is(tb, tn, "comment") || tok_is(tb, tn, "obj_info")) continue;
        if (tok_is(tb, tn, "end_header")) {
            if (next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: text after end_header", path, c.line);
            break;
        }
        if ((c.line == 2) != tok_is(tb, tn, "format"))
            FAIL("%s: line %zu: the format line must be the second line of a PLY file", path, c.line);
        if (tok_is(tb, tn, "format")) {
            if (fmt >= 0 || !next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: malformed format line", path, c.line);
            fmt = tok_is(tb, tn, "ascii") ? PLY_ASCII : tok_is(tb, tn, "binary_little_endian") ? PLY_LE
                : tok_is(tb, tn, "binary_big_endian") ? PLY_BE : -2;
            if (fmt == -2) FAIL("%s: line %zu: unknown PLY format '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
            if (!next_token(&p, e, &tb, &tn) || !tok_is(tb, tn, "1.0") || next_token(&p, e, &tb, &tn))
                FAIL("%s: line %zu: only PLY version 1.0 is supported", path, c.line);
            continue;
        }
        if (tok_is(tb, tn, "element")) {
            if (ne == PLY_MAX_ELEMENTS) FAIL("%s: line %zu: more than %d PLY elements", path, c.line, PLY_MAX_ELEMENTS);
            cur = &el[ne++];
            memset(cur, 0, sizeof *cur);
            if (!next_token(&p, e, &tb, &tn) || tn >= sizeof cur->name) FAIL("%s: line %zu: malformed element line", path, c.line);
            memcpy(cur->name, tb, tn);
            cur->name[tn] = 0;
            if (!next_token(&p, e, &tb, &tn) || !uint_token(tb, tn, &cur->count) || next_token(&p, e, &tb, &tn))
                FAIL("%s: line %zu: malformed element count", path, c.line);
            cur->is_vertex = !strcmp(cur->name, "vertex");
            cur->is_face = !strcmp(cur->name, "face");
            /* assimp reads the count of an element it does not know from the element's name ("element
             * 77facE 2" declares 77 instances there), and gives tristrips and materials meaning we do not
             * check: only these three are read alike by both. */
            if (!cur->is_vertex && !cur->is_face && strcmp(cur->name, "edge"))
                FAIL("%s: line %zu: PLY element '%.31s' is not supported (only vertex, face, edge)", path, c.line, cur->name);
            for (int i = 0; i < ne - 1; i++)
                if (!strcmp(el[i].name, cur->name)) FAIL("%s: line %zu: element '%s' declared twice", path, c.line, cur->name);
            continue;
        }
        if (tok_is(tb, tn, "property")) {
            if (!cur) FAIL("%s: line %zu: a property before any element", path, c.line);
            if (cur->np == PLY_MAX_PROPS) FAIL("%s: line %zu: more than %d properties", path, c.line, PLY_MAX_PROPS);
            ply_prop *pr = &cur->p[cur->np++];
            memset(pr, 0, sizeof *pr);
            if (!next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: malformed property", path, c.line);
            if (tok_is(tb, tn, "list")) {
                pr->is_list = 1;
                if (!next_token(&p, e, &tb, &tn) || (pr->count_t = ply_type_of(tb, tn)) == T_NONE ||
                    pr->count_t == T_F32 || pr->count_t == T_F64)
                    FAIL("%s: line %zu: a list count must have an integer type", path, c.line);
                if (!next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: malformed property", path, c.line);
            }
            if ((pr->t = ply_type_of(tb, tn)) == T_NONE)
                FAIL("%s: line %zu: unknown property type", path, c.line);
            if (!next_token(&p, e, &tb, &tn) || tn > 64) FAIL("%s: line %zu: property without a name", path, c.line);
            if (next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: text after the property name", path, c.line);
            if (cur->is_vertex && !pr->is_list && tn == 1 && *tb >= 'x' && *tb <= 'z') cur->xyz |= 1 << (*tb - 'x');
            int idx = tok_is(tb, tn, "vertex_indices") || tok_is(tb, tn, "vertex_index");
            if (pr->is_list && cur->is_face) {
                if (!idx) FAIL("%s: line %zu: face list '%.*s' is not supported (only vertex_indices)", path, c.line, (int)tn, tb);
                if (pr->t == T_F32 || pr->t == T_F64) FAIL("%s: line %zu: vertex_indices must have an integer type", path, c.line);
                pr->is_index = 1;
            }
            if (cur->is_face && tok_is(tb, tn, "material_index")) FAIL("%s: line %zu: material_index is not supported", path, c.line);
            if (cur->is_vertex && pr->is_list) FAIL("%s: line %zu: list properties of vertices are not supported", path, c.line);
            continue;
        }
        FAIL("%s: line %zu: unknown PLY header line '%.*s'", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
    }
    if (fmt < 0) FAIL("%s: the PLY header has no format line", path);
    if (fmt != PLY_ASCII && crlf) FAIL("%s: binary PLY with CRLF header lines is ambiguous", path);
    const ply_elem *vert = NULL;
    for (int i = 0; i < ne; i++) {
        if (el[i].is_vertex) vert = &el[i];
        if (el[i].np == 0 && el[i].count) FAIL("%s: element '%s' has no properties", path, el[i].name);
    }
    if (!vert) FAIL("%s: the PLY file has no vertex element", path);
    if (vert->xyz != 7) FAIL("%s: the PLY vertex element lacks an x, y or z property", path);
    /* Declared counts against the bytes present, before walking them: every instance takes a byte. */
    size_t body = len - (size_t)(c.p - buf);
    for (int i = 0; i < ne; i++)
        if (el[i].count > body)
            FAIL("%s: element '%s' declares %llu instances but only %zu bytes follow the header", path, el[i].name,
                 (unsigned long long)el[i].count, body);
    /* assimp's header reader consumes line ends after end_header even in binary files, so a body
     * starting with one would be read shifted by a byte from what is checked here. */
    if (fmt != PLY_ASCII && c.p < buf + len && (*c.p == '\n' || *c.p == '\r'))
        FAIL("%s: the binary PLY body starts with a line-end byte (ambiguous after end_header)", path);
    ply_body r = { (const unsigned char *)c.p, (const unsigned char *)buf + len, fmt, c, NULL, NULL };
    for (int i = 0; i < ne; i++) {
        for (uint64_t k = 0; k < el[i].count; k++) {
            if (fmt == PLY_ASCII) {
                if (!next_line(&r.tc, &r.lb, &r.le))
                    FAIL("%s: the file ends in %s %llu of %llu", path, el[i].name, (unsigned long long)k, (unsigned long long)el[i].count);
                if (r.lb == r.le) FAIL("%s: line %zu: an empty line in the PLY body", path, r.tc.line);
            }
            for (int j = 0; j < el[i].np; j++) {
                const ply_prop *pr = &el[i].p[j];
                int64_t n = 1, v = 0;
                if (pr->is_list) {
                    if (ply_read(&r, pr->count_t, &n))
                        FAIL("%s: %s %llu: truncated or malformed list count", path, el[i].name, (unsigned long long)k);
                    if (n < 0 || n > MS_MAX_POLYGON)
                        FAIL("%s: %s %llu: a list of %lld entries (at most %d)", path, el[i].name, (unsigned long long)k, (long long)n, MS_MAX_POLYGON);
                    if (pr->is_index && n < 3)
                        FAIL("%s: %s %llu: a face needs at least 3 vertices, not %lld", path, el[i].name, (unsigned long long)k, (long long)n);
                }
                for (int64_t m = 0; m < n; m++) {
                    if (ply_read(&r, pr->t, &v))
                        FAIL("%s: %s %llu: truncated or malformed value", path, el[i].name, (unsigned long long)k);
                    if (pr->is_index && (v < 0 || (uint64_t)v >= vert->count))
                        FAIL("%s: %s %llu: vertex index %lld is not in 0..%llu", path, el[i].name, (unsigned long long)k,
                             (long long)v, (unsigned long long)(vert->count ? vert->count - 1 : 0));
                }
            }
            if (fmt == PLY_ASCII && next_token(&r.lb, r.le, &tb, &tn))
                FAIL("%s: line %zu: more values than %s declares", path, r.tc.line, el[i].name);
        }
    }
    return 0;
}

/* ---------------------------------------------------------------- OFF */

#define OFF_MAX_LINE 4000   /* assimp's OFF reader copies lines into a 4096-byte buffer */
#define OFF_MAX_FACE 9      /* ... and refuses faces of more than 9 vertices */

static int off_line(text_cursor *c, const char **b, const char **e)
{
    do {
        if (!next_line(c, b, e)) return 0;
    } while (*b == *e);   /* assimp skips runs of line ends */
    return 1;
}

int ms_preflight_off(const char *buf, size_t len, const char *path, char *err, size_t errlen)
{
    if (has_nul(buf, len)) FAIL("%s: not an OFF text file (it contains a NUL byte)", path);
    text_cursor c = { buf, buf + len, 0 };
    const char *b, *e, *p, *tb = NULL;
    size_t tn = 0;
    if (!off_line(&c, &b, &e) || e - b != 3 || memcmp(b, "OFF", 3))
        FAIL("%s: not a plain OFF file (the first line must be 'OFF')", path);
    uint64_t n[3];
    if (!off_line(&c, &b, &e)) FAIL("%s: the OFF header has no counts", path);
    p = b;
    for (int i = 0; i < 3; i++)
        if (!next_token(&p, e, &tb, &tn) || !uint_token(tb, tn, &n[i]))
            FAIL("%s: line %zu: the counts must be three unsigned integers", path, c.line);
    if (next_token(&p, e, &tb, &tn)) FAIL("%s: line %zu: text after the counts", path, c.line);
    if (n[0] == 0 || n[1] == 0) FAIL("%s: the OFF file declares no vertices or no faces", path);
    /* Every vertex and face takes a line of at least 6 bytes ("0 0 0\n", "3 0 1 2" takes 8). */
    size_t rest = len - (size_t)(c.p - buf);
    if (n[0] > rest / 6 || n[1] > rest / 6 || n[0] + n[1] > rest / 6)
        FAIL("%s: declares %llu vertices and %llu faces but only %zu bytes follow", path, (unsigned long long)n[0],
             (unsigned long long)n[1], rest);
    for (uint64_t v = 0; v < n[0]; v++) {
        if (!off_line(&c, &b, &e)) FAIL("%s: the file ends after %llu of %llu vertices", path, (unsigned long long)v, (unsigned long long)n[0]);
        if (e - b > OFF_MAX_LINE) FAIL("%s: line %zu is longer than %d bytes", path, c.line, OFF_MAX_LINE);
        p = b;
        int k = 0;
        while (next_token(&p, e, &tb, &tn)) {
            if (!number_token(tb, tn)) FAIL("%s: line %zu: '%.*s' is not a number", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
            k++;
        }
        if (k != 3) FAIL("%s: line %zu: a vertex needs 3 numbers, not %d", path, c.line, k);
    }
    for (uint64_t f = 0; f < n[1]; f++) {
        if (!off_line(&c, &b, &e)) FAIL("%s: the file ends after %llu of %llu faces", path, (unsigned long long)f, (unsigned long long)n[1]);
        if (e - b > OFF_MAX_LINE) FAIL("%s: line %zu is longer than %d bytes", path, c.line, OFF_MAX_LINE);
        p = b;
        uint64_t k, idx;
        if (!next_token(&p, e, &tb, &tn) || !uint_token(tb, tn, &k)) FAIL("%s: line %zu: a face must start with its vertex count", path, c.line);
        if (k < 3 || k > OFF_MAX_FACE) FAIL("%s: line %zu: a face of %llu vertices (3 to %d)", path, c.line, (unsigned long long)k, OFF_MAX_FACE);
        for (uint64_t i = 0; i < k; i++)
            if (!next_token(&p, e, &tb, &tn) || !uint_token(tb, tn, &idx) || idx >= n[0])
                FAIL("%s: line %zu: vertex index %llu of the face is missing or not in 0..%llu", path, c.line,
                     (unsigned long long)i, (unsigned long long)(n[0] - 1));
        while (next_token(&p, e, &tb, &tn))   /* colours may follow */
            if (!number_token(tb, tn)) FAIL("%s: line %zu: '%.*s' is not a number", path, c.line, (int)(tn > 32 ? 32 : tn), tb);
    }
    return 0;
}

/* ---------------------------------------------------------------- STL */

int ms_preflight_stl(const char *buf, size_t len, const char *path, char *err, size_t errlen)
{
    /* Binary as assimp decides it: 84 + 50 * count bytes. assimp computes that in 32 bits, so a count
     * that wraps would pass there and be read past the end: compared here in 64 bits. */
    if (len >= 84) {
        uint32_t n = (uint32_t)(unsigned char)buf[80] | (uint32_t)(unsigned char)buf[81] << 8 |
            (uint32_t)(unsigned char)buf[82] << 16 | (uint32_t)(unsigned char)buf[83] << 24;
        if ((uint64_t)n * 50 + 84 == len) return n ? 0 : (snprintf(err, errlen, "%s: the binary STL has no triangles", path), -1);
        if ((uint32_t)(n * 50u + 84u) == (uint32_t)len)
            FAIL("%s: binary STL declares %u triangles, more than its %zu bytes hold", path, n, len);
    }
    if (has_nul(buf, len)) FAIL("%s: not an STL file (binary size does not match its triangle count, and not text)", path);
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)buf[i] > 127) FAIL("%s: not an STL file (binary size does not match its triangle count, and not text)", path);
    /* assimp's STL reader separates tokens by space, tab, CR and LF only (a form feed before "vertex"
     * hides it there and leaks): no other control characters. */
    for (size_t i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)buf[i];
        if (ch < 0x20 && ch != '\t' && ch != '\r' && ch != '\n')
            FAIL("%s: control character 0x%02x in an ASCII STL file", path, ch);
    }
    /* ASCII: solid NAME, then facets of exactly three vertices, endsolid; tokens separated by any space. */
    const char *p = buf, *end = buf + len;
    size_t line = 1;
    int solids = 0;
#define STL_TOK() do { while (p < end && (*p == ' ' || *p == '\t' || is_eol(*p))) { line += *p == '\n'; p++; } \
                       tb = p; while (p < end && !(*p == ' ' || *p == '\t' || is_eol(*p))) p++; tn = (size_t)(p - tb); } while (0)
#define STL_EXPECT(w) do { STL_TOK(); if (!tok_is(tb, tn, w)) FAIL("%s: line %zu: expected '%s'", path, line, w); } while (0)
/* assimp reads "normal" and the numbers after "facet" and "vertex" on the same line. */
#define STL_SAME_LINE_TOK() do { while (p < end && (*p == ' ' || *p == '\t')) p++; \
                       tb = p; while (p < end && !(*p == ' ' || *p == '\t' || is_eol(*p))) p++; tn = (size_t)(p - tb); } while (0)
#define STL_NUM() do { STL_SAME_LINE_TOK(); if (!number_token(tb, tn)) FAIL("%s: line %zu: expected a number on the same line", path, line); } while (0)
    const char *tb = NULL;
    size_t tn = 0;
    for (;;) {
        STL_TOK();
        if (tn == 0) break;
        if (!tok_is(tb, tn, "solid")) FAIL("%s: line %zu: expected 'solid'", path, line);
        /* The name: the rest of the line, without anything assimp would take for a keyword. */
        const char *nb = p;
        while (p < end && !is_eol(*p)) p++;
        for (const char *q = nb; q < p; q++)
            if ((p - q >= 5 && !memcmp(q, "facet", 5)) || (p - q >= 6 && !memcmp(q, "vertex", 6)) ||
                (p - q >= 8 && !memcmp(q, "endsolid", 8)))
                FAIL("%s: line %zu: the solid's name contains a keyword", path, line);
        if (p - nb > 1000) FAIL("%s: line %zu: the solid's name is too long", path, line);
        solids++;
        for (;;) {
            STL_TOK();
            if (tok_is(tb, tn, "endsolid")) {
                while (p < end && !is_eol(*p)) p++;
                break;
            }
            if (!tok_is(tb, tn, "facet")) FAIL("%s: line %zu: expected 'facet' or 'endsolid'", path, line);
            STL_SAME_LINE_TOK();
            if (!tok_is(tb, tn, "normal")) FAIL("%s: line %zu: expected 'normal' after 'facet'", path, line);
            STL_NUM(); STL_NUM(); STL_NUM();
            STL_EXPECT("outer");
            STL_EXPECT("loop");
            for (int v = 0; v < 3; v++) {
                STL_EXPECT("vertex");
                STL_NUM(); STL_NUM(); STL_NUM();
            }
            STL_EXPECT("endloop");
            STL_EXPECT("endfacet");
        }
    }
    if (!solids) FAIL("%s: not an STL file (empty)", path);
    return 0;
}
