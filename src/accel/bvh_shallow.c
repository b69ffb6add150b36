/* The shallow BVH of bvh.h: b's tree with every subtree of at most max_leaf triangles collapsed into a
 * leaf. Two passes over b's nodes: the triangle range of every subtree, then the copy. Why collapse
 * rather than build a second tree: the SAH build already found good splits; the frusta only want fewer
 * levels, and sharing the triangle order keeps prim ids (the receiver's own triangle) valid. */
#include "bvh.h"
#include <stdlib.h>
#include <string.h>

typedef struct range { uint32_t lo, hi; } range;

/* The triangle range of every node's subtree: leaves know theirs; an interior node spans from its left
 * child's first triangle to its right child's last. Children have larger indices than their parent
 * (pairs are allocated as the build descends), so one backward pass suffices. */
static void subtree_ranges(const ms_bvh *b, range *r)
{
    for (uint32_t i = b->n_nodes; i-- > 0;) {
        const ms_bvh_node *n = &b->nodes[i];
        if (n->count) { r[i].lo = n->first; r[i].hi = n->first + n->count; }
        else { r[i].lo = r[n->first].lo; r[i].hi = r[n->first + 1].hi; }
    }
}

int ms_bvh_shallow_build(ms_bvh_shallow *s, const ms_bvh *b, int max_leaf)
{
    memset(s, 0, sizeof *s);
    s->max_leaf = max_leaf < 1 ? 1 : max_leaf;
    range *r = malloc((size_t)b->n_nodes * sizeof *r);
    s->nodes = malloc((size_t)b->n_nodes * sizeof *s->nodes);   /* never more nodes than b */
    uint32_t *todo = malloc((size_t)b->n_nodes * 2 * sizeof *todo);
    if (!r || !s->nodes || !todo) { free(r); free(todo); ms_bvh_shallow_free(s); return -1; }
    subtree_ranges(b, r);
    /* Breadth-first copy: (source node, destination slot) pairs; children pairs stay adjacent. */
    uint32_t head = 0, tail = 0, used = 1;
    int depth_of_level = 0;
    todo[tail++] = 0;
    todo[tail++] = 0;
    uint32_t level_end = tail;
    while (head < tail) {
        if (head == level_end) { depth_of_level++; level_end = tail; }
        const uint32_t src = todo[head++], dst = todo[head++];
        const ms_bvh_node *n = &b->nodes[src];
        ms_bvh_node *o = &s->nodes[dst];
        *o = *n;
        const uint32_t cnt = r[src].hi - r[src].lo;
        if (n->count || cnt <= (uint32_t)s->max_leaf) {
            o->first = r[src].lo;
            o->count = cnt;
        } else {
            o->first = used;
            o->count = 0;
            todo[tail++] = n->first;     todo[tail++] = used;
            todo[tail++] = n->first + 1; todo[tail++] = used + 1;
            used += 2;
        }
    }
    s->n_nodes = used;
    s->depth = depth_of_level;
    free(r);
    free(todo);
    return 0;
}

void ms_bvh_shallow_free(ms_bvh_shallow *s)
{
    free(s->nodes);
    memset(s, 0, sizeof *s);
}
