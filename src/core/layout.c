/* ms_layout: the public structs' sizes and field offsets as this library was compiled, so that bindings
 * that mirror them (the Python module) check their mirror at load time instead of trusting a copy. A
 * field is listed here when a binding reads or writes it; adding a struct member elsewhere changes no
 * binding, since bindings place their fields by these offsets. */
#include "microshadow.h"
#include <stddef.h>
#include <string.h>

typedef struct layout_row {
    const char *structure, *field;   /* field NULL: the struct itself */
    size_t offset, size;
} layout_row;

#define STRUCT(s) { #s, NULL, 0, sizeof(s) }
#define FIELD(s, f) { #s, #f, offsetof(s, f), sizeof(((s *)0)->f) }

static const layout_row rows[] = {
    STRUCT(ms_vec3), FIELD(ms_vec3, x), FIELD(ms_vec3, y), FIELD(ms_vec3, z),
    STRUCT(ms_camera), FIELD(ms_camera, eye), FIELD(ms_camera, target), FIELD(ms_camera, up), FIELD(ms_camera, fov_y),
    FIELD(ms_camera, width), FIELD(ms_camera, height), FIELD(ms_camera, type), FIELD(ms_camera, fov),
    FIELD(ms_camera, ortho_height),
    STRUCT(ms_light), FIELD(ms_light, corner), FIELD(ms_light, edge_s), FIELD(ms_light, edge_t), FIELD(ms_light, emission),
    FIELD(ms_light, shape), FIELD(ms_light, texture), FIELD(ms_light, texture_width), FIELD(ms_light, texture_height),
    FIELD(ms_light, center), FIELD(ms_light, radius),
    STRUCT(ms_scene), FIELD(ms_scene, tri), FIELD(ms_scene, n_tris), FIELD(ms_scene, camera), FIELD(ms_scene, light),
    FIELD(ms_scene, samples), FIELD(ms_scene, load_s), FIELD(ms_scene, tri_mesh), FIELD(ms_scene, tri_uv),
    FIELD(ms_scene, n_meshes), FIELD(ms_scene, lights), FIELD(ms_scene, n_lights), FIELD(ms_scene, origin),
    FIELD(ms_scene, tri_object), FIELD(ms_scene, n_objects), FIELD(ms_scene, mesh_lightmap_scale),
    FIELD(ms_scene, materials), FIELD(ms_scene, n_materials), FIELD(ms_scene, tri_material), FIELD(ms_scene, tri_normal),
    STRUCT(ms_material), FIELD(ms_material, base_color), FIELD(ms_material, metallic), FIELD(ms_material, roughness),
    FIELD(ms_material, base_color_texture), FIELD(ms_material, alpha_texture), FIELD(ms_material, emissive),
    STRUCT(ms_scene_load_options), FIELD(ms_scene_load_options, allow_outside_paths),
    STRUCT(ms_render_options), FIELD(ms_render_options, method), FIELD(ms_render_options, pattern),
    FIELD(ms_render_options, samples), FIELD(ms_render_options, width), FIELD(ms_render_options, height),
    FIELD(ms_render_options, threads), FIELD(ms_render_options, seed), FIELD(ms_render_options, progress),
    FIELD(ms_render_options, progress_user), FIELD(ms_render_options, isa), FIELD(ms_render_options, embree_mode),
    FIELD(ms_render_options, embree_filter), FIELD(ms_render_options, traversal), FIELD(ms_render_options, no_filter),
    FIELD(ms_render_options, primary), FIELD(ms_render_options, consistent_primary),
    FIELD(ms_render_options, closed_cull), FIELD(ms_render_options, no_interior), FIELD(ms_render_options, no_merge),
    FIELD(ms_render_options, max_memory), FIELD(ms_render_options, stream), FIELD(ms_render_options, stream_rows),
    FIELD(ms_render_options, aa), FIELD(ms_render_options, aa_split), FIELD(ms_render_options, shading),
    STRUCT(ms_stats), FIELD(ms_stats, triangles), FIELD(ms_stats, load_s), FIELD(ms_stats, build_s),
    FIELD(ms_stats, setup_s), FIELD(ms_stats, primary_s), FIELD(ms_stats, shadow_s), FIELD(ms_stats, total_s),
    FIELD(ms_stats, samples), FIELD(ms_stats, threads), FIELD(ms_stats, width), FIELD(ms_stats, height),
    FIELD(ms_stats, samples_per_pixel), FIELD(ms_stats, method), FIELD(ms_stats, pattern), FIELD(ms_stats, kernel_isa),
    FIELD(ms_stats, traversal_isa), FIELD(ms_stats, visible_pixels), FIELD(ms_stats, shadow_rays),
    FIELD(ms_stats, penumbra_pixels), FIELD(ms_stats, shadow_factor_s), FIELD(ms_stats, filter_s),
    FIELD(ms_stats, n_counters), FIELD(ms_stats, counter_name), FIELD(ms_stats, counter), FIELD(ms_stats, shadow_cpu_s),
    FIELD(ms_stats, primary), FIELD(ms_stats, primary_setups), FIELD(ms_stats, primary_edge_evals),
    FIELD(ms_stats, primary_nodes), FIELD(ms_stats, occluders_culled), FIELD(ms_stats, interior_boxes), FIELD(ms_stats, occluders_merged), FIELD(ms_stats, receivers_on_merged),
    FIELD(ms_stats, memory_need), FIELD(ms_stats, memory_budget), FIELD(ms_stats, stream_rows), FIELD(ms_stats, aa),
    STRUCT(ms_frame), FIELD(ms_frame, width), FIELD(ms_frame, height), FIELD(ms_frame, vis), FIELD(ms_frame, shadow),
    FIELD(ms_frame, front), FIELD(ms_frame, rgb), FIELD(ms_frame, exposure), FIELD(ms_frame, stats),
    FIELD(ms_frame, shadow_spec), FIELD(ms_frame, n_lights),
    STRUCT(ms_points), FIELD(ms_points, n), FIELD(ms_points, position), FIELD(ms_points, normal),
    FIELD(ms_points, triangle), FIELD(ms_points, key),
    STRUCT(ms_points_options), FIELD(ms_points_options, method), FIELD(ms_points_options, pattern),
    FIELD(ms_points_options, samples), FIELD(ms_points_options, threads), FIELD(ms_points_options, seed),
    FIELD(ms_points_options, isa), FIELD(ms_points_options, progress), FIELD(ms_points_options, progress_user),
    FIELD(ms_points_options, embree_mode), FIELD(ms_points_options, embree_filter),
    FIELD(ms_points_options, max_memory),
    STRUCT(ms_bake_options), FIELD(ms_bake_options, points), FIELD(ms_bake_options, size), FIELD(ms_bake_options, uv_set),
    FIELD(ms_bake_options, dilate), FIELD(ms_bake_options, padding), FIELD(ms_bake_options, no_leak_fix),
    FIELD(ms_bake_options, pass), FIELD(ms_bake_options, pass_user), FIELD(ms_bake_options, texel_density), FIELD(ms_bake_options, uv_packing),
    FIELD(ms_bake_options, uv_cache),
    STRUCT(ms_lightmap), FIELD(ms_lightmap, frame), FIELD(ms_lightmap, position), FIELD(ms_lightmap, normal),
    FIELD(ms_lightmap, triangle), FIELD(ms_lightmap, uv), FIELD(ms_lightmap, n_tris), FIELD(ms_lightmap, texels),
    FIELD(ms_lightmap, unwrapped_tris), FIELD(ms_lightmap, unwrap_s), FIELD(ms_lightmap, raster_s),
    FIELD(ms_lightmap, texels_moved), FIELD(ms_lightmap, leak_s), FIELD(ms_lightmap, seam_mean), FIELD(ms_lightmap, seam_max),
    FIELD(ms_lightmap, seam_points), FIELD(ms_lightmap, excluded_tris), FIELD(ms_lightmap, unbaked_tris),
    FIELD(ms_lightmap, pages), FIELD(ms_lightmap, page), FIELD(ms_lightmap, page_fill),
    FIELD(ms_lightmap, n_objects), FIELD(ms_lightmap, object_uv_set), FIELD(ms_lightmap, object_scale_offset),
    FIELD(ms_lightmap, charts), FIELD(ms_lightmap, uv_cached),
    STRUCT(ms_bake_gltf_options), FIELD(ms_bake_gltf_options, no_textures), FIELD(ms_bake_gltf_options, no_shadowmask),
};

ms_status ms_layout(const char *structure, const char *field, size_t *offset, size_t *size)
{
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const layout_row *r = &rows[i];
        if (strcmp(r->structure, structure) != 0) continue;
        if (field ? !r->field || strcmp(r->field, field) != 0 : r->field != NULL) continue;
        if (offset) *offset = r->offset;
        if (size) *size = r->size;
        return MS_OK;
    }
    return MS_ERR_INVALID;
}
