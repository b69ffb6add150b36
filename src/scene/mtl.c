/* OBJ materials: MTL files read here rather than by assimp (which would open the paths itself, and
 * blocks on a FIFO): regular files only, at most MS_MAX_MESH_BYTES, one line at a time. Mapped onto
 * metallic-roughness (docs/shading.md): base colour Kd (default 0.8) times map_Kd, alpha d (or 1 - Tr),
 * metallic Pm (default 0), roughness Pr, else from the Phong exponent Ns as GGX alpha = sqrt(2 / (Ns + 2))
 * (Walter et al. 2007, eq. 33: the Beckmann width of a Phong lobe), else 1. map_d makes the material
 * alpha-tested (MS_ALPHA_MASK_MAP, cutoff 0.5, alpha = d times the map); d alone (no map) stays opaque for
 * visibility: a uniformly translucent surface is not a cut-out. Ke is the emission (linear radiance). */
#include "scene_internal.h"
#include "microshadow.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ms_mtl_lib_free(ms_mtl_lib *lib)
{
    for (size_t i = 0; i < lib->n; i++) free(lib->names[i]);
    free(lib->names);
    free(lib->index);
    for (size_t i = 0; i < lib->n_tex; i++) free(lib->tex_path[i]);
    free(lib->tex_path);
    free(lib->tex_id);
    memset(lib, 0, sizeof *lib);
}

uint32_t ms_mtl_find(const ms_mtl_lib *lib, const char *name)
{
    for (size_t i = lib->n; i-- > 0;)
        if (!strcmp(lib->names[i], name)) return lib->index[i];
    return MS_NO_MATERIAL;
}

/* The soup texture of file `full`, read (and warned about) once per library; -2 when out of memory. */
static long texture(ms_mtl_lib *lib, ms_tri_soup *soup, const char *full)
{
    for (size_t i = 0; i < lib->n_tex; i++)
        if (!strcmp(lib->tex_path[i], full)) return lib->tex_id[i];
    char err[1024];
    const long t = ms_soup_add_texture_file(soup, full, 1, err, sizeof err);
    if (t < 0) ms_warn_material("%s: texture ignored", err);
    char **np = realloc(lib->tex_path, (lib->n_tex + 1) * sizeof *np);
    if (!np) return -2;
    lib->tex_path = np;
    long *ni = realloc(lib->tex_id, (lib->n_tex + 1) * sizeof *ni);
    if (!ni) return -2;
    lib->tex_id = ni;
    if (!(lib->tex_path[lib->n_tex] = strdup(full))) return -2;
    lib->tex_id[lib->n_tex++] = t;
    return t;
}

static float clamp01(float x) { return x >= 0.0f ? (x <= 1.0f ? x : 1.0f) : 0.0f; }   /* NaN -> 0 */

/* Up to n floats from s; the number read. */
static int floats(const char *s, float *out, int n)
{
    int k = 0;
    while (k < n) {
        char *end;
        const float v = strtof(s, &end);
        if (end == s) break;
        out[k++] = v;
        s = end;
    }
    return k;
}

typedef struct pending {
    ms_material m;
    int have_pr, have_ns;
    float ns;
    char name[256];
    int open;
} pending;

static int flush(pending *p, ms_tri_soup *soup, ms_mtl_lib *lib)
{
    if (!p->open) return 0;
    p->open = 0;
    if (!p->have_pr && p->have_ns && isfinite(p->ns)) {
        const float alpha = sqrtf(2.0f / (fmaxf(p->ns, 0.0f) + 2.0f));
        p->m.roughness = clamp01(sqrtf(alpha));
    }
    const long idx = ms_soup_add_material(soup, &p->m, p->name);
    if (idx < 0) return -1;
    char **nn = realloc(lib->names, (lib->n + 1) * sizeof *nn);
    if (!nn) return -1;
    lib->names = nn;
    uint32_t *ni = realloc(lib->index, (lib->n + 1) * sizeof *ni);
    if (!ni) return -1;
    lib->index = ni;
    if (!(lib->names[lib->n] = strdup(p->name))) return -1;
    lib->index[lib->n++] = (uint32_t)idx;
    return 0;
}

int ms_mtl_load(const char *owner, const char *ref, ms_tri_soup *soup, ms_mtl_lib *lib, char *err, size_t errlen)
{
    /* The MTL file, then each map it names, must stay inside the folder of the file naming it. */
    char path[4096], why[1024];
    if (ms_resolve_inside(owner, ref, soup->allow_outside_paths, "mtllib", path, sizeof path, err, errlen)) return -1;
    char *buf;
    size_t len;
    if (ms_read_input(path, MS_MAX_MESH_BYTES, MS_INPUT_AUX, &buf, &len, why, sizeof why)) {
        ms_warn_material("%s: materials ignored", why);
        return 0;
    }
    const int rc = ms_mtl_load_memory(buf, len, path, soup, lib, err, errlen);
    free(buf);
    return rc;
}

