/* The light-shape table (light_shape.h) and the public per-shape entry points that read it. */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <string.h>

extern const ms_light_shape_ops ms_light_rect, ms_light_disk_shape, ms_light_sphere_shape, ms_light_triangle_shape,
    ms_light_sun_shape, ms_light_ellipse_shape;

/* Indexed by ms_light_shape. */
static const ms_light_shape_ops *const shapes[] = {
    [MS_LIGHT_RECT] = &ms_light_rect,
    [MS_LIGHT_DISK] = &ms_light_disk_shape,
    [MS_LIGHT_SPHERE] = &ms_light_sphere_shape,
    [MS_LIGHT_TRIANGLE] = &ms_light_triangle_shape,
    [MS_LIGHT_SUN] = &ms_light_sun_shape,
};

const ms_light_shape_ops *ms_light_shape_of(ms_light_shape shape)
{
    return (unsigned)shape < sizeof shapes / sizeof *shapes ? shapes[shape] : NULL;
}

/* The scene file's shapes: one row per enum value, and the ellipse, a disk given by its parallelogram. */
static const ms_light_shape_ops *const named[] = {
    &ms_light_rect, &ms_light_disk_shape, &ms_light_sphere_shape, &ms_light_triangle_shape, &ms_light_sun_shape,
    &ms_light_ellipse_shape,
};

const ms_light_shape_ops *ms_light_shape_named(const char *name)
{
    for (size_t i = 0; i < sizeof named / sizeof *named; i++)
        if (strcmp(named[i]->name, name) == 0) return named[i];
    return NULL;
}

const ms_light_shape_ops *ms_light_shape_at(size_t i)
{
    return i < sizeof named / sizeof *named ? named[i] : NULL;
}

int ms_light_finite(const ms_light *l)
{
    const ms_light_shape_ops *o = ms_light_shape_of(l->shape);
    if (!o || !isfinite(l->emission.x) || !isfinite(l->emission.y) || !isfinite(l->emission.z)) return 0;
    if (o->finite) return o->finite(l);
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    if (!v3_finite(F.corner) || !v3_finite(F.edge_s) || !v3_finite(F.edge_t)) return 0;
    return v3_dot(F.normal, F.normal) > 0.0f;
}

int ms_light_shape_contains(ms_light_shape shape, float s, float t)
{
    const ms_light_shape_ops *o = ms_light_shape_of(shape);
    return !o || !o->contains || o->contains(s, t);
}

float ms_light_area(const ms_light *l)
{
    const ms_light_shape_ops *o = ms_light_shape_of(l->shape);
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    return o ? o->area(l, &F) : v3_len(F.normal);
}
