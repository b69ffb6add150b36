/* --stats: timings, sizes and the method's counters as JSON (cJSON). */
#include "microshadow.h"
#include "microshadow.h"
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

ms_status ms_stats_write_stream(const ms_frame *f, FILE *out, const char *path, char *err, size_t errlen)
{
    const ms_stats *s = &f->stats;
    cJSON *o = cJSON_CreateObject();
    if (!o) { snprintf(err, errlen, "%s: out of memory", path); return MS_ERR_NO_MEMORY; }
    cJSON_AddStringToObject(o, "version", MS_VERSION_STRING);
    cJSON_AddStringToObject(o, "method", s->method);
    cJSON_AddStringToObject(o, "pattern", s->pattern);
    cJSON_AddStringToObject(o, "kernel_isa", s->kernel_isa ? s->kernel_isa : "none");
    cJSON_AddStringToObject(o, "traversal_isa", s->traversal_isa ? s->traversal_isa : "none");
    cJSON_AddNumberToObject(o, "triangles", (double)s->triangles);
    cJSON_AddNumberToObject(o, "width", s->width);
    cJSON_AddNumberToObject(o, "height", s->height);
    cJSON_AddNumberToObject(o, "samples", s->samples);
    cJSON_AddNumberToObject(o, "samples_per_pixel", s->samples_per_pixel);
    cJSON_AddNumberToObject(o, "threads", s->threads);
    cJSON_AddNumberToObject(o, "load_s", s->load_s);
    cJSON_AddNumberToObject(o, "build_s", s->build_s);
    cJSON_AddNumberToObject(o, "setup_s", s->setup_s);
    cJSON_AddStringToObject(o, "primary", s->primary ? s->primary : "none");
    cJSON_AddNumberToObject(o, "primary_s", s->primary_s);
    cJSON_AddNumberToObject(o, "primary_setups", (double)s->primary_setups);
    cJSON_AddNumberToObject(o, "primary_edge_evals", (double)s->primary_edge_evals);
    cJSON_AddNumberToObject(o, "primary_nodes", (double)s->primary_nodes);
    cJSON_AddNumberToObject(o, "occluders_culled", (double)s->occluders_culled);
    cJSON_AddNumberToObject(o, "interior_boxes", (double)s->interior_boxes);
    cJSON_AddNumberToObject(o, "occluders_merged", (double)s->occluders_merged);
    cJSON_AddNumberToObject(o, "receivers_on_merged", (double)s->receivers_on_merged);
    cJSON_AddNumberToObject(o, "shadow_s", s->shadow_s);
    cJSON_AddNumberToObject(o, "shadow_cpu_s", s->shadow_cpu_s);
    cJSON_AddNumberToObject(o, "total_s", s->total_s);
    cJSON_AddNumberToObject(o, "visible_pixels", (double)s->visible_pixels);
    cJSON_AddNumberToObject(o, "shadow_rays", (double)s->shadow_rays);
    cJSON_AddNumberToObject(o, "penumbra_pixels", (double)s->penumbra_pixels);
    cJSON_AddNumberToObject(o, "shadow_factor_s", s->shadow_factor_s);
    cJSON_AddNumberToObject(o, "filter_s", s->filter_s);
    cJSON_AddNumberToObject(o, "memory_need", (double)s->memory_need);
    cJSON_AddNumberToObject(o, "stream_rows", s->stream_rows);
    cJSON_AddNumberToObject(o, "memory_budget", (double)s->memory_budget);
    cJSON_AddNumberToObject(o, "shadow_rays_per_s", s->shadow_s > 0 ? (double)s->shadow_rays / s->shadow_s : 0.0);
    cJSON *c = cJSON_AddObjectToObject(o, "counters");
    for (int i = 0; c && i < s->n_counters; i++) cJSON_AddNumberToObject(c, s->counter_name[i], (double)s->counter[i]);
    char *text = cJSON_Print(o);
    cJSON_Delete(o);
    if (!text) { snprintf(err, errlen, "%s: out of memory", path); return MS_ERR_NO_MEMORY; }
    fputs(text, out);
    fputc('\n', out);
    free(text);
    return MS_OK;   /* write errors surface at the flush */
}
