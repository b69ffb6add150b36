/* Replays the fuzzers' committed inputs through the same bodies as the libFuzzer harnesses
 * (tests/fuzz/fuzz_entry.h), with whatever compiler built the tests: every seed in tests/fuzz/corpus
 * loads (they are valid files of each format), every kept crash input in tests/fuzz/crashes is refused
 * with one line naming the file, and none crashes, hangs or leaks (ASan/UBSan/LSan). */
#include "testutil.h"
#include "../fuzz/fuzz_entry.h"
#include <dirent.h>
#include <sys/stat.h>

static const char *const targets[] = { "obj", "ply", "off", "stl", "gltf", "scene", "exr", "jpeg" };

static uint8_t *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)len + 1);
    *n = fread(b, 1, (size_t)len, f);
    fclose(f);
    return b;
}

/* Runs every file of tests/fuzz/<kind>/<target>; returns how many there were. */
static int replay(const char *kind, int want_ok)
{
    int total = 0;
    for (size_t t = 0; t < sizeof targets / sizeof targets[0]; t++) {
        char dir[4096];
        snprintf(dir, sizeof dir, "%s/%s/%s", MS_FUZZ_DIR, kind, targets[t]);
        DIR *d = opendir(dir);
        /* every harness has seeds: a missing corpus (e.g. files a .gitignore kept out) is a failure */
        if (!d && want_ok) fail_msg("%s: no seed corpus", dir);
        if (!d) continue;
        struct dirent *e;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.') continue;
            char p[4096 + 256];
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            size_t n = 0;
            uint8_t *b = slurp(p, &n);
            assert_non_null(b);
            int rc = !strcmp(targets[t], "scene") ? ms_fuzz_scene(ms_fuzz_scene_dir(), b, n)
                     : !strcmp(targets[t], "exr") ? ms_fuzz_exr(b, n)
                     : !strcmp(targets[t], "jpeg") ? ms_fuzz_jpeg(b, n) : ms_fuzz_mesh(targets[t], b, n);
            free(b);
            if ((rc == 0) != want_ok) {
                closedir(d);
                fail_msg("%s: %s, expected %s", p, rc ? "refused" : "loaded", want_ok ? "to load" : "to be refused");
            }
            total++;
        }
        closedir(d);
    }
    return total;
}

static void test_seeds_load(void **st)
{
    (void)st;
    int n = replay("corpus", 1);
    print_message("%d seed inputs loaded\n", n);
    assert_true(n >= 6);
}

static void test_crash_inputs_refused(void **st)
{
    (void)st;
    int n = replay("crashes", 0);
    print_message("%d kept crash inputs refused\n", n);
    assert_true(n >= 6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seeds_load),
        cmocka_unit_test(test_crash_inputs_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
