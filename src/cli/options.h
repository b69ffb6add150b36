/* The command line's option parsing, shared by `microshadow` and `microshadow bake`: getopt_long made
 * strict. A valued option given twice is refused (the second would silently win), an unknown option is
 * refused with the nearest known one suggested, a missing value is named as such. */
#ifndef MS_CLI_OPTIONS_H
#define MS_CLI_OPTIONS_H
#include <getopt.h>
#include <stdint.h>

#include "microshadow.h"

/* Exit codes (README, "Exit codes"): 0 success; 2 bad input or a request refused (a malformed or unreadable
 * file, a bad option, an unwritable output, a method not compiled in, over the memory budget); 3 out of memory
 * although the estimate fitted the budget; 4 cancelled; 1 anything else. */
#define EXIT_BAD_INPUT 2
#define EXIT_NO_MEMORY 3
#define EXIT_CANCELLED 4
/* The exit code of a library status. */
int ms_cli_exit_code(ms_status st);
#define MS_CLI_MAX_OPTIONS 64

typedef struct ms_cli_parser {
    const char *prog;                        /* "microshadow" or "microshadow bake", for the messages */
    const struct option *longopts;           /* terminated by a zero row; -o is the one short valued option */
    const char *given[MS_CLI_MAX_OPTIONS + 1];   /* the value each valued option got (last: -o), or NULL */
} ms_cli_parser;

/* Starts parsing argv from argv[1]. */
void ms_cli_parser_init(ms_cli_parser *p, const char *prog, const struct option *longopts);
/* The next option's val ('o', 'h' or a longopts val; optarg holds its value), -1 after the last option,
 * or 0 after printing one line for a bad option (the caller exits with EXIT_BAD_INPUT). */
int ms_cli_next(ms_cli_parser *p, int argc, char **argv);
/* An integer value in [lo, hi] of option opt; -1 after printing one line. */
int ms_cli_parse_long(const ms_cli_parser *p, const char *opt, const char *s, long lo, long hi, long *out);
/* A size in bytes of option opt: a positive number with an optional unit K, M, G, T (powers of 1024; "Ki",
 * "KiB", "KB" alike); -1 after printing one line. */
int ms_cli_parse_size(const ms_cli_parser *p, const char *opt, const char *s, uint64_t *out);
/* 0 when method is compiled in; otherwise -1 after one line (not compiled in, or unknown with the nearest
 * known method suggested). */
int ms_cli_check_method(const ms_cli_parser *p, const char *method);
#endif