int ms_mtl_load_memory(char *buf, size_t len, const char *path, ms_tri_soup *soup, ms_mtl_lib *lib, char *err,
                       size_t errlen)
{
    (void)len;   /* buf[len] == 0; a NUL before it ends the file */
    pending p;
    memset(&p, 0, sizeof p);
    int rc = 0;
    char *line = buf;
    while (line && *line && !rc) {
        char *next = strpbrk(line, "\r\n");
        if (next) *next++ = 0;
        while (*line == ' ' || *line == '\t') line++;
        char *arg = line;
        while (*arg && !isspace((unsigned char)*arg)) arg++;
        const size_t kl = (size_t)(arg - line);
        while (*arg == ' ' || *arg == '\t') arg++;
        /* trailing blanks off the argument */
        for (size_t e = strlen(arg); e > 0 && isspace((unsigned char)arg[e - 1]); e--) arg[e - 1] = 0;
#define KEY(k) (kl == sizeof k - 1 && !strncmp(line, k, kl))
        float f[3];
        if (KEY("newmtl")) {
            if (flush(&p, soup, lib)) { rc = -1; break; }
            memset(&p, 0, sizeof p);
            p.open = 1;
            snprintf(p.name, sizeof p.name, "%s", arg);
            p.m = (ms_material){ .base_color = { 0.8f, 0.8f, 0.8f, 1.0f }, .metallic = 0.0f, .roughness = 1.0f, .base_color_texture = -1,
                                 .alpha_cutoff = 0.5f, .alpha_texture = -1 };
        } else if (!p.open) {
            /* statements before the first newmtl belong to no material */
        } else if (KEY("Kd") && floats(arg, f, 3) == 3) {
            for (int c = 0; c < 3; c++) p.m.base_color[c] = clamp01(f[c]);
        } else if (KEY("d") && floats(arg, f, 1) == 1) {
            p.m.base_color[3] = clamp01(f[0]);
        } else if (KEY("Tr") && floats(arg, f, 1) == 1) {
            p.m.base_color[3] = clamp01(1.0f - f[0]);
        } else if (KEY("Ke") && floats(arg, f, 3) == 3) {
            /* emission (linear radiance), bounded like glTF's; an emissive material may also become a light
             * (scene file "lights_from_emissive", scene_emitters.c) */
            for (int c = 0; c < 3; c++) p.m.emissive[c] = f[c] >= 0.0f && f[c] <= MS_MAX_RADIANCE ? f[c] : 0.0f;
        } else if (KEY("Pm") && floats(arg, f, 1) == 1) {
            p.m.metallic = clamp01(f[0]);
        } else if (KEY("Pr") && floats(arg, f, 1) == 1) {
            p.m.roughness = clamp01(f[0]);
            p.have_pr = 1;
        } else if (KEY("Ns") && floats(arg, f, 1) == 1) {
            p.ns = f[0];
            p.have_ns = 1;
        } else if ((KEY("map_Kd") || KEY("map_d")) && *arg) {
            /* Options (-bm 1, -s 1 1 1, ...) come first: the file is the last word. */
            const int is_d = KEY("map_d");
            const char *file = strrchr(arg, ' ');
            const char *tab = strrchr(arg, '\t');
            if (tab && (!file || tab > file)) file = tab;
            file = file ? file + 1 : arg;
            char full[4096];
            if (ms_resolve_inside(path, file, soup->allow_outside_paths, is_d ? "map_d" : "map_Kd", full, sizeof full,
                                  err, errlen)) {
                rc = -2;
                break;
            } else {
                const long t = texture(lib, soup, full);
                if (t == -2) { rc = -1; break; }
                if (t >= 0 && !is_d) { p.m.base_color_texture = (int32_t)t; p.m.base_color_uv = 0; }
                /* map_d: alpha-tested at 0.5 against d times the map (docs/shading.md); a map that cannot be
                 * read leaves the material opaque (one warning, above). */
                if (t >= 0 && is_d) { p.m.alpha_mode = MS_ALPHA_MASK_MAP; p.m.alpha_cutoff = 0.5f; p.m.alpha_texture = (int32_t)t; }
            }
        }
#undef KEY
        line = next;
    }
    if (!rc) rc = flush(&p, soup, lib);
    if (rc == -1) snprintf(err, errlen, "%s: out of memory reading its materials", path);
    if (rc) ms_one_line(err);
    return rc ? -1 : 0;
}
