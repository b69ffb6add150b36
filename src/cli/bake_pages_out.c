/* A paged lightmap's outputs (bake_pages_out.h). The lightmap's frame holds the pages stacked; each page is
 * copied into a frame of its own and every image output is written once per page, all of them in one
 * ms_outputs_write so that the set stays all or nothing. The writers are the library's; a wrapper finds
 * its page by the path it is asked to write (the writer callback has no user pointer). */
#include "bake_pages_out.h"
#include <stdlib.h>
#include <string.h>

typedef struct page_out {
    char *path;
    ms_frame frame;
    ms_output_write_fn write;
} page_out;

static page_out g_out[MS_MAX_OUTPUTS];
static int g_n;
static const ms_lightmap *g_lm;
static ms_frame *g_frames;
static int g_pages;

static ms_status write_page(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen)
{
    (void)f;
    for (int i = 0; i < g_n; i++)
        if (!strcmp(g_out[i].path, name)) return g_out[i].write(&g_out[i].frame, out, name, err, errlen);
    snprintf(err, errlen, "%s: no lightmap page for this output", name);
    return MS_ERR_INVALID;
}

void ms_bake_uv_cache_source(const ms_lightmap *lm) { g_lm = lm; }

ms_status ms_bake_uv_cache_write(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen)
{
    (void)f;
    return ms_bake_write_uv_cache(g_lm, out, name, err, errlen);
}

char *ms_bake_uv_cache_default(const char *exr_path)
{
    const char *slash = strrchr(exr_path, '/'), *dot = strrchr(exr_path, '.');
    const size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - exr_path) : strlen(exr_path);
    char *p = malloc(stem + sizeof ".uvcache");
    if (!p) return NULL;
    memcpy(p, exr_path, stem);
    memcpy(p + stem, ".uvcache", sizeof ".uvcache");
    return p;
}

static int is_image(ms_output_write_fn w)
{
    return w == ms_exr_write_stream || w == ms_png_write_stream || w == ms_vis_write_stream || w == ms_shadow_write_stream;
}

static char *dup_path(const char *s)
{
    char *p = malloc(strlen(s) + 1);
    if (p) memcpy(p, s, strlen(s) + 1);
    return p;
}

static char *page_path(const char *path, int page)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    const size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - path) : strlen(path);
    char *p = malloc(strlen(path) + 16);
    if (!p) return NULL;
    memcpy(p, path, stem);
    sprintf(p + stem, ".%d%s", page, path + stem);
    return p;
}

/* Page p of lm's frame as a frame of its own (every light's planes). */
static int page_frame(const ms_lightmap *lm, int p, ms_frame *out)
{
    const ms_frame *f = &lm->frame;
    const int size = f->width, nl = f->n_lights > 1 ? f->n_lights : 1;
    const size_t per = (size_t)size * size, all = (size_t)f->width * f->height;
    *out = *f;
    out->height = size;
    out->stats.height = size;
    out->shadow_spec = NULL;
    out->vis = malloc(nl * per * sizeof(float));
    out->shadow = malloc(nl * per * sizeof(float));
    out->front = f->front ? malloc(nl * per * sizeof(uint16_t)) : NULL;
    out->rgb = malloc(3 * per * sizeof(float));
    if (!out->vis || !out->shadow || (f->front && !out->front) || !out->rgb) return -1;
    for (int l = 0; l < nl; l++) {
        memcpy(out->vis + l * per, f->vis + l * all + p * per, per * sizeof(float));
        memcpy(out->shadow + l * per, f->shadow + l * all + p * per, per * sizeof(float));
        if (f->front) memcpy(out->front + l * per, f->front + l * all + p * per, per * sizeof(uint16_t));
    }
    memcpy(out->rgb, f->rgb + 3 * p * per, 3 * per * sizeof(float));
    return 0;
}

int ms_bake_pages_out(const ms_lightmap *lm, ms_output *outs, int *n, char *err, size_t errlen)
{
    const int pages = lm->pages > 1 ? lm->pages : 1;
    if (pages == 1) return 0;
    int img = 0;
    const int given = *n;
    for (int k = 0; k < given; k++) img += outs[k].path && is_image(outs[k].write);
    if (*n + img * (pages - 1) > MS_MAX_OUTPUTS) {
        snprintf(err, errlen, "the lightmap has %d pages: %d image outputs per page exceed the %d files one bake may write "
                 "(fewer outputs, a larger --size or a lower --texel-density)", pages, img, MS_MAX_OUTPUTS);
        return -1;
    }
    ms_frame *frames = calloc((size_t)pages, sizeof *frames);
    if (!frames) { snprintf(err, errlen, "out of memory for the lightmap's pages"); return -1; }
    int rc = 0;
    for (int p = 0; p < pages && !rc; p++) rc = page_frame(lm, p, &frames[p]);
    for (int k = 0; k < given && !rc; k++) {
        if (!outs[k].path || !is_image(outs[k].write)) continue;
        const ms_output_write_fn inner = outs[k].write;
        for (int p = 0; p < pages && !rc; p++) {
            page_out *g = &g_out[g_n];
            g->path = p ? page_path(outs[k].path, p) : dup_path(outs[k].path);
            g->write = inner;
            g->frame = frames[p];   /* shared between the outputs of page p; freed once (below) */
            if (!g->path) { rc = -1; break; }
            g_n++;
            if (p) {
                outs[*n] = outs[k];
                outs[*n].path = g->path;
                outs[*n].write = write_page;
                (*n)++;
            } else
                outs[k].write = write_page;
        }
    }
    if (rc) snprintf(err, errlen, "out of memory for the lightmap's pages");
    /* the page frames are referenced by g_out; keep the array for ms_bake_pages_out_free */
    g_frames = frames;
    g_pages = pages;
    return rc;
}

void ms_bake_pages_out_free(void)
{
    for (int i = 0; i < g_n; i++) free(g_out[i].path);
    for (int p = 0; p < g_pages; p++) {
        free(g_frames[p].vis);
        free(g_frames[p].shadow);
        free(g_frames[p].front);
        free(g_frames[p].rgb);
    }
    free(g_frames);
    g_frames = NULL;
    g_n = g_pages = 0;
}
