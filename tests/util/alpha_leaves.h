/* The leaf-card scene of the alpha-tested occluders' tests and its brute-force oracle (alpha_leaves.c). */
#ifndef MS_TEST_ALPHA_LEAVES_H
#define MS_TEST_ALPHA_LEAVES_H
#include "testutil.h"
#include "shadow/method.h"
#include "visibility/alpha.h"
#include "accel/bvh.h"
#include <stdint.h>

/* A triangle as the oracle knows it. */
#define MAX_TRIS 16
typedef struct otri {
    double v[3][3];
    double uv[3][2];   /* image coordinates: v = 0 at the top row */
    int alpha;         /* 1: a leaf card (alpha-tested), 0: the ground */
} otri;

/* The oracle's answer for one segment. */
enum { O_CLEAR = 0, O_OCCLUDED = 1, O_AMBIGUOUS = 2 };

/* The scene, its BVH and alpha set, and a frame's queries with the oracle's index of each query's triangle. */
typedef struct setup {
    ms_scene sc;
    ms_bvh bvh;
    ms_alpha *alpha;
    ms_render_ctx ctx;
    ms_shadow_query *q;
    int nq;
    int *self;          /* oracle index of each query's triangle */
    int *oracle_tri;    /* per leaf-order prim: oracle index */
    char dir[4096];
} setup;

/* The oracle's masks for the context's pattern: occluded and ambiguous bits, over the front samples. */
typedef struct oracle_masks {
    uint64_t *front, *vis, *amb;
    long front_n, amb_alpha, amb_geom, occluded_n;
} oracle_masks;

/* The oracle's triangles (the ground and the cards), as load_scene wrote them. */
extern otri al_tris[MAX_TRIS];
extern int al_n_tris;

/* The mask's bilinear alpha at image coordinates (u, v) in [0, 1]^2 (v = 0 the top row), in [0, 1]. */
double al_oracle_alpha(double u, double v);
/* Writes the scene as "gltf" or "obj" into a temp dir (its path into dir_out) and loads it; fills al_tris. */
void al_load_scene(const char *format, ms_scene *sc, char *dir_out, size_t dn);
/* Segment or ray o + t d against oracle triangle T in double (alpha_leaves.c says what near_edge flags). */
int al_oracle_hit(const otri *T, const double o[3], const double d[3], double tmin, double tmax, double *t, double *b1,
                  double *b2, int *near_edge);
/* T's alpha at barycentrics (b1, b2). */
double al_card_alpha(const otri *T, double b1, double b2);
/* The segment P -> L against every oracle triangle but self: O_CLEAR, O_OCCLUDED or O_AMBIGUOUS (*why: alpha 1,
 * geometry 2). */
int al_oracle_segment(const float P[3], const float L[3], int self, int *why);
/* The oracle index of a library triangle (9 floats), or fails the test. */
int al_oracle_index(const float *tri);
/* The scene in format, its BVH, alpha set and a size x size frame's queries; al_setup_free frees it. */
void al_setup_make(setup *s, const char *format, int size);
void al_setup_free(setup *s);
/* The oracle's masks for ctx's pattern; al_oracle_free frees them. */
void al_oracle_run(const setup *s, const ms_render_ctx *ctx, oracle_masks *om);
void al_oracle_free(oracle_masks *om);
/* Method name's masks on the setup's queries against the oracle: the samples that differ outside the ambiguous
 * ones (printed with label). */
long al_method_vs_oracle(const setup *s, const ms_render_ctx *ctx, const char *name, const oracle_masks *om,
                         const char *label);

#endif
