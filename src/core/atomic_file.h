// Private: files that appear whole or not at all. Write to a temporary file
// beside the destination, then rename it over the destination.
#ifndef PLUME_ATOMIC_FILE_H
#define PLUME_ATOMIC_FILE_H

#include <stdio.h>

#include "plume/core.h"

typedef struct plume_atomic_file {
	FILE *stream; ///< write here (NULL for writers that need a path: use tmp_path)
	char final_path[4096];
	char tmp_path[4096];
} plume_atomic_file;

/// Creates "<dir>/.<name>.XXXXXX" beside path and opens it for writing.
plume_status plume_atomic_open(plume_atomic_file *file, const char *path, plume_error *err);

/// Closes the stream, checks that every byte reached the disk and renames the
/// temporary file to the final path. On failure the temporary file is removed.
plume_status plume_atomic_commit(plume_atomic_file *file, plume_error *err);

/// Closes and removes the temporary file.
void plume_atomic_abort(plume_atomic_file *file);

#endif
