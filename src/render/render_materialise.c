/* Procedural scenes for the methods that do not stream (render_materialise.h). */
#include "render_materialise.h"
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int ms_scene_materialise(const ms_scene *scene, int threads, ms_scene *soup, char *err, size_t errlen)
{
    const double t0 = omp_get_wtime();
    *soup = *scene;
    soup->procedural.type = MS_PROCEDURAL_NONE;
    soup->tri = scene->n_tris <= SIZE_MAX / (9 * sizeof(float)) ? malloc(scene->n_tris * 9 * sizeof(float)) : NULL;
    if (!soup->tri) {
        snprintf(err, errlen, "out of memory materialising %zu procedural triangles (methods hpc and hpc-scanline stream them)",
                 scene->n_tris);
        return -1;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t c = 0; c < scene->n_tris; c += 4096)
        ms_procedural_triangles(scene, c, scene->n_tris - c < 4096 ? scene->n_tris - c : 4096, soup->tri + 9 * c);
    soup->load_s = scene->load_s + (omp_get_wtime() - t0);   /* generation counts as loading */
    return 0;
}
