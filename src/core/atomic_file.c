// Files that appear whole or not at all: a temporary file in the destination's
// folder (so rename stays on one file system), renamed when complete.
#define _POSIX_C_SOURCE 200809L
#include "atomic_file.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

plume_status plume_atomic_open(plume_atomic_file *file, const char *path, plume_error *err)
{
	memset(file, 0, sizeof *file);
	size_t length = strlen(path);
	if (length == 0 || length + 16 >= sizeof file->tmp_path)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: invalid output path", path);
	memcpy(file->final_path, path, length + 1);
	const char *slash = strrchr(path, '/');
	int dir_length = slash != NULL ? (int)(slash - path + 1) : 0;
	snprintf(file->tmp_path, sizeof file->tmp_path, "%.*s.%s.XXXXXX", dir_length, path,
	         slash != NULL ? slash + 1 : path);
	int fd = mkstemp(file->tmp_path);
	if (fd < 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", path, strerror(errno));
	// mkstemp creates 0600; give the result the usual permissions.
	mode_t mask = umask(0);
	umask(mask);
	fchmod(fd, 0666 & ~mask);
	file->stream = fdopen(fd, "wb");
	if (file->stream == NULL) {
		int error = errno;
		close(fd);
		unlink(file->tmp_path);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", path, strerror(error));
	}
	return PLUME_OK;
}

plume_status plume_atomic_commit(plume_atomic_file *file, plume_error *err)
{
	if (file->stream != NULL) {
		bool failed = ferror(file->stream) != 0;
		failed |= fclose(file->stream) != 0;
		file->stream = NULL;
		if (failed) {
			int error = errno;
			unlink(file->tmp_path);
			return plume_error_set(err, PLUME_ERROR_IO, "%s: write failed: %s", file->final_path, strerror(error));
		}
	}
	if (rename(file->tmp_path, file->final_path) != 0) {
		int error = errno;
		unlink(file->tmp_path);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write: %s", file->final_path, strerror(error));
	}
	return PLUME_OK;
}

void plume_atomic_abort(plume_atomic_file *file)
{
	if (file->stream != NULL) {
		fclose(file->stream);
		file->stream = NULL;
	}
	if (file->tmp_path[0] != '\0')
		unlink(file->tmp_path);
}
