/* The three.js viewer (viewer/) in the tests: whether node, Chromium and the viewer's npm packages are there, its
 * headless screenshots (viewer/screenshot.mjs), and luminance images compared over a frame's hit pixels. */
#ifndef TU_VIEWER_H
#define TU_VIEWER_H
#include <stddef.h>

/* 1 when node, /usr/bin/chromium and MS_VIEWER_DIR/node_modules (three, puppeteer-core) are present; 0 with a
 * "skipped: ..." line naming what is missing (scripts/install-deps.sh installs them). */
int tu_have_browser(void);
/* The viewer's screenshot of glb under scene file json's camera (json "": the camera the bake wrote into the glb)
 * into shot (a PNG), with screenshot.mjs's options in extra ("" for none); fails the test when it does not exit 0. */
void tu_screenshot(const char *glb, const char *json, const char *shot, const char *extra);
double tu_srgb_to_linear(double c);
/* An sRGB PNG of W x H pixels as linear luminance per pixel (0.2126 R + 0.7152 G + 0.0722 B of the linearised
 * channels; the caller frees it), or fails the test. */
double *tu_png_luminance(const char *path, int W, int H);
/* Two luminance images over the pixels where mask (n floats) is >= 0 (a --vis PFM: -1 where the primary ray
 * missed; NULL: every pixel): how many, their correlation and mean of each and the ratio of those means (a / b). */
typedef struct tu_lum_agreement { long n; double corr, mean_a, mean_b, ratio; } tu_lum_agreement;
tu_lum_agreement tu_lum_compare(const double *a, const double *b, const float *mask, size_t n);
#endif
