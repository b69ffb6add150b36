/* Every triangle baked or named (bake_unbaked.h): the reasons mirror the texel rasterization's skips in
 * bake.c (no plane, UVs not finite or without area) and the UV choice's (bake_uvs.c: "lightmap": false; xatlas
 * leaving out what it deems without area), so a warning names exactly the triangles with no texels of their
 * own from their own UVs. */
#include "bake_unbaked.h"
#include "scene/scene_internal.h"
#include <math.h>
#include <string.h>

int ms_bake_tri_normal(const float *w, float nn[3])
{
    float e1[3], e2[3];
    for (int d = 0; d < 3; d++) { e1[d] = w[3 + d] - w[d]; e2[d] = w[6 + d] - w[d]; }
    nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
    nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
    nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const float len = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    if (!(len > 0.0f) || !isfinite(len)) return -1;
    for (int d = 0; d < 3; d++) nn[d] /= len;
    return 0;
}

ms_unbaked ms_bake_tri_state(const ms_scene *sc, const float *uv, int size, size_t t)
{
    if (sc->mesh_lightmap_scale && sc->tri_mesh && sc->tri_mesh[t] < sc->n_meshes &&
        !(sc->mesh_lightmap_scale[sc->tri_mesh[t]] > 0.0f))
        return MS_UNBAKED_EXCLUDED;
    float nn[3];
    if (ms_bake_tri_normal(sc->tri + 9 * t, nn)) return MS_UNBAKED_NO_AREA;
    const float *u = uv + 6 * t;
    for (int k = 0; k < 6; k++)
        if (!isfinite(u[k])) return MS_UNBAKED_NO_UVS;
    const double a[2] = { u[0] * (double)size, u[1] * (double)size }, b[2] = { u[2] * (double)size, u[3] * (double)size },
                 c[2] = { u[4] * (double)size, u[5] * (double)size };
    if ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) == 0.0) return MS_UNBAKED_UV_FLAT;
    const double lo0 = fmin(a[0], fmin(b[0], c[0])), hi0 = fmax(a[0], fmax(b[0], c[0]));
    const double lo1 = fmin(a[1], fmin(b[1], c[1])), hi1 = fmax(a[1], fmax(b[1], c[1]));
    if (hi0 < 0.0 || hi1 < 0.0 || lo0 >= size || lo1 >= size) return MS_UNBAKED_UV_OUTSIDE;
    return MS_BAKED;
}

const char *ms_unbaked_name(ms_unbaked r)
{
    switch (r) {
    case MS_UNBAKED_EXCLUDED: return "lightmap false";
    case MS_UNBAKED_NO_AREA: return "no area";
    case MS_UNBAKED_NO_UVS: return "no UVs";
    case MS_UNBAKED_UV_FLAT: return "UVs without area";
    case MS_UNBAKED_UV_OUTSIDE: return "UVs outside the lightmap";
    default: return "baked";
    }
}

void ms_bake_report_unbaked(const ms_scene *sc, const ms_lightmap *lm, int size, size_t count[MS_UNBAKED_REASONS])
{
    memset(count, 0, MS_UNBAKED_REASONS * sizeof *count);
    for (size_t t = 0; t < sc->n_tris; t++) count[ms_bake_tri_state(sc, lm->uv, size, t)]++;
    static const char *const why[MS_UNBAKED_REASONS] = {
        NULL, NULL,
        "no area (zero-area triangles have no plane to receive light)",
        "no UVs (xatlas leaves out triangles of area at most FLT_EPSILON, 1.19e-7, once the unwrap has scaled the "
        "scene's extent to about 1024 units, weighted by their mesh's lightmap scale)",
        "UVs without area at this lightmap size",
        "UVs wholly outside the lightmap",
    };
    for (int r = MS_UNBAKED_NO_AREA; r < MS_UNBAKED_REASONS; r++)
        if (count[r])
        {
            char glb[96];   /* a glb leaves out what has no area (no normal), names the rest */
            if (r == MS_UNBAKED_NO_AREA) snprintf(glb, sizeof glb, "left out of a glb");
            else snprintf(glb, sizeof glb, "in a glb: primitives and materials named \"not baked: %s\"", ms_unbaked_name((ms_unbaked)r));
            ms_warn("%zu triangle%s not baked: %s; the lightmap has no texels of %s (%s)", count[r], count[r] == 1 ? "" : "s",
                    why[r], count[r] == 1 ? "it" : "them", glb);
        }
}
