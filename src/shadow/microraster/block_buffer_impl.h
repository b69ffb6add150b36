/* The questions the block traversal (block_raster_impl.h) asks of a pixel's k x k buffer of visible samples:
 * the rectangle of what is left, how many are left, whether any is left in a box of samples. Instantiated per
 * k with the includer (core/perk_each.h: MS_K, MS_WORD) for each ISA; no include guard for that reason. Every
 * instance returns the same answer as the portable loop it replaces. */

/* The rectangle of the visible samples of a buffer within rows j0..j1 (the others known empty):
 * columns r[0]..r[1], rows r[2]..r[3]; 0 if none. */
static inline int MS_KFN(br_live_rect)(const MS_WORD *buf, int j0, int j1, int r[4])
{
#if defined(MS_TARGET_AVX512) || (defined(MS_TARGET_AVX2) && MS_K <= 32)
    /* The whole buffer in vector registers (one to eight), with no loop over rows: rows outside j0..j1 are
     * empty (a rectangle only shrinks, and it bounds every visible sample), so reading them changes
     * nothing, and the loop's data-dependent trip count is gone; with AVX2 at k = 64 (sixteen registers)
     * the scalar loop stays, the whole buffer costing more than the rows it skips. */
    (void)j0;
    (void)j1;
    uint64_t rows = 0;
#if MS_K == 16
    const __m256i v = _mm256_loadu_si256((const __m256i *)buf);
    rows = _pext_u32((uint32_t)~_mm256_movemask_epi8(_mm256_cmpeq_epi16(v, _mm256_setzero_si256())), 0x55555555u);
    __m128i o = _mm_or_si128(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
#else
    __m256i acc = _mm256_setzero_si256();
    for (int q = 0; q < MS_K / (32 / (int)sizeof(MS_WORD)); q++) {   /* unrolled: the trip count is fixed */
        const __m256i v = _mm256_loadu_si256((const __m256i *)buf + q);
        acc = _mm256_or_si256(acc, v);
#if MS_K == 32
        rows |= (uint64_t)(uint8_t)~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(v, _mm256_setzero_si256()))) << (8 * q);
#else   /* AVX-512 at k = 64 */
        rows |= (uint64_t)(uint8_t)(~_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(v, _mm256_setzero_si256()))) & 15) << (4 * q);
#endif
    }
    __m128i o = _mm_or_si128(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
#endif
    if (!rows) return 0;
    o = _mm_or_si128(o, _mm_unpackhi_epi64(o, o));
    uint64_t a = (uint64_t)_mm_cvtsi128_si64(o);
#if MS_K <= 32
    a |= a >> 32;
#if MS_K == 16
    a |= a >> 16;
#endif
    a &= (MS_WORD)~(MS_WORD)0;
#endif
#else
    /* Branch-free: the rows' emptiness is data, and a branch on it mispredicts. */
    MS_WORD any = 0;
    uint64_t rows = 0;
    for (int j = j0; j <= j1; j++) { any |= buf[j]; rows |= (uint64_t)(buf[j] != 0) << j; }
    if (!any) return 0;
    const uint64_t a = (uint64_t)any;
#endif
    r[0] = __builtin_ctzll(a);
    r[1] = 63 - __builtin_clzll(a);
    r[2] = __builtin_ctzll(rows);
    r[3] = 63 - __builtin_clzll(rows);
    return 1;
}

/* The visible samples of a buffer (the leaf cache's scores). */
static inline int MS_KFN(br_count)(const MS_WORD *w)
{
#if defined(MS_TARGET_AVX512) && MS_K >= 32
    /* Nibble table per byte (no VPOPCNTDQ needed), summed bytewise (at most 8 per register and byte, 64 in
     * all), then by 8-byte group. */
    const __m512i lut = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4));
    const __m512i low = _mm512_set1_epi8(0x0f);
    __m512i acc = _mm512_setzero_si512();
    for (int q = 0; q < MS_K * MS_K / 512; q++) {   /* unrolled: the trip count is fixed */
        const __m512i v = _mm512_loadu_si512((const void *)(w + q * (512 / MS_K)));
        acc = _mm512_add_epi8(acc, _mm512_add_epi8(_mm512_shuffle_epi8(lut, _mm512_and_si512(v, low)),
                                                   _mm512_shuffle_epi8(lut, _mm512_and_si512(_mm512_srli_epi16(v, 4), low))));
    }
    return (int)_mm512_reduce_add_epi64(_mm512_sad_epu8(acc, _mm512_setzero_si512()));
