/* OBJ, PLY, OFF and STL through assimp, from memory, after ms_preflight_* accepted the bytes: every
 * triangle of every mesh instance, in world space. */
#include "scene_internal.h"
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void xform(const struct aiMatrix4x4 *m, const struct aiVector3D *p, float out[3])
{
    out[0] = m->a1 * p->x + m->a2 * p->y + m->a3 * p->z + m->a4;
    out[1] = m->b1 * p->x + m->b2 * p->y + m->b3 * p->z + m->b4;
    out[2] = m->c1 * p->x + m->c2 * p->y + m->c3 * p->z + m->c4;
}

static void mat_mul(struct aiMatrix4x4 *r, const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b)
{
    const float *A = &a->a1, *B = &b->a1;
    float R[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            float s = 0;
            for (int k = 0; k < 4; k++) s += A[4 * i + k] * B[4 * k + j];
            R[4 * i + j] = s;
        }
    memcpy(&r->a1, R, sizeof R);
}

typedef struct walk_ctx { const struct aiScene *sc; ms_tri_soup *soup; size_t added, max_tris; int full; } walk_ctx;

static int walk(walk_ctx *w, const struct aiNode *node, const struct aiMatrix4x4 *parent, int depth)
{
    if (depth > 256) return 0;   /* a cycle in a malformed file: stop rather than recurse forever */
    struct aiMatrix4x4 m;
    mat_mul(&m, parent, &node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= w->sc->mNumMeshes) continue;
        const struct aiMesh *mesh = w->sc->mMeshes[node->mMeshes[i]];
        for (unsigned f = 0; f < mesh->mNumFaces; f++) {
            const struct aiFace *face = &mesh->mFaces[f];
            if (face->mNumIndices != 3) continue;   /* points and lines cast no shadow */
            float v[9], uv[MS_SOUP_UV_SETS][6];
            const float *uvp[MS_SOUP_UV_SETS] = { NULL };
            int ok = 1;
            for (int k = 0; k < 3; k++) {
                unsigned idx = face->mIndices[k];
                if (idx >= mesh->mNumVertices) { ok = 0; break; }
                xform(&m, &mesh->mVertices[idx], v + 3 * k);
                /* UV channel s of the mesh is UV set s (baking); a channel may be absent. */
                for (int s = 0; s < MS_SOUP_UV_SETS && s < AI_MAX_NUMBER_OF_TEXTURECOORDS; s++) {
                    if (!mesh->mTextureCoords[s]) continue;
                    uv[s][2 * k] = mesh->mTextureCoords[s][idx].x;
                    uv[s][2 * k + 1] = mesh->mTextureCoords[s][idx].y;
                    uvp[s] = uv[s];
                }
            }
            if (!ok) continue;
            if (w->added == w->max_tris) { w->full = 1; return -1; }
            if (ms_soup_push_uv(w->soup, v, uvp)) return -1;
            w->added++;
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        if (walk(w, node->mChildren[c], &m, depth + 1)) return -1;
    return 0;
}

int ms_mesh_assimp(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                   size_t *added, char *err, size_t errlen)
{
    *added = 0;
    if (len > UINT32_MAX) { snprintf(err, errlen, "%s: mesh file too large for assimp", path); return -1; }
    /* An OBJ's "mtllib" would make assimp open that path itself (a FIFO there hangs it), and materials
     * cast no shadow: comment those lines out in a copy. */
    char *copy = NULL;
    if (!strcmp(ext, "obj")) {
        copy = malloc(len + 1);
        if (!copy) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
        memcpy(copy, buf, len + 1);
        for (size_t i = 0; i + 6 <= len; i++)
            if ((i == 0 || copy[i - 1] == '\n' || copy[i - 1] == '\r') && !memcmp(copy + i, "mtllib", 6)) copy[i] = '#';
        buf = copy;
    }
    /* From memory, so that assimp reads exactly the bytes that were checked; the hint picks the one
     * importer for the extension (no probing of the others). ValidateDataStructure rejects what the
     * importer built inconsistently instead of handing it on. */
    const struct aiScene *sc = aiImportFileFromMemory(buf, (unsigned)len,
        aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure, ext);
    free(copy);
    if (!sc || !sc->mRootNode) {
        const char *why = aiGetErrorString();
        /* assimp's messages can span lines; keep the first line only. */
        char first[256];
        snprintf(first, sizeof first, "%s", why && why[0] ? why : "unknown format");
        first[strcspn(first, "\r\n")] = 0;
        snprintf(err, errlen, "%s: assimp cannot read the mesh: %s", path, first);
        if (sc) aiReleaseImport(sc);
        return -1;
    }
    struct aiMatrix4x4 id;
    memset(&id, 0, sizeof id);
    id.a1 = id.b2 = id.c3 = id.d4 = 1.0f;
    walk_ctx w = { sc, soup, 0, (len + 64) * MS_MAX_TRIS_PER_BYTE, 0 };
    int rc = walk(&w, sc->mRootNode, &id, 0);
    aiReleaseImport(sc);
    *added = w.added;
    if (rc && w.full) {
        snprintf(err, errlen, "%s: the mesh expands to more than %zu triangles (%d per byte of file)", path,
                 w.max_tris, MS_MAX_TRIS_PER_BYTE);
        return -1;
    }
    if (rc) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    return 0;
}
