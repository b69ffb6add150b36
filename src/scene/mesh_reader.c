/* What the OBJ, PLY, OFF and STL readers share: see mesh_reader.h. */
#include "mesh_reader.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int ms_text_line(ms_text *c, const char **b, const char **e)
{
    if (c->p >= c->end) return 0;
    *b = c->p;
    while (c->p < c->end && *c->p != '\n' && *c->p != '\r' && *c->p != '\f') c->p++;
    *e = c->p;
    if (c->p < c->end) {
        if (*c->p == '\r' && c->p + 1 < c->end && c->p[1] == '\n') c->p++;
        c->p++;
    }
    c->line++;
    return 1;
}

int ms_text_token(const char **p, const char *e, const char **tb, size_t *tn)
{
    const char *s = *p;
    while (s < e && ms_is_blank(*s)) s++;
    if (s == e) { *p = s; return 0; }
    *tb = s;
    while (s < e && !ms_is_blank(*s)) s++;
    *tn = (size_t)(s - *tb);
    *p = s;
    return 1;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* The syntax of a real; the parts' extents. */
typedef struct real_parts {
    int neg, special;          /* special: 1 nan, 2 inf */
    const char *ip; size_t in; /* integer digits */
    const char *fp; size_t fn; /* fraction digits */
    int eneg; const char *ep; size_t en;
} real_parts;

static int real_syntax(const char *s, size_t n, real_parts *r)
{
    memset(r, 0, sizeof *r);
    size_t i = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) r->neg = s[i++] == '-';
    if (n - i == 3 && !strncasecmp(s + i, "nan", 3)) { r->special = 1; return 0; }
    if ((n - i == 3 && !strncasecmp(s + i, "inf", 3)) || (n - i == 8 && !strncasecmp(s + i, "infinity", 8))) {
        r->special = 2;
        return 0;
    }
    r->ip = s + i;
    while (i < n && is_digit(s[i])) i++;
    r->in = (size_t)(s + i - r->ip);
    if (i < n && s[i] == '.') {
        i++;
        r->fp = s + i;
        while (i < n && is_digit(s[i])) i++;
        r->fn = (size_t)(s + i - r->fp);
    }
    if (r->in == 0 && r->fn == 0) return -1;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-')) r->eneg = s[i++] == '-';
        r->ep = s + i;
        while (i < n && is_digit(s[i])) i++;
        r->en = (size_t)(s + i - r->ep);
        if (r->en == 0) return -1;
    }
    return i == n ? 0 : -1;
}

/* assimp's strtoul10_64: the value of up to `max` digits (the rest skipped); *used the digits taken. */
static uint64_t digits_value(const char *s, size_t n, size_t max, size_t *used, int *overflow)
{
    uint64_t v = 0;
    size_t k = 0;
    *overflow = 0;
    for (; k < n && k < max; k++) {
        uint64_t nv = v * 10 + (uint64_t)(s[k] - '0');
        if (nv < v || v > UINT64_MAX / 10) { *overflow = 1; break; }
        v = nv;
    }
    *used = k;
    return v;
}

static const double frac_scale[16] = { 0.0, 0.1, 0.01, 0.001, 0.0001, 0.00001, 0.000001, 0.0000001, 0.00000001,
    0.000000001, 0.0000000001, 0.00000000001, 0.000000000001, 0.0000000000001, 0.00000000000001,
    0.000000000000001 };

int ms_parse_real_f(const char *s, size_t n, float *out)
{
    real_parts r;
    if (real_syntax(s, n, &r)) return -1;
    if (r.special) { *out = r.special == 1 ? NAN : r.neg ? -INFINITY : INFINITY; return 0; }
    size_t used;
    int ovf;
    float f = 0;
    if (r.in) {
        uint64_t v = digits_value(r.ip, r.in, r.in, &used, &ovf);
        f = ovf ? (float)strtod(r.ip, NULL) : (float)v;   /* past 2^64: no longer assimp's value */
    }
    if (r.fn) {
        uint64_t v = digits_value(r.fp, r.fn, 15, &used, &ovf);
        double pl = (double)v * frac_scale[used];
        f += (float)pl;
    }
    if (r.en) {
        uint64_t v = digits_value(r.ep, r.en, r.en, &used, &ovf);
        float ex = ovf || v > 100000 ? 100000.0f : (float)v;
        if (r.eneg) ex = -ex;
        f *= powf(10.0f, ex);
    }
    *out = r.neg ? -f : f;
    return 0;
}