#else
    int v = 0;
    for (int q = 0; q < MS_K * MS_K / 64; q++) {
        uint64_t x;
        memcpy(&x, w + q * (64 / MS_K), sizeof x);
        v += __builtin_popcountll(x);
    }
    return v;
#endif
}

/* 1 if a visible sample lies in columns x0..x1 of rows y0..y1. The hottest test of the traversal (every
 * leaf and every triangle that passes the lane tests asks it per pixel): for k = 16 and 32 with AVX2 the
 * buffer is a few vector registers and the rows' mask is built by comparison, with no loop over rows to
 * mispredict; the same bits as the loop. */
static inline int MS_KFN(br_covers)(const MS_WORD *buf, int x0, int x1, int y0, int y1)
{
    const MS_WORD ones = (MS_WORD)~(MS_WORD)0;   /* cast after ~: uint16_t promotes to int */
    const MS_WORD mask = (MS_WORD)((MS_WORD)(ones >> (MS_K - 1 - (x1 - x0))) << x0);
#if defined(MS_TARGET_AVX512) || (defined(MS_TARGET_AVX2) && MS_K <= 32)
    /* The buffer's rows y0..y1 and columns x0..x1 tested in vector registers with no loop over rows (its
     * trip count is data, and mispredicted it was a quarter of the leaf tests on the dense statues at 1024
     * samples); with AVX2 at k = 64 the scalar loop stays, as above. */
#if MS_K > 16 || defined(MS_TARGET_AVX512)
    const uint64_t rows = (y1 == 63 ? ~0ull : (2ull << y1) - 1u) & ~((1ull << y0) - 1u);
#endif
#if defined(MS_TARGET_AVX512) && MS_K == 16
    return !!_mm256_mask_test_epi16_mask((__mmask16)rows, _mm256_loadu_si256((const __m256i *)buf), _mm256_set1_epi16((short)mask));
#elif defined(MS_TARGET_AVX512)
    const int per = 64 / (int)sizeof(MS_WORD);   /* rows per register */
    const __m512i cm = MS_K == 32 ? _mm512_set1_epi32((int)mask) : _mm512_set1_epi64((long long)mask);
    unsigned hit = 0;
    for (int q = 0; q < MS_K / per; q++) {   /* unrolled: the trip count is fixed */
        const __m512i v = _mm512_loadu_si512((const void *)(buf + per * q));
        const unsigned m = (unsigned)(rows >> (per * q));
        hit |= MS_K == 32 ? (unsigned)_mm512_mask_test_epi32_mask((__mmask16)m, v, cm)
                          : (unsigned)_mm512_mask_test_epi64_mask((__mmask8)m, v, cm);
    }
    return hit != 0;
#elif MS_K == 16
    const __m256i idx = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m256i in = _mm256_andnot_si256(_mm256_cmpgt_epi16(_mm256_set1_epi16((short)y0), idx),
                                           _mm256_cmpgt_epi16(_mm256_set1_epi16((short)(y1 + 1)), idx));
    const __m256i m = _mm256_and_si256(in, _mm256_set1_epi16((short)mask));
    return !_mm256_testz_si256(_mm256_loadu_si256((const __m256i *)buf), m);
#else
    /* AVX2, k = 32: the row range as a lane mask per register, formed from the rows' bits. */
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    __m256i acc = _mm256_setzero_si256();
    for (int q = 0; q < 4; q++) {   /* unrolled: the trip count is fixed */
        const __m256i m = _mm256_set1_epi32((int)((rows >> (8 * q)) & 255u));
        const __m256i sel = _mm256_cmpeq_epi32(_mm256_and_si256(m, bit), bit);
        acc = _mm256_or_si256(acc, _mm256_and_si256(sel, _mm256_loadu_si256((const __m256i *)(buf + 8 * q))));
    }
    return !_mm256_testz_si256(acc, _mm256_set1_epi32((int)mask));
#endif
#else
    MS_WORD any = 0;
    for (int j = y0; j <= y1; j++) any |= buf[j];
    return (any & mask) != 0;
#endif
}
