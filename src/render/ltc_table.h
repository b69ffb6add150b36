/* The LTC fit of the GGX BRDF (third_party/ltc/README.md): entry a + t*size fitted at roughness
 * a/(size-1) and view cos theta = 1 - (t/(size-1))^2. */
#ifndef MS_LTC_TABLE_H
#define MS_LTC_TABLE_H
#ifdef __cplusplus
extern "C" {
#endif
int ms_ltc_table_size(void);
/* The inverse transform, column by column (m[0..2] is column 0), in the frame z = normal, view in +x. */
const double *ms_ltc_table_minv(int index);
/* The BRDF's directional albedo without Fresnel: the integral of f cos over the hemisphere. */
float ms_ltc_table_magnitude(int index);
#ifdef __cplusplus
}
#endif
#endif
