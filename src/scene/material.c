/* The soup's material list (scene_internal.h). */
#include "scene_internal.h"
#include "microshadow.h"
#include <stdlib.h>

long ms_soup_add_material(ms_tri_soup *soup, const ms_material *m)
{
    if (soup->n_mats >= MS_MAX_MATERIALS) return -1;
    ms_material *a = realloc(soup->mats, (soup->n_mats + 1) * sizeof *a);
    if (!a) return -1;
    soup->mats = a;
    a[soup->n_mats] = *m;
    return (long)soup->n_mats++;
}
