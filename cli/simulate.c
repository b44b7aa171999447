// PLACEHOLDER: replaced by `plume simulate` (issue in progress).
#include <stdio.h>

#include "cli.h"

int cli_simulate(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	fprintf(stderr, "plume simulate: not built yet\n");
	return CLI_EXIT_FAILURE;
}

void cli_help_simulate(void)
{
	printf("plume simulate: not built yet\n");
}
