/* Strict option parsing for the command line (options.h). */
#include "options.h"
#include "microshadow.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void ms_cli_parser_init(ms_cli_parser *p, const char *prog, const struct option *longopts)
{
    memset(p, 0, sizeof *p);
    p->prog = prog;
    p->longopts = longopts;
    optind = 1;
    opterr = 0;
}

/* "unknown option '--metod' (did you mean --method?)": the suggestion only when it is close (at most a
 * third of the word's letters, and at least 2, differ), so that nonsense is not explained as a typo. */
static void unknown_option(const ms_cli_parser *p, const char *arg)
{
    char word[64];
    const char *w = arg;
    while (*w == '-') w++;
    size_t len = strcspn(w, "=");
    if (len >= sizeof word) len = sizeof word - 1;
    memcpy(word, w, len);
    word[len] = 0;
    const char *names[MS_CLI_MAX_OPTIONS + 1];
    int n = 0;
    for (const struct option *o = p->longopts; o->name && n < MS_CLI_MAX_OPTIONS; o++) names[n++] = o->name;
    names[n] = NULL;
    size_t bd;
    const char *best = ms_nearest_name(word, names, &bd);
    const size_t limit = len / 3 > 2 ? len / 3 : 2;
    if (best && bd <= limit) fprintf(stderr, "%s: unknown option '%s' (did you mean --%s?)\n", p->prog, arg, best);
    else fprintf(stderr, "%s: unknown option '%s' (see --help)\n", p->prog, arg);
}

int ms_cli_next(ms_cli_parser *p, int argc, char **argv)
{
    int idx = -1;
    /* The leading ':' makes a missing value ':' rather than '?', so the two mistakes get their own message. */
    const int c = getopt_long(argc, argv, ":o:h", p->longopts, &idx);
    if (c == -1) return -1;
    if (c == ':') {
        if (optopt > 0 && optopt < 256) fprintf(stderr, "%s: option '-%c' needs a value\n", p->prog, optopt);
        else fprintf(stderr, "%s: option '%s' needs a value\n", p->prog, argv[optind - 1]);
        return 0;
    }
    if (c == '?') {
        if (optopt > 0 && optopt < 256) {
            char s[3] = { '-', (char)optopt, 0 };
            unknown_option(p, s);
        } else unknown_option(p, argv[optind - 1]);
        return 0;
    }
    /* A valued option given twice: which one the user meant cannot be known, so neither is taken. */
    int slot = -1;
    if (c == 'o') slot = MS_CLI_MAX_OPTIONS;
    else if (idx >= 0 && idx < MS_CLI_MAX_OPTIONS && p->longopts[idx].has_arg == required_argument) slot = idx;
    if (slot >= 0) {
        if (p->given[slot]) {
            char name[80];
            if (c == 'o') snprintf(name, sizeof name, "-o");
            else snprintf(name, sizeof name, "--%s", p->longopts[idx].name);
            fprintf(stderr, "%s: %s given twice ('%s', then '%s'): give it once\n", p->prog, name, p->given[slot], optarg);
            return 0;
        }
        p->given[slot] = optarg;
    }
    return c;
}

int ms_cli_parse_long(const ms_cli_parser *p, const char *opt, const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    const long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) {
        fprintf(stderr, "%s: %s: '%s' is not an integer in [%ld, %ld]\n", p->prog, opt, s, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int ms_cli_exit_code(ms_status st)
{
    switch (st) {
    case MS_OK: return 0;
    case MS_ERR_INVALID: case MS_ERR_IO: case MS_ERR_METHOD: case MS_ERR_BUDGET: return EXIT_BAD_INPUT;
    case MS_ERR_NO_MEMORY: return EXIT_NO_MEMORY;
    case MS_ERR_CANCELLED: return EXIT_CANCELLED;
    }
    return 1;
}

int ms_cli_check_method(const ms_cli_parser *p, const char *method)
{
    const int avail = ms_method_available(method);
    if (avail > 0) return 0;
    if (avail < 0) fprintf(stderr, "%s: --method: '%s' is not compiled into this build\n", p->prog, method);
    else fprintf(stderr, "%s: --method: '%s' is not a known method (did you mean %s? see --help)\n", p->prog, method,
                 ms_nearest_name(method, ms_method_names(), NULL));
    return -1;
}

int ms_cli_parse_size(const ms_cli_parser *p, const char *opt, const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    double scale = 1.0;
    /* A unit: K, M, G or T (powers of 1024), with an optional "i" and "B"; a bare "B" or nothing: bytes. */
    static const char units[] = "KMGT";
    const char *u = *end && (end[0] & ~0x20) ? strchr(units, end[0] & ~0x20) : NULL;
    const char *rest = end;
    if (u) {
        for (const char *q = units; q <= u; q++) scale *= 1024.0;
        rest = end + 1;
        if (*rest == 'i') rest++;
    }
    if (*rest == 'B' || *rest == 'b') rest++;
    if (errno || end == s || *rest || !(v > 0.0) || !(v * scale < 9.2e18) || v * scale < 1.0) {
        fprintf(stderr, "%s: %s: '%s' is not a size in bytes (a number, optionally with K, M, G or T: e.g. 512M, 1.5G)\n",
                p->prog, opt, s);
        return -1;
    }
    *out = (uint64_t)(v * scale);
    return 0;
}
