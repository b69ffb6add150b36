/* The GGX microfacet BRDF (Walter et al. 2007) with the height-correlated Smith masking-shadowing term
 * (Heitz 2014), exactly as the LTC table was fitted to (third_party/ltc: fit/brdf_ggx.h), no Fresnel. */
#ifndef MS_BRDF_GGX_H
#define MS_BRDF_GGX_H

/* GGX alpha from perceptual roughness r (glTF roughnessFactor): alpha = r^2, at least the fit's 1e-5. */
float ms_ggx_alpha(float roughness);

/* f(v, l) * max(n.l, 0) = D G2 / (4 n.v) for unit n, v, l; 0 when v or l is below the normal's plane. */
float ms_ggx_f_cos(const float n[3], const float v[3], const float l[3], float alpha);

#endif
