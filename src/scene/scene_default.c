/* The built-in scene: a ground, occluders of several sizes and heights (a tall pillar, a cube, a
 * floating open plate, a sphere) under a square light, so that both hard contact shadows and wide
 * penumbrae show. Procedural: no file needed. */
#include "microshadow.h"
#include "scene_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int quad(ms_tri_soup *s, const float a[3], const float b[3], const float c[3], const float d[3])
{
    float t0[9] = { a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2] };
    float t1[9] = { a[0], a[1], a[2], c[0], c[1], c[2], d[0], d[1], d[2] };
    return ms_soup_push(s, t0) || ms_soup_push(s, t1);
}

static int box(ms_tri_soup *s, float x0, float y0, float z0, float x1, float y1, float z1)
{
    float p[8][3];
    for (int i = 0; i < 8; i++) {
        p[i][0] = (i & 1) ? x1 : x0;
        p[i][1] = (i & 2) ? y1 : y0;
        p[i][2] = (i & 4) ? z1 : z0;
    }
    static const int f[6][4] = { { 0, 1, 3, 2 }, { 4, 6, 7, 5 }, { 0, 4, 5, 1 },
                                 { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 5, 7, 3 } };
    for (int i = 0; i < 6; i++)
        if (quad(s, p[f[i][0]], p[f[i][1]], p[f[i][2]], p[f[i][3]])) return -1;
    return 0;
}

static int sphere(ms_tri_soup *s, float cx, float cy, float cz, float r, int rings, int segs)
{
    for (int i = 0; i < rings; i++) {
        float th0 = (float)M_PI * (float)i / (float)rings, th1 = (float)M_PI * (float)(i + 1) / (float)rings;
        for (int j = 0; j < segs; j++) {
            float ph0 = 2.0f * (float)M_PI * (float)j / (float)segs;
            float ph1 = 2.0f * (float)M_PI * (float)(j + 1) / (float)segs;
            float q[4][3];
            const float th[4] = { th0, th0, th1, th1 }, ph[4] = { ph0, ph1, ph1, ph0 };
            for (int k = 0; k < 4; k++) {
                q[k][0] = cx + r * sinf(th[k]) * cosf(ph[k]);
                q[k][1] = cy + r * cosf(th[k]);
                q[k][2] = cz + r * sinf(th[k]) * sinf(ph[k]);
            }
            if (quad(s, q[0], q[1], q[2], q[3])) return -1;
        }
    }
    return 0;
}

int ms_scene_default(ms_scene *out)
{
    memset(out, 0, sizeof *out);
    ms_tri_soup s = { 0 };
    const float g0[3] = { -8, 0, -8 }, g1[3] = { 8, 0, -8 }, g2[3] = { 8, 0, 8 }, g3[3] = { -8, 0, 8 };
    const float p0[3] = { -0.9f, 1.6f, 1.4f }, p1[3] = { 0.3f, 1.6f, 1.4f }, p2[3] = { 0.3f, 1.6f, 2.6f },
                p3[3] = { -0.9f, 1.6f, 2.6f };
    if (quad(&s, g0, g3, g2, g1) ||
        box(&s, -3.2f, 0.0f, -0.6f, -2.8f, 3.5f, -0.2f) ||      /* tall thin pillar */
        box(&s, 1.5f, 0.0f, -1.5f, 3.0f, 1.5f, 0.0f) ||         /* cube on the ground */
        quad(&s, p0, p1, p2, p3) ||                             /* floating open plate */
        sphere(&s, -0.8f, 0.9f, -2.6f, 0.9f, 24, 48)) {         /* sphere resting on the ground */
        ms_soup_free(&s);
        return -1;
    }
    free(s.tri_d);   /* generated about the origin: the scene's frame is the world's */
    out->tri = s.tri;
    out->n_tris = s.n;
    out->tri_mesh = s.mesh;
    out->n_meshes = 1;
    out->tri_object = s.object;
    out->n_objects = s.n_objects;
    out->camera = (ms_camera){ { 0.0f, 6.5f, 10.0f }, { 0.0f, 0.6f, 0.0f }, { 0.0f, 1.0f, 0.0f }, 50.0f, 1024, 768, MS_CAMERA_PINHOLE, 0.0f, 0.0f };
    out->light = (ms_light){ { -1.25f, 6.0f, -1.25f }, { 2.5f, 0.0f, 0.0f }, { 0.0f, 0.0f, 2.5f },
                             { MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    out->samples = 1024;
    return 0;
}
