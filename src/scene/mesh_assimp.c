/* OBJ, PLY, OFF and STL through assimp, from memory, after ms_preflight_* accepted the bytes: every
 * triangle of every mesh instance, in world space. */
#include "scene_internal.h"
#include "microshadow.h"
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

typedef struct walk_ctx {
    const struct aiScene *sc;
    ms_tri_soup *soup;
    size_t added, max_tris;
    int full;
    const ms_mtl_lib *mtl;   /* OBJ: the materials of its MTL files, by name (NULL: none) */
} walk_ctx;

/* The soup material of an assimp material: for OBJ by its name (usemtl) in the MTL files. */
static uint32_t material_of(const walk_ctx *w, const struct aiMesh *mesh)
{
    if (!w->mtl || mesh->mMaterialIndex >= w->sc->mNumMaterials) return MS_NO_MATERIAL;
    struct aiString name;
    if (aiGetMaterialString(w->sc->mMaterials[mesh->mMaterialIndex], AI_MATKEY_NAME, &name) != aiReturn_SUCCESS)
        return MS_NO_MATERIAL;
    return ms_mtl_find(w->mtl, name.data);
}

static int walk(walk_ctx *w, const struct aiNode *node, const struct aiMatrix4x4 *parent, int depth)
{
    if (depth > 256) return 0;   /* a cycle in a malformed file: stop rather than recurse forever */
    struct aiMatrix4x4 m;
    mat_mul(&m, parent, &node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= w->sc->mNumMeshes) continue;
        const struct aiMesh *mesh = w->sc->mMeshes[node->mMeshes[i]];
        const uint32_t material = material_of(w, mesh);
        /* Normals to world space by the cofactor matrix of m (the inverse transpose up to scale). */
        const float *M = &m.a1;
        float cof[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
                cof[3 * r + c] = M[4 * r1 + c1] * M[4 * r2 + c2] - M[4 * r1 + c2] * M[4 * r2 + c1];
            }
        for (unsigned f = 0; f < mesh->mNumFaces; f++) {
            const struct aiFace *face = &mesh->mFaces[f];
            if (face->mNumIndices != 3) continue;   /* points and lines cast no shadow */
            float v[9], uv[MS_SOUP_UV_SETS][6], nv[9];
            const float *uvp[MS_SOUP_UV_SETS] = { NULL };
            int ok = 1;
            for (int k = 0; k < 3; k++) {
                unsigned idx = face->mIndices[k];
                if (idx >= mesh->mNumVertices) { ok = 0; break; }
                xform(&m, &mesh->mVertices[idx], v + 3 * k);
                if (mesh->mNormals) {
                    const struct aiVector3D *q = &mesh->mNormals[idx];
                    for (int r = 0; r < 3; r++) nv[3 * k + r] = cof[3 * r] * q->x + cof[3 * r + 1] * q->y + cof[3 * r + 2] * q->z;
                }
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
            if (ms_soup_push_full(w->soup, v, uvp, material, mesh->mNormals ? nv : NULL)) return -1;
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
    ms_mtl_lib mtl;
    memset(&mtl, 0, sizeof mtl);
    if (!strcmp(ext, "obj")) {
        copy = malloc(len + 1);
        if (!copy) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
        memcpy(copy, buf, len + 1);
        /* ... and the MTL files are read here instead (mtl.c), relative to the OBJ. assimp's line ends are
         * \r, \n and \f, and it skips blanks at a line's start and takes any of them (or \0) after the
         * keyword: "\f  mtllib\f/x" is an mtllib line to it (the fuzzers' mtllib-absolute-leak input). */
        for (size_t i = 0; i + 6 <= len; i++) {
            size_t b = i;
            while (b > 0 && (copy[b - 1] == ' ' || copy[b - 1] == '\t')) b--;
            if (!((b == 0 || copy[b - 1] == '\n' || copy[b - 1] == '\r' || copy[b - 1] == '\f') && !memcmp(copy + i, "mtllib", 6) &&
                  (i + 6 == len || strchr(" \t\r\n\f", copy[i + 6]))))
                continue;
            copy[i] = '#';
            size_t a = i + 6, e = a;
            while (a < len && (copy[a] == ' ' || copy[a] == '\t')) a++;
            for (e = a; e < len && copy[e] != '\n' && copy[e] != '\r' && copy[e] != '\f'; e++) {}
            while (e > a && (copy[e - 1] == ' ' || copy[e - 1] == '\t')) e--;
            if (e == a) continue;
            char ref[4096];
            if (e - a >= sizeof ref) {
                snprintf(err, errlen, "%s: an mtllib path of more than %zu bytes", path, sizeof ref - 1);
                ms_mtl_lib_free(&mtl);
                free(copy);
                return -1;
            }
            snprintf(ref, sizeof ref, "%.*s", (int)(e - a), copy + a);
            if (ms_mtl_load(path, ref, soup, &mtl, err, errlen)) {
                ms_mtl_lib_free(&mtl);
                free(copy);
                return -1;
            }
        }
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
        ms_mtl_lib_free(&mtl);
        return -1;
    }
    struct aiMatrix4x4 id;
    memset(&id, 0, sizeof id);
    id.a1 = id.b2 = id.c3 = id.d4 = 1.0f;
    walk_ctx w = { sc, soup, 0, (len + 64) * MS_MAX_TRIS_PER_BYTE, 0, mtl.n ? &mtl : NULL };
    int rc = walk(&w, sc->mRootNode, &id, 0);
    aiReleaseImport(sc);
    ms_mtl_lib_free(&mtl);
    *added = w.added;
    if (rc && w.full) {
        snprintf(err, errlen, "%s: the mesh expands to more than %zu triangles (%d per byte of file)", path,
                 w.max_tris, MS_MAX_TRIS_PER_BYTE);
        return -1;
    }
    if (rc) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    return 0;
}
