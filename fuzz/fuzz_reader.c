// libFuzzer harness of one of plume's readers (issue 17), chosen at build time
// by FUZZ_READER (fuzz/CMakeLists.txt builds one executable per reader). Each
// input is written to a file in a private working folder, so that the reader
// runs exactly as the CLI runs it, relative paths included: the folder holds
// links to the example specs that specs refer to (key feathers, ../franco-walter/...).
// A reader must return a status for any bytes: a crash, a sanitizer report, a
// leak or a hang (libFuzzer's -timeout) is a finding.
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plume/plume.h"

enum {
	READER_FEATHER_SPEC, // plume_spec_generate: franco-walter, streit-heidrich, zhang-kanai
	READER_COAT,         // plume_coat_spec_generate
	READER_SCENE,        // plume_scene_load (scene + feather + mesh)
	READER_LAB,          // plume_lab_spec_load
	READER_CAMERA,       // plume_raytrace_def_read
	READER_MESH_SPEC,    // plume_mesh_spec_read (guides specs)
	READER_OBJ,          // plume_mesh_read_obj
	READER_FEATHER_JSON, // plume_read_json
};

static char s_root[256];
static char s_work[512];
static char s_input[600];

/// Removes the working folder (links and the input only: nothing it links to).
static void remove_work(void)
{
	DIR *d = opendir(s_work);
	if (d != NULL) {
		struct dirent *entry;
		while ((entry = readdir(d)) != NULL) {
			char path[1024];
			snprintf(path, sizeof path, "%s/%s", s_work, entry->d_name);
			if (entry->d_name[0] != '.')
				unlink(path);
		}
		closedir(d);
	}
	rmdir(s_work);
	d = opendir(s_root);
	if (d != NULL) {
		struct dirent *entry;
		while ((entry = readdir(d)) != NULL) {
			char path[1024];
			snprintf(path, sizeof path, "%s/%s", s_root, entry->d_name);
			if (entry->d_name[0] != '.')
				unlink(path);
		}
		closedir(d);
	}
	rmdir(s_root);
}

/// Links every file of examples/<folder> into dir.
static void link_examples(const char *folder, const char *dir)
{
	char source[1024];
	snprintf(source, sizeof source, "%s/examples/%s", PLUME_SOURCE_DIR, folder);
	DIR *d = opendir(source);
	if (d == NULL)
		return;
	struct dirent *entry;
	while ((entry = readdir(d)) != NULL) {
		if (entry->d_name[0] == '.')
			continue;
		char from[1600], to[1600];
		snprintf(from, sizeof from, "%s/%s", source, entry->d_name);
		snprintf(to, sizeof to, "%s/%s", dir, entry->d_name);
		if (symlink(from, to) != 0) {
			// a name already linked from another folder: the first one stays
		}
	}
	closedir(d);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	char *root = s_root;
	snprintf(s_root, sizeof s_root, "/tmp/plume-fuzz-%ld", (long)getpid());
	mkdir(root, 0700);
	atexit(remove_work);
	// root/<folder> -> examples/<folder> for "../franco-walter/hawk.json"; root/work holds the input
	// beside links to the files specs name without a folder ("key-plume.json", "quad.obj").
	static const char *const folders[] = {"franco-walter", "streit-heidrich", "zhang-kanai", "coats", "scenes",
	                                      "lab",           "meshes",          "cameras"};
	for (size_t i = 0; i < sizeof folders / sizeof folders[0]; ++i) {
		char from[1024], to[512];
		snprintf(from, sizeof from, "%s/examples/%s", PLUME_SOURCE_DIR, folders[i]);
		snprintf(to, sizeof to, "%s/%s", s_root, folders[i]);
		if (symlink(from, to) != 0) {
			// already there
		}
	}
	snprintf(s_work, sizeof s_work, "%s/work", s_root);
	mkdir(s_work, 0700);
	link_examples("coats", s_work);
	link_examples("franco-walter", s_work);
	link_examples("streit-heidrich", s_work);
	snprintf(s_input, sizeof s_input, "%s/input.%s", s_work, FUZZ_READER == READER_OBJ ? "obj" : "json");
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	FILE *file = fopen(s_input, "wb");
	if (file == NULL)
		abort();
	if (size > 0 && fwrite(data, 1, size, file) != size)
		abort();
	fclose(file);
	plume_error err = {0};
	// Bounds for the fuzzer's memory (libFuzzer's -rss_limit_mb) and time (-timeout=30): a coat
	// or a mesh past 8 MiB is refused. The instrumented mesher does about 7,000 vertices a
	// second (a 1.07M-vertex tall feather took 156 s), and a guide set that folds is meshed
	// again at other edge lengths before it fails: a 100,000-vertex one (32 MiB) took over
	// 30 s (fuzz/corpus/mesh_spec/folding-long-rachis.json, 12 s in a release build). 8 MiB is
	// about 26,000 vertices; larger meshes are the tests' and benchmarks' business.
	const uint64_t max_memory = 8u << 20;
	plume_spec_options options = {.max_memory = max_memory};
	switch (FUZZ_READER) {
	case READER_FEATHER_SPEC: {
		plume_feather *feather = NULL;
		plume_spec_generate(s_input, &options, &feather, &err);
		plume_feather_destroy(feather);
		break;
	}
	case READER_COAT: {
		plume_coat *coat = NULL;
		plume_coat_spec_generate(s_input, &options, &coat, &err);
		plume_coat_destroy(coat);
		break;
	}
	case READER_SCENE: {
		plume_scene *scene = NULL;
		plume_scene_load(s_input, &options, &scene, &err);
		plume_scene_destroy(scene);
		break;
	}
	case READER_LAB: {
		plume_lab_spec spec;
		plume_lab_spec_load(s_input, &spec, &err);
		break;
	}
	case READER_CAMERA: {
		plume_raytrace_def def = plume_raytrace_default_def();
		plume_raytrace_def_read(s_input, &def, &err);
		break;
	}
	case READER_MESH_SPEC: {
		plume_mesh_spec_options mesh_options = plume_mesh_spec_default_options();
		mesh_options.max_memory = max_memory;
		plume_mesh *mesh = NULL;
		plume_mesh_spec_read(s_input, &mesh_options, &mesh, NULL, &err);
		plume_mesh_destroy(mesh);
		break;
	}
	case READER_OBJ: {
		plume_mesh *mesh = NULL;
		plume_mesh_read_obj(s_input, &mesh, &err);
		plume_mesh_destroy(mesh);
		break;
	}
	default: {
		plume_feather *feather = NULL;
		plume_read_json(s_input, &feather, &err);
		plume_feather_destroy(feather);
		break;
	}
	}
	return 0;
}
