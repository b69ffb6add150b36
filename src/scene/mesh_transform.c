/* Per-mesh transforms of the scene file (#30 item 5): {"file": ..., "transform": {...}}, applied to the
 * mesh's triangles after the file's own node transforms. */
#include "mesh_transform.h"
#include "microshadow.h"
#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TFAIL(...) do { snprintf(err, errlen, __VA_ARGS__); return -1; } while (0)

/* n numbers of an array (n = 0: any length up to max; *got the count) into out. */
static int numbers(const cJSON *a, const char *what, const char *path, int want, int max, double *out, int *got,
                   char *err, size_t errlen)
{
    if (!cJSON_IsArray(a)) TFAIL("%s: %s must be an array of %d numbers", path, what, want ? want : max);
    const int n = cJSON_GetArraySize(a);
    if ((want && n != want) || n > max) TFAIL("%s: %s must have %d numbers, not %d", path, what, want ? want : max, n);
    int i = 0;
    const cJSON *x;
    cJSON_ArrayForEach(x, a) {
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble) || fabs(x->valuedouble) > FLT_MAX)
            TFAIL("%s: %s[%d] must be a finite number within the float range", path, what, i);
        out[i++] = x->valuedouble;
    }
    *got = n;
    return 0;
}

static void mat_mul(const double a[12], const double b[12], double r[12])
{
    /* 3x4 affine (row-major, last row 0 0 0 1): r = a b */
    double t[12];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double s = j == 3 ? a[4 * i + 3] : 0.0;
            for (int k = 0; k < 3; k++) s += a[4 * i + k] * b[4 * k + j];
            t[4 * i + j] = s;
        }
    }
    memcpy(r, t, sizeof t);
}

int ms_mesh_transform_parse(const cJSON *t, const char *objname, const char *path, double m[12], char *err,
                            size_t errlen)
{
    static const double id[12] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0 };
    memcpy(m, id, sizeof id);
    if (!cJSON_IsObject(t)) TFAIL("%s: %s.transform must be an object", path, objname);
    char what[96];
    const cJSON *it;
    int trs = 0, mat = 0;
    cJSON_ArrayForEach(it, t) {
        if (!strcmp(it->string, "translate") || !strcmp(it->string, "rotate_deg") || !strcmp(it->string, "scale")) trs = 1;
        else if (!strcmp(it->string, "matrix")) mat = 1;
        else TFAIL("%s: %s.transform: unknown key \"%.40s\" (known: translate, rotate_deg, scale, matrix)", path,
                   objname, it->string);
    }
    if (trs && mat) TFAIL("%s: %s.transform: give either \"matrix\" or translate/rotate_deg/scale, not both", path, objname);
    int n;
    if (mat) {
        /* 16 numbers, column-major as in glTF: element (row r, column c) is matrix[4 c + r]. */
        double a[16];
        snprintf(what, sizeof what, "%s.transform.matrix", objname);
        if (numbers(cJSON_GetObjectItemCaseSensitive(t, "matrix"), what, path, 16, 16, a, &n, err, errlen)) return -1;
        if (a[3] != 0 || a[7] != 0 || a[11] != 0 || a[15] != 1)
            TFAIL("%s: %s: the last row (matrix[3], [7], [11], [15]) must be 0 0 0 1 (column-major, as in glTF: "
                  "projective matrices are not supported)", path, what);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) m[4 * r + c] = a[4 * c + r];
    } else {
        double s[3] = { 1, 1, 1 }, rd[3] = { 0, 0, 0 }, tr[3] = { 0, 0, 0 };
        const cJSON *x = cJSON_GetObjectItemCaseSensitive(t, "scale");
        if (x && cJSON_IsNumber(x)) {
            if (!isfinite(x->valuedouble) || fabs(x->valuedouble) > FLT_MAX)
                TFAIL("%s: %s.transform.scale must be a finite number within the float range", path, objname);
            s[0] = s[1] = s[2] = x->valuedouble;
        } else if (x) {
            snprintf(what, sizeof what, "%s.transform.scale", objname);
            if (!cJSON_IsArray(x)) TFAIL("%s: %s must be a number or an array of 3 numbers", path, what);
            if (numbers(x, what, path, 3, 3, s, &n, err, errlen)) return -1;
        }
        if ((x = cJSON_GetObjectItemCaseSensitive(t, "rotate_deg"))) {
            snprintf(what, sizeof what, "%s.transform.rotate_deg", objname);
            if (numbers(x, what, path, 3, 3, rd, &n, err, errlen)) return -1;
        }
        if ((x = cJSON_GetObjectItemCaseSensitive(t, "translate"))) {
            snprintf(what, sizeof what, "%s.transform.translate", objname);
            if (numbers(x, what, path, 3, 3, tr, &n, err, errlen)) return -1;
        }
        /* M = T Rz Ry Rx S: scaled, then rotated about x, then y, then z (degrees, right-handed, about the
         * mesh's origin), then translated. */
        double S[12] = { s[0], 0, 0, 0, 0, s[1], 0, 0, 0, 0, s[2], 0 };
        const double k = acos(-1.0) / 180.0;
        const double cx = cos(rd[0] * k), sx = sin(rd[0] * k), cy = cos(rd[1] * k), sy = sin(rd[1] * k),
                     cz = cos(rd[2] * k), sz = sin(rd[2] * k);
        const double Rx[12] = { 1, 0, 0, 0, 0, cx, -sx, 0, 0, sx, cx, 0 };
        const double Ry[12] = { cy, 0, sy, 0, 0, 1, 0, 0, -sy, 0, cy, 0 };
        const double Rz[12] = { cz, -sz, 0, 0, sz, cz, 0, 0, 0, 0, 1, 0 };
        mat_mul(Rx, S, m);
        mat_mul(Ry, m, m);
        mat_mul(Rz, m, m);
        m[3] = tr[0]; m[7] = tr[1]; m[11] = tr[2];
    }
    /* Singular (a scale of 0, a flattening matrix): the mesh would collapse to a plane, line or point. */
    const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                       m[2] * (m[4] * m[9] - m[5] * m[8]);
    double big = 0;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) big = fmax(big, fabs(m[4 * r + c]));
    if (!isfinite(det) || fabs(det) <= 1e-12 * big * big * big)
        TFAIL("%s: %s.transform is singular (determinant %g): it would flatten the mesh", path, objname, det);
    return 0;
}

