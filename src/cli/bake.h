/* `microshadow bake`: the lightmap baker's command line (bake.c). */
#ifndef MS_CLI_BAKE_H
#define MS_CLI_BAKE_H
/* argv[0] is "bake". Returns the exit status: 0, 2 for bad input, 1 otherwise. */
int ms_cli_bake(int argc, char **argv);
#endif
