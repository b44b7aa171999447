// PLACEHOLDER: replaced by `plume lab` (issue in progress).
#include <stdio.h>

#include "cli.h"

int cli_lab(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	fprintf(stderr, "plume lab: not built yet\n");
	return CLI_EXIT_FAILURE;
}

void cli_help_lab(void)
{
	printf("plume lab: not built yet\n");
}
