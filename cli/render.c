// PLACEHOLDER: replaced by `plume render` (issue in progress).
#include <stdio.h>

#include "cli.h"

int cli_render(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	fprintf(stderr, "plume render: not built yet\n");
	return CLI_EXIT_FAILURE;
}

void cli_help_render(void)
{
	printf("plume render: not built yet\n");
}
