/* Replays the fuzzers' committed inputs through the same bodies as the libFuzzer harnesses
 * (tests/fuzz/fuzz_entry.h), with whatever compiler built the tests: every seed in tests/fuzz/corpus
 * loads (they are valid files of each format), every kept crash input in tests/fuzz/crashes is refused
 * with one line naming the file, and none crashes, hangs or leaks (ASan/UBSan/LSan). Each input runs in a
 * child process (many to a child, run_batch), so that an input that aborts or crashes (assimp's assertions
 * call abort()) is reported as a failure naming the file and the signal, and the others are still
 * replayed; one still running after 20 s is a hang (SIGALRM); under LeakSanitizer the child checks for
 * leaks before it exits, and a leak is traced to its input by replaying them one per child.
 *
 * Seeds named by their SHA-1 (40 hex digits: what libFuzzer's -merge=1 adds, scripts/fuzz.sh) are inputs that
 * reached new coverage: they must load or be refused with one line, like any input; the named seeds are
 * valid files and must load.
 *
 * tests/fuzz/known_failing.txt lists kept inputs that still fail in this tree, each with the reason: they
 * are replayed and reported, but do not fail the test (an input listed there that now passes is reported
 * too, so that the list can shrink). The harnesses are those with a folder in tests/fuzz/corpus. */
#include "testutil.h"
#include "../fuzz/fuzz_entry.h"
#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

/* LeakSanitizer's on-demand check, present in sanitized builds only. */
extern int __lsan_do_recoverable_leak_check(void) __attribute__((weak));

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

static int merged_name(const char *name)
{
    size_t i = 0;
    while (name[i] && strchr("0123456789abcdef", name[i])) i++;
    return i == 40 && !name[i];
}

static int known_failing(const char *kind, const char *target, const char *name)
{
    char p[4096], line[1024], want[1024];
    snprintf(p, sizeof p, "%s/known_failing.txt", MS_FUZZ_DIR);
    snprintf(want, sizeof want, "%s/%s/%s", kind, target, name);
    FILE *f = fopen(p, "r");
    if (!f) return 0;
    int found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        line[strcspn(line, " \t\r\n")] = 0;   /* the path, then the reason */
        found = line[0] != '#' && !strcmp(line, want);
    }
    fclose(f);
    return found;
}

/* The body of the harness `target` on one file: 0 loaded, 1 refused (one line), 99 unreadable. */
static int harness(const char *target, const char *p)
{
    size_t n = 0;
    uint8_t *b = slurp(p, &n);
    if (!b) return 99;
    int rc = !strcmp(target, "scene") ? ms_fuzz_scene(ms_fuzz_scene_dir(), b, n)
             : !strcmp(target, "exr") ? ms_fuzz_exr(b, n)
             : !strcmp(target, "png") ? ms_fuzz_png(b, n)
             : !strcmp(target, "mtl") ? ms_fuzz_mtl(b, n)
             : !strcmp(target, "jpeg") ? ms_fuzz_jpeg(b, n)
             : !strcmp(target, "ktx2") ? ms_fuzz_ktx2(b, n)
             : !strcmp(target, "webp") ? ms_fuzz_webp(b, n) : ms_fuzz_mesh(target, b, n);
    free(b);
    return rc ? 1 : 0;
}

/* A child process's exit: 0, or 128 + the signal it died of. */
static int wait_child(pid_t pid)
{
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {}
    return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
}

/* The harness on one file, in a child process: harness()'s result, 2 leaked, 128 + the signal when it died. */
static int run_one(const char *target, const char *p)
{
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        alarm(20);   /* a hang (libFuzzer's -timeout is 10 s) dies of SIGALRM, reported as such */
        const int rc = harness(target, p);
        if (__lsan_do_recoverable_leak_check && __lsan_do_recoverable_leak_check()) _exit(2);
        _exit(rc);
    }
    return wait_child(pid);
}

/* The harness on files[0..n) in one child process, each file's result into r[] as run_one gives it. A
 * child per file spent most of the suite's time in forks and leak checks; here one child takes as many
 * files as it can, writes each result to a pipe, and checks for leaks once at the end. A child that dies
 * names its file (the first without a result) and the next child goes on after it; a leak found at the
 * end is attributed by replaying that child's files one by one. */
static void run_batch(const char *target, char *const *files, int n, int *r)
{
    int i = 0;
    while (i < n) {
        int fd[2];
        assert_int_equal(pipe(fd), 0);
        fflush(NULL);
        const pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            close(fd[0]);
            for (int k = i; k < n; k++) {
                alarm(20);   /* per file: a hang dies of SIGALRM, named by its file */
                const unsigned char rc = (unsigned char)harness(target, files[k]);
                if (write(fd[1], &rc, 1) != 1) _exit(98);
            }
            alarm(0);
            const unsigned char leak = __lsan_do_recoverable_leak_check && __lsan_do_recoverable_leak_check() ? 'L' : 'K';
            if (write(fd[1], &leak, 1) != 1) _exit(98);
            _exit(0);
        }
        close(fd[1]);
        const int first = i;
        unsigned char c;
        int leaked = 0, ended = 0;
        while (read(fd[0], &c, 1) == 1) {
            if (i < n) r[i++] = c;
            else { leaked = c == 'L'; ended = 1; }
        }
        close(fd[0]);
        const int died = wait_child(pid);
        if (died && i < n) r[i++] = died;   /* the file it was on */
        else if (!ended) leaked = 1;        /* died in its leak check: its files one by one say which */
        if (leaked)
            for (int k = first; k < i; k++)
                if (r[k] < 2) r[k] = run_one(target, files[k]);
    }
}

