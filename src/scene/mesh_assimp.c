/* Meshes through assimp: every triangle of every mesh instance, in world space. */
#include "scene_internal.h"
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int ms_soup_push(ms_tri_soup *soup, const float v[9])
{
    if (soup->n == soup->cap) {
        size_t cap = soup->cap ? 2 * soup->cap : 1024;
        float *t = realloc(soup->tri, cap * 9 * sizeof(float));
        if (!t) return -1;
        soup->tri = t;
        soup->cap = cap;
    }
    memcpy(soup->tri + 9 * soup->n, v, 9 * sizeof(float));
    soup->n++;
    return 0;
}

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

static int walk(const struct aiScene *sc, const struct aiNode *node, const struct aiMatrix4x4 *parent,
                ms_tri_soup *soup, size_t *added, int depth)
{
    if (depth > 256) return 0;   /* a cycle in a malformed file: stop rather than recurse forever */
    struct aiMatrix4x4 m;
    mat_mul(&m, parent, &node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= sc->mNumMeshes) continue;
        const struct aiMesh *mesh = sc->mMeshes[node->mMeshes[i]];
        for (unsigned f = 0; f < mesh->mNumFaces; f++) {
            const struct aiFace *face = &mesh->mFaces[f];
            if (face->mNumIndices != 3) continue;   /* points and lines cast no shadow */
            float v[9];
            int ok = 1;
            for (int k = 0; k < 3; k++) {
                unsigned idx = face->mIndices[k];
                if (idx >= mesh->mNumVertices) { ok = 0; break; }
                xform(&m, &mesh->mVertices[idx], v + 3 * k);
            }
            if (!ok) continue;
            if (ms_soup_push(soup, v)) return -1;
            (*added)++;
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        if (walk(sc, node->mChildren[c], &m, soup, added, depth + 1)) return -1;
    return 0;
}

int ms_mesh_load(const char *path, ms_tri_soup *soup, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) != 0) { snprintf(err, errlen, "%s: mesh file not found", path); return -1; }
    if (!S_ISREG(st.st_mode)) { snprintf(err, errlen, "%s: mesh is not a regular file", path); return -1; }
    FILE *probe = fopen(path, "rb");
    if (!probe) { snprintf(err, errlen, "%s: mesh file is not readable", path); return -1; }
    fclose(probe);
    const struct aiScene *sc = aiImportFile(path, aiProcess_Triangulate | aiProcess_SortByPType);
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
    size_t added = 0;
    int rc = walk(sc, sc->mRootNode, &id, soup, &added, 0);
    aiReleaseImport(sc);
    if (rc) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    if (added == 0) { snprintf(err, errlen, "%s: the mesh has no triangles", path); return -1; }
    for (size_t i = (soup->n - added) * 9; i < soup->n * 9; i++)
        if (!isfinite(soup->tri[i])) {
            snprintf(err, errlen, "%s: triangle %zu has a NaN or infinite coordinate", path,
                     i / 9 - (soup->n - added));
            return -1;
        }
    return 0;
}
