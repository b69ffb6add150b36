/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_footprint_impl.h): a
 * mask slot's per-point sample data, made when a triangle first may block the receiver (D; the pool: hpc_slots.c). */

/* The shear axis of each 16-sample packet exactly as the reference tracer chooses it (packet_shear), or -1
 * (lane by lane); for hpc-scanline also the Scanline frame, or -2 in kz[0]'s place for edge-on points. */
static void slot_setup(const shared *sh, chunk *c, int32_t s, const ms_shadow_query *q, const ms_grid *g)
{
    const ms_render_ctx *ctx = sh->ctx;
    const int k = sh->k;
    int8_t *kz = slot_kz(sh, c, s);
    /* ms_wt_packet_axis in the lanes (in scalar form it was a visible share of the cast): a packet is
     * 16 consecutive samples of one row (k >= 16), its directions formed as group_block16 forms them, the
     * axis the light's (sh->shear_axis) or else lane 0's largest, kept when every lane's |d| on it is at
     * least half its largest. */
    static const float lane_i[LANES] = { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15 };
    const l16 li0 = l16_load(lane_i), two = l16_set1(2.0f), zero = l16_set1(0.0f);
    for (int pk = 0; pk < sh->npk; pk++) {
        const int s0 = pk * LANES;
        const l16 li = l16_add(l16_set1((float)(s0 % k)), li0), lj = l16_set1((float)(s0 / k));
        l16 d[3], ad[3];
        float d0[3];
        for (int a = 0; a < 3; a++) {
            d[a] = l16_sub(l16_add(l16_add(l16_set1(g->p0[a]), l16_mul(li, l16_set1(g->ds[a]))), l16_mul(lj, l16_set1(g->dt[a]))),
                           l16_set1(q->p[a]));
            ad[a] = l16_abs(d[a]);
            float tmp[LANES];
            l16_store(tmp, d[a]);
            d0[a] = tmp[0];
        }
        const int z = ms_wt_max_axis(d0), pref = sh->shear_axis;
        const l16 m = l16_max(ad[0], l16_max(ad[1], ad[2]));
        const unsigned ok = l16_le(m, l16_mul(two, ad[z])) & l16_gt(m, zero);
        const unsigned okp = pref >= 0 ? l16_le(m, l16_mul(two, ad[pref])) & l16_gt(m, zero) : 0u;
        kz[pk] = (int8_t)(okp == 0xffffu ? pref : ok == 0xffffu ? z : -1);
    }
    /* kz[npk]: the axis every packet shares, or -1 (leaf_lanes_sample then needs no per-packet look-up) */
    int8_t uni = kz[0];
    for (int pk = 1; pk < sh->npk && uni >= 0; pk++) uni = kz[pk] == uni ? uni : -1;
    kz[sh->npk] = uni;
    if (sh->scanline) {
        ms_raster_frame *f = slot_frame(sh, c, s);
        float n[3], rel[3];
        v3_cross(n, g->ds, g->dt);
        v3_sub(rel, g->p0, q->p);
        const float h = fabsf(v3_dot(n, rel)), dd = v3_len(n) * v3_len(rel);
        if (!(h > EDGE_ON * dd) || ms_raster_frame_init(f, q->p, g, ctx->near, ctx->far, 0) != 0) f->k = 0;   /* edge-on */
    }
}

/* The mask and sample data of receiver r (D: made when a triangle first may block it, L59-L64). -1 when out
 * of memory. */
static int32_t slot_of(const shared *sh, chunk *c, uint32_t r, const ms_grid *g)
{
    int32_t s = sh->slot[r];
    if (s >= 0) return s;
    if ((s = hpc_slot_get(sh, c)) < 0) { c->failed = 1; return -1; }
    sh->slot[r] = s;
    memcpy(slot_mask(sh, c, s), sh->front + (size_t)sh->orig[r] * sh->mw, (size_t)sh->mw * sizeof(uint64_t));
    slot_setup(sh, c, s, &sh->q[r], g);
    return s;
}
