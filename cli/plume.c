// plume: the command-line tool. One file per subcommand; this one dispatches.
#include <stdio.h>
#include <string.h>

#include "cli.h"

typedef struct command {
	const char *name;
	const char *summary;
	int (*run)(int argc, char **argv);
	void (*help)(void);
} command;

static const command commands[] = {
    {"generate", "generate a feather from a spec; write images and geometry", cli_generate, cli_help_generate},
    {"grow", "write a feather's growth or unfurling sequence, frame by frame", cli_grow, cli_help_grow},
    {"coat", "cover a surface with feathers from a coat spec", cli_coat, cli_help_coat},
    {"mesh", "mesh a feather into a barb-aligned shell; write OBJ, picture and report", cli_mesh, cli_help_mesh},
    {"simulate", "simulate a feather as an anisotropic shell from a scene spec", cli_simulate, cli_help_simulate},
    {"render", "ray-trace a feather, a coat or a simulation", cli_render, cli_help_render},
    {"lab", "virtual lab: traction tests, calibration, studies", cli_lab, cli_help_lab},
    {"sweep", "run a command over many parameter values, locally (-j N) or with MPI", cli_sweep, cli_help_sweep},
    {"view", "write a web page that shows .glb files in a browser (three.js)", cli_view, cli_help_view},
    {"demo", "generate the built-in feather end to end, no input needed", cli_demo, cli_help_demo},
};
enum { COMMAND_COUNT = sizeof commands / sizeof commands[0] };

static void print_usage(FILE *stream)
{
	fprintf(stream,
	        "plume %s — feathers: generation, simulation, rendering\n\n"
	        "Usage: plume COMMAND [options]\n\nCommands:\n",
	        PLUME_VERSION_STRING);
	for (int i = 0; i < COMMAND_COUNT; ++i)
		fprintf(stream, "  %-10s %s\n", commands[i].name, commands[i].summary);
	fprintf(stream, "  %-10s %s\n\n", "help", "help on a command: plume help COMMAND");
	fprintf(stream, "Options: --help, --version\n");
}

static const command *find_command(const char *name)
{
	for (int i = 0; i < COMMAND_COUNT; ++i)
		if (strcmp(commands[i].name, name) == 0)
			return commands + i;
	return NULL;
}

static int unknown_command(const char *name)
{
	fprintf(stderr, "plume: unknown command '%s'. Commands:", name);
	for (int i = 0; i < COMMAND_COUNT; ++i)
		fprintf(stderr, " %s", commands[i].name);
	fprintf(stderr, ". Try 'plume --help'.\n");
	return CLI_EXIT_USAGE;
}

int main(int argc, char **argv)
{
	if (argc < 2) {
		print_usage(stderr);
		return CLI_EXIT_USAGE;
	}
	const char *name = argv[1];
	if (strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0) {
		print_usage(stdout);
		return CLI_EXIT_OK;
	}
	if (strcmp(name, "--version") == 0) {
		printf("plume %s\n", PLUME_VERSION_STRING);
		return CLI_EXIT_OK;
	}
	if (strcmp(name, "help") == 0) {
		if (argc < 3) {
			print_usage(stdout);
			return CLI_EXIT_OK;
		}
		const command *topic = find_command(argv[2]);
		if (topic == NULL)
			return unknown_command(argv[2]);
		topic->help();
		return CLI_EXIT_OK;
	}
	const command *chosen = find_command(name);
	if (chosen == NULL)
		return unknown_command(name);
	return chosen->run(argc - 1, argv + 1);
}