int ms_parse_real_d(const char *s, size_t n, double *out)
{
    real_parts r;
    if (real_syntax(s, n, &r)) return -1;
    if (r.special) { *out = r.special == 1 ? NAN : r.neg ? -INFINITY : INFINITY; return 0; }
    size_t used;
    int ovf;
    double f = 0;
    if (r.in) {
        uint64_t v = digits_value(r.ip, r.in, r.in, &used, &ovf);
        f = ovf ? strtod(r.ip, NULL) : (double)v;
    }
    if (r.fn) {
        uint64_t v = digits_value(r.fp, r.fn, 15, &used, &ovf);
        f += (double)v * frac_scale[used];
    }
    if (r.en) {
        uint64_t v = digits_value(r.ep, r.en, r.en, &used, &ovf);
        double ex = ovf || v > 100000 ? 100000.0 : (double)v;
        if (r.eneg) ex = -ex;
        f *= pow(10.0, ex);
    }
    *out = r.neg ? -f : f;
    return 0;
}

int ms_parse_int(const char *s, size_t n, int64_t *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
    if (i == n || n - i > 18) return -1;
    int64_t v = 0;
    for (; i < n; i++) {
        if (!is_digit(s[i])) return -1;
        v = 10 * v + (s[i] - '0');
    }
    *out = neg ? -v : v;
    return 0;
}

/* ---------------------------------------------------------------- triangulation (assimp's) */

typedef struct v3 { float x, y, z; } v3;
static v3 at(const float *p, int i) { v3 r = { p[3 * i], p[3 * i + 1], p[3 * i + 2] }; return r; }
static v3 sub(v3 a, v3 b) { v3 r = { a.x - b.x, a.y - b.y, a.z - b.z }; return r; }
static v3 normalize(v3 a)
{
    const float l = sqrtf(a.x * a.x + a.y * a.y + a.z * a.z);
    if (l == 0.0f) return a;
    const float inv = 1.0f / l;
    a.x *= inv; a.y *= inv; a.z *= inv;
    return a;
}
static float dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

typedef struct v2 { float x, y; } v2;
static int left_of(v2 p0, v2 p1, v2 p2)
{
    return (p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y) > 0;
}
static int in_triangle(v2 p0, v2 p1, v2 p2, v2 pp)
{
    const v2 a = { p1.x - p0.x, p1.y - p0.y }, b = { p2.x - p0.x, p2.y - p0.y }, c = { pp.x - p0.x, pp.y - p0.y };
    float d00 = a.x * a.x + a.y * a.y, d01 = a.x * b.x + a.y * b.y, d02 = a.x * c.x + a.y * c.y;
    float d11 = b.x * b.x + b.y * b.y, d12 = b.x * c.x + b.y * c.y;
    const float inv = 1 / (d00 * d11 - d01 * d01);
    d11 = (d11 * d02 - d01 * d12) * inv;
    d00 = (d00 * d12 - d01 * d02) * inv;
    return d11 > 0 && d00 > 0 && d11 + d00 < 1;
}

