// PLACEHOLDER: replaced by `plume coat` (issue in progress).
#include <stdio.h>

#include "cli.h"

int cli_coat(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	fprintf(stderr, "plume coat: not built yet\n");
	return CLI_EXIT_FAILURE;
}

void cli_help_coat(void)
{
	printf("plume coat: not built yet\n");
}
