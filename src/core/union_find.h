/* Union-find over indices 0..n-1 (parent[i] = i to start), with path halving. A union keeps the smaller root,
 * so every set's root is its smallest member: numbering sets "when a root is first met" in index order gives
 * them the order of their first members, which the callers rely on for results independent of thread count. */
#ifndef MS_UNION_FIND_H
#define MS_UNION_FIND_H
#include <stdint.h>

static inline uint32_t ms_uf_find(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

static inline void ms_uf_union(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = ms_uf_find(parent, a);
    b = ms_uf_find(parent, b);
    if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

#endif