/* The parent's directory streams, open while a child runs its leak check in its copy of the parent's
 * memory: not the child's leaks (with gcc's ASan the children reported them), so LeakSanitizer is told to
 * ignore them. */
extern void __lsan_ignore_object(const void *p) __attribute__((weak));

static DIR *open_dir_ignored(const char *path)
{
    DIR *d = opendir(path);
    if (d && __lsan_ignore_object) __lsan_ignore_object(d);
    return d;
}

/* Runs every file of tests/fuzz/<kind>/<target> for every harness; returns how many there were. */
static int replay(const char *kind, int want_ok)
{
    int total = 0, failed = 0, known = 0;
    char first[4600] = "";
    DIR *td = open_dir_ignored(MS_FUZZ_DIR "/corpus");
    assert_non_null(td);
    struct dirent *te;
    ms_fuzz_scene_dir();   /* made here, so that it outlives the children */
    while ((te = readdir(td))) {
        if (te->d_name[0] == '.') continue;
        const char *target = te->d_name;
        char dir[4096];
        snprintf(dir, sizeof dir, "%s/%s/%s", MS_FUZZ_DIR, kind, target);
        DIR *d = open_dir_ignored(dir);
        /* every harness has seeds: a missing corpus (e.g. files a .gitignore kept out) is a failure */
        if (!d && want_ok) fail_msg("%s: no seed corpus", dir);
        if (!d) continue;
        struct dirent *e;
        char **files = NULL;
        int nf = 0, cap = 0;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.') continue;
            if (nf == cap) {
                cap = cap ? 2 * cap : 256;
                files = realloc(files, (size_t)cap * sizeof *files);
                assert_non_null(files);
            }
            const size_t len = strlen(dir) + strlen(e->d_name) + 2;
            files[nf] = malloc(len);
            assert_non_null(files[nf]);
            snprintf(files[nf++], len, "%s/%s", dir, e->d_name);
        }
        closedir(d);
        int *res = malloc((size_t)(nf ? nf : 1) * sizeof *res);
        assert_non_null(res);
        /* the parent's, as the directory streams: not the children's leaks */
        if (__lsan_ignore_object) {
            __lsan_ignore_object(res);
            __lsan_ignore_object(files);
            for (int f = 0; f < nf; f++) __lsan_ignore_object(files[f]);
        }
        run_batch(target, files, nf, res);
        for (int f = 0; f < nf; f++) {
            const char *p = files[f], *name = strrchr(p, '/') + 1;
            const int r = res[f];
            char why[4800] = "";
            if (r == 99) snprintf(why, sizeof why, "%s: cannot be read", p);
            else if (r >= 128) snprintf(why, sizeof why, "%s: the harness died of signal %d (%s)", p, r - 128, strsignal(r - 128));
            else if (r == 2) snprintf(why, sizeof why, "%s: leaked (LeakSanitizer's report above)", p);
            else if ((r == 0) != want_ok && !(want_ok && r == 1 && merged_name(name)))
                snprintf(why, sizeof why, "%s: %s, expected %s", p, r ? "refused" : "loaded", want_ok ? "to load" : "to be refused");
            const int listed = known_failing(kind, target, name);
            if (why[0] && listed) {
                print_message("known failing (tests/fuzz/known_failing.txt): %s\n", why);
                known++;
            } else if (why[0]) {
                print_message("FAILED: %s\n", why);
                if (!failed++) snprintf(first, sizeof first, "%s", why);
            } else if (listed) {
                print_message("%s/%s/%s passes now: remove it from tests/fuzz/known_failing.txt\n", kind, target, name);
            }
            total++;
        }
        for (int f = 0; f < nf; f++) free(files[f]);
        free(files);
        free(res);
    }
    closedir(td);
    if (known) print_message("%d known failing inputs replayed (not counted as failures)\n", known);
    if (failed) fail_msg("%d of %d inputs failed; the first: %s", failed, total, first);
    return total;
}

static void test_seeds_load(void **st)
{
    (void)st;
    int n = replay("corpus", 1);
    print_message("%d corpus inputs replayed (seeds loaded, merged ones loaded or refused with one line)\n", n);
    assert_true(n >= 6);
}

static void test_crash_inputs_refused(void **st)
{
    (void)st;
    int n = replay("crashes", 0);
    print_message("%d kept crash inputs refused\n", n);
    assert_true(n >= 6);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seeds_load),
        cmocka_unit_test(test_crash_inputs_refused),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