/* v (3 floats) := a v (a 3x3, row-major) scaled back to v's length, times sign; NaN stays NaN. */
static void direction_transform(const double a[9], double sign, float *v)
{
    const double x = v[0], y = v[1], z = v[2];
    double o[3];
    for (int r = 0; r < 3; r++) o[r] = a[3 * r] * x + a[3 * r + 1] * y + a[3 * r + 2] * z;
    const double l0 = sqrt(x * x + y * y + z * z), l1 = sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    const double f = l1 > 0 && isfinite(l1) ? sign * l0 / l1 : 0;
    for (int r = 0; r < 3; r++) v[r] = (float)(o[r] * f);
}

void ms_soup_transform(ms_tri_soup *soup, size_t from, size_t to, const double m[12])
{
    /* Normals by the cofactor matrix (the inverse transpose times the determinant), times the sign of the
     * determinant, each keeping its length; a negative determinant (a mirror) also turns the winding. */
    double cof[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[3 * r + c] = m[4 * r1 + c1] * m[4 * r2 + c2] - m[4 * r1 + c2] * m[4 * r2 + c1];
        }
    const double det = m[0] * cof[0] + m[1] * cof[1] + m[2] * cof[2];
    const int flip = det < 0;
    const double lin[9] = { m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10] };   /* m without translation */
    for (size_t t = from; t < to; t++) {
        float *v = soup->tri + 9 * t;
        double *vd = soup->tri_d + 9 * t;
        for (int k = 0; k < 3; k++) {
            const double x = v[3 * k], y = v[3 * k + 1], z = v[3 * k + 2];
            for (int r = 0; r < 3; r++) v[3 * k + r] = (float)(m[4 * r] * x + m[4 * r + 1] * y + m[4 * r + 2] * z + m[4 * r + 3]);
            /* the double positions stay double: a "translate" of 1e5 keeps the mesh's detail (scene_frame.c) */
            const double xd = vd[3 * k], yd = vd[3 * k + 1], zd = vd[3 * k + 2];
            for (int r = 0; r < 3; r++) vd[3 * k + r] = m[4 * r] * xd + m[4 * r + 1] * yd + m[4 * r + 2] * zd + m[4 * r + 3];
        }
        float *nv = soup->normal ? soup->normal + 9 * t : NULL;
        if (nv)
            for (int k = 0; k < 3; k++) direction_transform(cof, flip ? -1.0 : 1.0, nv + 3 * k);
        /* Normal-map tangents (x, y, z, w per corner) are directions along the surface: by m itself, each
         * keeping its length; w (the bitangent's handedness) turns with a mirror. */
        float *tv = t < soup->tangent_n ? soup->tangent + 12 * t : NULL;
        if (tv)
            for (int k = 0; k < 3; k++) {
                direction_transform(lin, 1.0, tv + 4 * k);
                if (flip) tv[4 * k + 3] = -tv[4 * k + 3];
            }
        if (!flip) continue;
        float tmp[4];
        memcpy(tmp, v + 3, 3 * sizeof *tmp); memcpy(v + 3, v + 6, 3 * sizeof *tmp); memcpy(v + 6, tmp, 3 * sizeof *tmp);
        double tmpd[3];
        memcpy(tmpd, vd + 3, sizeof tmpd); memcpy(vd + 3, vd + 6, sizeof tmpd); memcpy(vd + 6, tmpd, sizeof tmpd);
        if (nv) { memcpy(tmp, nv + 3, 3 * sizeof *tmp); memcpy(nv + 3, nv + 6, 3 * sizeof *tmp); memcpy(nv + 6, tmp, 3 * sizeof *tmp); }
        if (tv) { memcpy(tmp, tv + 4, sizeof tmp); memcpy(tv + 4, tv + 8, sizeof tmp); memcpy(tv + 8, tmp, sizeof tmp); }
        for (int s = 0; s < MS_SOUP_UV_SETS; s++) {
            if (!soup->uv[s]) continue;
            float *u = soup->uv[s] + 6 * t, w[2];
            memcpy(w, u + 2, sizeof w); memcpy(u + 2, u + 4, sizeof w); memcpy(u + 4, w, sizeof w);
        }
    }
}

