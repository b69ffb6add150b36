/* Masks on demand (D, sec. 3.3): a receiver's slot (its mask and per-point sample data) taken from its chunk's
 * pool when a triangle first may block it, given back at full umbra; the umbra bits recorded (A). Compiled
 * once (hpc_engine.h; the slot's set-up, in the lanes, in hpc_slots_impl.h). */
#include "hpc_engine.h"
#include <stdlib.h>

int32_t hpc_slot_get(const shared *sh, chunk *c)
{
    int32_t s;
    if (c->n_free) s = c->free_list[--c->n_free];
    else {
        if (c->n_slots == c->cap_slots) {
            const int32_t cap = c->cap_slots ? 2 * c->cap_slots : 256;
            uint8_t *p = realloc(c->pool, (size_t)cap * sh->slot_bytes);
            int32_t *fl = realloc(c->free_list, (size_t)cap * sizeof *fl);
            if (p) c->pool = p;
            if (fl) c->free_list = fl;
            if (!p || !fl) return -1;
            c->cap_slots = cap;
        }
        s = c->n_slots++;
    }
    c->live++;
    if (c->live > c->peak) c->peak = c->live;
    c->cnt[C_MASKS_ALLOCATED]++;
    return s;
}

void hpc_slot_put(chunk *c, int32_t s)
{
    c->free_list[c->n_free++] = s;
    c->live--;
}

/* Receiver r's open groups after a triangle (L72-L75): its umbra bits, and at full umbra its mask back. */
void hpc_record_umbra(const shared *sh, chunk *c, uint32_t r, int32_t s, uint64_t gu)
{
    if (hpc_sw(sh, MS_HPC_OFF_UMBRA)) return;   /* A off: umbra found by casting is not recorded */
    sh->gumbra[r] = gu;
    if (gu == sh->all_groups) {
        sh->full[r] = 1;
        if (!hpc_sw(sh, MS_HPC_OFF_ON_DEMAND)) {   /* D: the mask goes back (L75) */
            hpc_slot_put(c, s);
            sh->slot[r] = -1;
        }
        c->umbra_in_tree++;
        c->cnt[C_FULL_UMBRA_POINTS]++;
    }
}
