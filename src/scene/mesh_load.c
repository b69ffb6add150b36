/* Mesh files: chosen by extension (no probing), read by microshadow's own readers (OBJ, PLY, OFF, STL:
 * mesh_reader.h) or cgltf (glTF), then checked for finite coordinates. */
#include "scene_internal.h"
#include "mesh_reader.h"
#include "microshadow.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *extension(const char *path, char *ext, size_t n)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    ext[0] = 0;
    if (!dot || (slash && dot < slash)) return ext;
    size_t i = 0;
    for (dot++; *dot && i + 1 < n; dot++) ext[i++] = (char)tolower((unsigned char)*dot);
    ext[i] = 0;
    if (*dot) ext[0] = 0;   /* longer than any we know */
    return ext;
}

static int load_memory(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                       char *err, size_t errlen)
{
    size_t added = 0, before = soup->n;
    int rc;
    if (len == 0) { snprintf(err, errlen, "%s: the mesh file is empty", path); return -1; }
    if (!strcmp(ext, "gltf") || !strcmp(ext, "glb")) {
        rc = ms_mesh_gltf(buf, len, path, soup, &added, err, errlen);
    } else {
        int (*reader)(const char *, size_t, const char *, ms_tri_soup *, size_t *, char *, size_t) =
            !strcmp(ext, "obj") ? ms_mesh_obj : !strcmp(ext, "ply") ? ms_mesh_ply
          : !strcmp(ext, "off") ? ms_mesh_off : !strcmp(ext, "stl") ? ms_mesh_stl : NULL;
        if (!reader) {
            snprintf(err, errlen, "%s: unsupported mesh format '.%s' (microshadow reads .obj, .ply, .off, .stl, "
                     ".gltf, .glb)", path, ext);
            return -1;
        }
        rc = reader(buf, len, path, soup, &added, err, errlen);
    }
    if (rc) { soup->n = before; return -1; }
    if (added == 0) { snprintf(err, errlen, "%s: the mesh has no triangles", path); return -1; }
    for (size_t i = before * 9; i < soup->n * 9; i++)
        if (!isfinite(soup->tri[i])) {
            snprintf(err, errlen, "%s: triangle %zu has a NaN or infinite coordinate", path, i / 9 - before);
            soup->n = before;
            return -1;
        }
    return 0;
}

int ms_mesh_load_memory(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                        char *err, size_t errlen)
{
    int rc = load_memory(buf, len, ext, path, soup, err, errlen);
    if (rc) ms_one_line(err);
    return rc;
}

int ms_mesh_load(const char *path, ms_tri_soup *soup, char *err, size_t errlen)
{
    char ext[8];
    extension(path, ext, sizeof ext);
    char *buf;
    size_t len;
    if (ms_read_input(path, MS_MAX_MESH_BYTES, MS_INPUT_MESH, &buf, &len, err, errlen)) { ms_one_line(err); return -1; }
    int rc = ms_mesh_load_memory(buf, len, ext, path, soup, err, errlen);
    free(buf);
    return rc;
}
