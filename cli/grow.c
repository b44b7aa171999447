// PLACEHOLDER: replaced by `plume grow` (issue in progress).
#include <stdio.h>

#include "cli.h"

int cli_grow(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	fprintf(stderr, "plume grow: not built yet\n");
	return CLI_EXIT_FAILURE;
}

void cli_help_grow(void)
{
	printf("plume grow: not built yet\n");
}
