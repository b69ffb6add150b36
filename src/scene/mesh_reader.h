/* microshadow's own OBJ, PLY, OFF and STL readers (mesh_obj.c, mesh_ply.c, mesh_off.c, mesh_stl.c) and
 * what they share (mesh_reader.c): a line and token cursor, number parsing, polygon triangulation and the
 * bounded emission of triangles into the soup.
 *
 * Hostile input (docs/design.md): every reader walks its bytes a bounded number of times, checks each
 * declared count against the bytes present before allocating for it, and refuses a file with one line
 * naming the file (and line or element) and saying whether it is malformed or over a limit. */
#ifndef MS_MESH_READER_H
#define MS_MESH_READER_H
#include "scene_internal.h"
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define MS_FAIL(...) do { snprintf(err, errlen, __VA_ARGS__); return -1; } while (0)
/* A token quoted in a message: at most 32 characters of it. */
#define MS_TOKQ(n) (int)((n) > 32 ? 32 : (n))

/* Lines of text split at \n, \r\n, \r or \f; `line` is the 1-based number of the last line returned. */
typedef struct ms_text { const char *p, *end; size_t line; } ms_text;
int ms_text_line(ms_text *c, const char **b, const char **e);
/* The next token of [*p, e) separated by blanks (space, tab, vertical tab, and \x01: the mark mesh_obj.c
 * leaves where it joined a continued line); 0 at the end. */
int ms_text_token(const char **p, const char *e, const char **tb, size_t *tn);
static inline int ms_is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\x01'; }
static inline int ms_tok_is(const char *s, size_t n, const char *w)
{
    size_t i = 0;
    for (; i < n && w[i]; i++)
        if (s[i] != w[i]) return 0;
    return i == n && !w[i];
}

/* A decimal real: [+-](digits[.digits*] | .digits)[(e|E)[+-]digits], or nan / inf / infinity (any case).
 * The whole token must be the number. The value is computed as assimp's fast_atof computes it (so that
 * meshes read here are bit for bit what assimp read before): the float flavour in float arithmetic,
 * the double flavour in double. 0, or -1 when the token is not such a number. */
int ms_parse_real_f(const char *s, size_t n, float *out);
int ms_parse_real_d(const char *s, size_t n, double *out);
/* A decimal integer [+-]digits (at most 18 digits); 0 or -1. */
int ms_parse_int(const char *s, size_t n, int64_t *out);

/* Triangulates a polygon of n (3..MS_MAX_POLYGON) vertices whose positions are pos[3*i]: as assimp's
 * aiProcess_Triangulate does (the concave corner of a quad starts its fan; larger polygons are cut into
 * ears in the plane of their Newell normal, which for a convex polygon is the fan from its last vertex).
 * Writes at most n - 2 triangles as corner numbers into tri; returns their number. */
int ms_triangulate(const float *pos, int n, int (*tri)[3]);

/* Triangles into the soup, at most `max` of them (MS_MAX_TRIS_PER_BYTE per input byte). */
typedef struct ms_emit {
    ms_tri_soup *soup;
    size_t added, max;
    const char *path;
} ms_emit;
void ms_emit_init(ms_emit *em, ms_tri_soup *soup, size_t len, const char *path);
/* One triangle: positions (9 floats, and vd: the same 9 parsed in double, or NULL when the floats are
 * exact), UV set 0 (6 floats or NULL), vertex normals (9 or NULL), material.
 * -1 with one line in err when out of memory or past the triangle limit. */
int ms_emit_tri(ms_emit *em, const float v[9], const double *vd, const float *uv6, const float *n9, uint32_t material,
                char *err, size_t errlen);

int ms_mesh_obj(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen);
int ms_mesh_ply(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen);
int ms_mesh_off(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen);
int ms_mesh_stl(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                size_t errlen);

#endif
