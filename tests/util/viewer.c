/* The viewer in the tests (viewer.h). */
#include "viewer.h"
#include "testutil.h"
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int tu_have_browser(void)
{
    if (system("node --version > /dev/null 2>&1") != 0) { printf("skipped: node not found (scripts/install-deps.sh installs nodejs)\n"); return 0; }
    if (access("/usr/bin/chromium", X_OK) != 0) { printf("skipped: /usr/bin/chromium not found (scripts/install-deps.sh installs chromium)\n"); return 0; }
    if (access(MS_VIEWER_DIR "/node_modules/puppeteer-core/package.json", R_OK) != 0 ||
        access(MS_VIEWER_DIR "/node_modules/three/build/three.module.js", R_OK) != 0) {
        printf("skipped: " MS_VIEWER_DIR "/node_modules lacks three or puppeteer-core (scripts/install-deps.sh runs npm ci there)\n");
        return 0;
    }
    return 1;
}

void tu_screenshot(const char *glb, const char *json, const char *shot, const char *extra)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "node '%s/screenshot.mjs' '%s' '%s' '%s' %s", MS_VIEWER_DIR, glb, json, shot, extra);
    fflush(stdout);
    assert_int_equal(system(cmd), 0);
}

double tu_srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

double *tu_png_luminance(const char *path, int W, int H)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&img, path));
    img.format = PNG_FORMAT_RGB;
    assert_int_equal((int)img.width, W);
    assert_int_equal((int)img.height, H);
    uint8_t *px = malloc((size_t)W * H * 3);
    double *y = malloc((size_t)W * H * sizeof *y);
    assert_true(px && y);
    assert_true(png_image_finish_read(&img, NULL, px, 0, NULL));
    static const double wy[3] = { 0.2126, 0.7152, 0.0722 };
    for (size_t i = 0; i < (size_t)W * H; i++) {
        y[i] = 0.0;
        for (int c = 0; c < 3; c++) y[i] += wy[c] * tu_srgb_to_linear(px[3 * i + c] / 255.0);
    }
    free(px);
    return y;
}

tu_lum_agreement tu_lum_compare(const double *a, const double *b, const float *mask, size_t n)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    tu_lum_agreement r = { 0, 0, 0, 0, 0 };
    for (size_t i = 0; i < n; i++) {
        if (mask && mask[i] < 0.0f) continue;
        sa += a[i]; sb += b[i]; saa += a[i] * a[i]; sbb += b[i] * b[i]; sab += a[i] * b[i];
        r.n++;
    }
    if (!r.n) return r;
    r.mean_a = sa / r.n;
    r.mean_b = sb / r.n;
    const double cov = sab / r.n - r.mean_a * r.mean_b, va = saa / r.n - r.mean_a * r.mean_a, vb = sbb / r.n - r.mean_b * r.mean_b;
    r.corr = va > 0 && vb > 0 ? cov / sqrt(va * vb) : 0.0;
    r.ratio = r.mean_b > 0 ? r.mean_a / r.mean_b : 0.0;
    return r;
}