int ms_triangulate(const float *pos, int n, int (*tri)[3])
{
    if (n < 3) return 0;
    if (n == 3) { tri[0][0] = 0; tri[0][1] = 1; tri[0][2] = 2; return 1; }
    if (n == 4) {
        int s = 0;
        for (int i = 0; i < 4; i++) {
            const v3 v = at(pos, i);
            const v3 l = normalize(sub(at(pos, (i + 3) % 4), v)), d = normalize(sub(at(pos, (i + 2) % 4), v)),
                     r = normalize(sub(at(pos, (i + 1) % 4), v));
            const float angle = acosf(dot(l, d)) + acosf(dot(r, d));
            if (angle > 3.1415926538f) { s = i; break; }   /* the concave corner */
        }
        tri[0][0] = s; tri[0][1] = (s + 1) % 4; tri[0][2] = (s + 2) % 4;
        tri[1][0] = s; tri[1][1] = (s + 2) % 4; tri[1][2] = (s + 3) % 4;
        return 2;
    }
    /* Newell normal; project onto the plane of its two smaller components. */
    float sxy = 0, syz = 0, szx = 0;
    for (int i = 0; i < n; i++) {
        const v3 p = at(pos, (i + 1) % n), lo = at(pos, i), hi = at(pos, (i + 2) % n);
        sxy += p.x * (hi.y - lo.y);
        syz += p.y * (hi.z - lo.z);
        szx += p.z * (hi.x - lo.x);
    }
    const v3 nn = { syz, szx, sxy };
    const float ax = fabsf(nn.x), ay = fabsf(nn.y), az = fabsf(nn.z);
    int ac = 0, bc = 1;
    float inv = nn.z;
    if (ax > ay) {
        if (ax > az) { ac = 1; bc = 2; inv = nn.x; }
    } else if (ay > az) {
        ac = 2; bc = 0; inv = nn.y;
    }
    if (inv < 0.f) { int t = ac; ac = bc; bc = t; }
    v2 pt[MS_MAX_POLYGON];
    unsigned char done[MS_MAX_POLYGON];
    for (int i = 0; i < n; i++) {
        pt[i].x = pos[3 * i + ac];
        pt[i].y = pos[3 * i + bc];
        done[i] = 0;
    }
    int num = n, ear = 0, prev = n - 1, next = 0, out = 0;
    while (num > 3) {
        int found = 0;
        for (ear = next;; prev = ear, ear = next) {
            for (next = ear + 1; done[next >= n ? (next = 0) : next]; ++next) {}
            if (next < ear && ++found == 2) break;
            const v2 p1 = pt[ear], p0 = pt[prev], p2 = pt[next];
            if (left_of(p0, p2, p1)) continue;   /* not convex (counter-clockwise winding) */
            int t;
            for (t = 0; t < n; t++) {
                const v2 q = pt[t];
                if ((q.x != p1.x || q.y != p1.y) && (q.x != p2.x || q.y != p2.y) && (q.x != p0.x || q.y != p0.y) &&
                    in_triangle(p0, p1, p2, q))
                    break;
            }
            if (t != n) continue;
            break;
        }
        if (found == 2) {
            /* No ear (not a simple polygon): assimp drops the rest; here it is fanned instead. */
            int rest[MS_MAX_POLYGON], k = 0;
            for (int i = 0; i < n; i++)
                if (!done[i]) rest[k++] = i;
            for (int i = 1; i + 1 < k; i++) { tri[out][0] = rest[0]; tri[out][1] = rest[i]; tri[out][2] = rest[i + 1]; out++; }
            return out;
        }
        tri[out][0] = prev; tri[out][1] = ear; tri[out][2] = next;
        out++;
        done[ear] = 1;
        --num;
    }
    int t = 0;
    while (done[t]) t++;
    tri[out][0] = t;
    for (++t; done[t]; ++t) {}
    tri[out][1] = t;
    for (++t; done[t]; ++t) {}
    tri[out][2] = t;
    out++;
    /* assimp's NGON encoding: a triangle whose first corner is the previous one's first corner is
     * rotated (c, a, b), so that the triangles of a polygon alternate between two starting corners. */
    int last = -1;
    for (int i = 0; i < out; i++) {
        if (tri[i][0] == last) {
            const int a = tri[i][0], b = tri[i][1], c = tri[i][2];
            tri[i][0] = c; tri[i][1] = a; tri[i][2] = b;
        }
        last = tri[i][0];
    }
    return out;
}

/* ---------------------------------------------------------------- emission */

void ms_emit_init(ms_emit *em, ms_tri_soup *soup, size_t len, const char *path)
{
    em->soup = soup;
    em->added = 0;
    em->max = (len + 64) * MS_MAX_TRIS_PER_BYTE;
    em->path = path;
}

int ms_emit_tri(ms_emit *em, const float v[9], const double *vd, const float *uv6, const float *n9, uint32_t material,
                char *err, size_t errlen)
{
    if (em->added == em->max)
        MS_FAIL("%s: the mesh expands to more than %zu triangles (%d per byte of file)", em->path, em->max,
                MS_MAX_TRIS_PER_BYTE);
    /* Positions and normals as assimp's identity node transform left them (x + 0*y + 0*z + 0: a -0
     * becomes +0), so that images stay bit for bit what they were with assimp. */
    float p[9], nv[9];
    for (int k = 0; k < 3; k++) {
        const float x = v[3 * k], y = v[3 * k + 1], z = v[3 * k + 2];
        p[3 * k] = 1.0f * x + 0.0f * y + 0.0f * z + 0.0f;
        p[3 * k + 1] = 0.0f * x + 1.0f * y + 0.0f * z + 0.0f;
        p[3 * k + 2] = 0.0f * x + 0.0f * y + 1.0f * z + 0.0f;
        if (n9) {
            const float a = n9[3 * k], b = n9[3 * k + 1], c = n9[3 * k + 2];
            nv[3 * k] = 1.0f * a + 0.0f * b + 0.0f * c;
            nv[3 * k + 1] = 0.0f * a + 1.0f * b + 0.0f * c;
            nv[3 * k + 2] = 0.0f * a + 0.0f * b + 1.0f * c;
        }
    }
    const float *uvp[MS_SOUP_UV_SETS] = { uv6 };
    double pd[9];
    for (int i = 0; i < 9; i++) pd[i] = vd ? vd[i] + 0.0 : (double)p[i];   /* + 0.0: a -0 becomes +0, as p */
    if (ms_soup_push_d(em->soup, p, pd, uvp, material, n9 ? nv : NULL)) MS_FAIL("%s: out of memory", em->path);
    em->added++;
    return 0;
}
