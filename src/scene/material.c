/* The soup's material list (scene_internal.h). */
#include "scene_internal.h"
#include "microshadow.h"
#include <stdlib.h>
#include <string.h>

long ms_soup_add_material(ms_tri_soup *soup, const ms_material *m, const char *name)
{
    if (soup->n_mats >= MS_MAX_MATERIALS) return -1;
    char *copy = name && *name ? strdup(name) : NULL;
    if (name && *name && !copy) return -1;
    char **nn = realloc(soup->mat_names, (soup->n_mats + 1) * sizeof *nn);
    if (!nn) { free(copy); return -1; }
    soup->mat_names = nn;
    ms_material *a = realloc(soup->mats, (soup->n_mats + 1) * sizeof *a);
    if (!a) { free(copy); return -1; }
    soup->mats = a;
    a[soup->n_mats] = *m;
    nn[soup->n_mats] = copy;
    return (long)soup->n_mats++;
}

void ms_soup_free_names(ms_tri_soup *soup)
{
    for (size_t i = 0; soup->mat_names && i < soup->n_mats; i++) free(soup->mat_names[i]);
    free(soup->mat_names);
    soup->mat_names = NULL;
}