int ms_soup_copy_range(ms_tri_soup *soup, size_t from, size_t to)
{
    /* the copy's objects are new ones, in the same order as the original's */
    uint32_t lo = UINT32_MAX;
    for (size_t t = from; t < to; t++) lo = soup->object[t] < lo ? soup->object[t] : lo;
    ms_soup_new_object(soup);
    const uint32_t base = soup->cur_object;
    for (size_t t = from; t < to; t++) {
        soup->cur_object = base + (soup->object[t] - lo);
        float v[9], n[9], uv[MS_SOUP_UV_SETS][6];
        double vd[9];
        const float *uvp[MS_SOUP_UV_SETS] = { NULL };
        memcpy(v, soup->tri + 9 * t, sizeof v);
        memcpy(vd, soup->tri_d + 9 * t, sizeof vd);
        if (soup->normal) memcpy(n, soup->normal + 9 * t, sizeof n);
        for (int s = 0; s < MS_SOUP_UV_SETS; s++)
            if (soup->uv[s]) { memcpy(uv[s], soup->uv[s] + 6 * t, sizeof uv[s]); uvp[s] = uv[s]; }
        const uint32_t mat = soup->material ? soup->material[t] : MS_NO_MATERIAL;
        if (ms_soup_push_d(soup, v, vd, uvp, mat, soup->normal ? n : NULL)) return -1;
        if (soup->cur_object + 1 > soup->n_objects) soup->n_objects = soup->cur_object + 1;
        if (t < soup->tangent_n) {   /* copied first: setting them may move the array */
            float tg[12];
            memcpy(tg, soup->tangent + 12 * t, sizeof tg);
            if (ms_soup_set_tangents(soup, soup->n - 1, 1, tg)) return -1;
        }
    }
    return 0;
}
