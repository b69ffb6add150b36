/* A program of someone else's: uses the installed microshadow through its public header only. The
 * built-in scene's light (y = 6, 2.5 x 2.5 around the y axis, emitting down) fully lights an open
 * point of the ground, a point inside the cube (x 1.5..3, y 0..1.5, z -1.5..0) sees none of it, and
 * a point under the floating plate lies in its penumbra; a small frame renders; the API's data links. Exit 0
 * when all hold. */
#include <microshadow.h>
#include <stdio.h>

int main(void)
{
    char err[512];
    ms_scene sc;
    if (ms_scene_default(&sc) != 0) { fprintf(stderr, "consumer: no default scene\n"); return 1; }
    ms_accel *acc = NULL;
    if (ms_accel_build(&sc, 0, &acc, err, sizeof err) != MS_OK) { fprintf(stderr, "consumer: %s\n", err); return 1; }
    const float pos[9] = { 5.0f, 0.0f, 5.0f, 2.25f, 0.5f, -0.75f, -0.3f, 0.0f, 2.0f };
    const float nor[9] = { 0, 1, 0, 0, 1, 0, 0, 1, 0 };
    ms_points pts = { 3, pos, nor, NULL, NULL };
    float v[3], s[3];
    ms_status st = ms_visibility_points(acc, NULL, &pts, NULL, v, s, NULL, NULL, err, sizeof err);
    ms_accel_free(acc);
    if (st != MS_OK) { fprintf(stderr, "consumer: %s: %s\n", ms_status_name(st), err); ms_scene_free(&sc); return 1; }
    printf("V open %.4f, inside the cube %.4f, under the plate %.4f\n", v[0], v[1], v[2]);
    int ok = v[0] == 1.0f && v[1] == 0.0f && v[2] > 0.0f && v[2] < 1.0f;
    ms_render_options o;
    ms_render_options_default(&o);
    o.width = 32;
    o.height = 24;
    o.samples = 256;
    ms_frame f;
    if (ms_render(&sc, &o, &f, err, sizeof err) != 0) { fprintf(stderr, "consumer: %s\n", err); ok = 0; }
    else {
        printf("frame %dx%d, %llu visible pixels, version %s\n", f.width, f.height,
               (unsigned long long)f.stats.visible_pixels, MS_VERSION_STRING);
        ok = ok && f.stats.visible_pixels > 0;
        /* the API's data too (a symbol the shared library must export, not only its functions) */
        printf("float image endings: %s %s\n", ms_float_image_suffixes[0], ms_float_image_suffixes[1]);
        ok = ok && ms_float_image_suffixes[0] && ms_float_image_suffixes[2] == NULL;
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
    return ok ? 0 : 1;
}
