#define _POSIX_C_SOURCE 200809L
#include "support.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void test_make_temp_dir(char *out, size_t size)
{
	snprintf(out, size, "/tmp/plume-test-XXXXXX");
	if (mkdtemp(out) == NULL)
		fail_msg("mkdtemp failed");
}

void test_remove_tree(const char *path)
{
	struct stat info;
	if (lstat(path, &info) != 0)
		return;
	if (S_ISDIR(info.st_mode)) {
		DIR *dir = opendir(path);
		if (dir != NULL) {
			struct dirent *entry;
			while ((entry = readdir(dir)) != NULL) {
				if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
					continue;
				char child[4096];
				snprintf(child, sizeof child, "%s/%s", path, entry->d_name);
				test_remove_tree(child);
			}
			closedir(dir);
		}
		rmdir(path);
	} else {
		unlink(path);
	}
}

unsigned char *test_read_file(const char *path, size_t *size)
{
	FILE *file = fopen(path, "rb");
	if (file == NULL)
		return NULL;
	fseek(file, 0, SEEK_END);
	long length = ftell(file);
	fseek(file, 0, SEEK_SET);
	unsigned char *data = malloc((size_t)length + 1);
	size_t got = fread(data, 1, (size_t)length, file);
	fclose(file);
	data[got] = 0;
	if (size != NULL)
		*size = got;
	return data;
}

void test_write_file(const char *path, const char *text)
{
	FILE *file = fopen(path, "wb");
	assert_non_null(file);
	fputs(text, file);
	fclose(file);
}

uint64_t test_hash_file(const char *path)
{
	size_t size;
	unsigned char *data = test_read_file(path, &size);
	if (data == NULL)
		return 0;
	uint64_t hash = 0xcbf29ce484222325ULL;
	for (size_t i = 0; i < size; ++i)
		hash = (hash ^ data[i]) * 0x100000001b3ULL;
	free(data);
	return hash;
}

int test_file_exists(const char *path) { return access(path, F_OK) == 0; }

int test_count_entries(const char *path)
{
	DIR *dir = opendir(path);
	if (dir == NULL)
		return -1;
	int count = 0;
	struct dirent *entry;
	while ((entry = readdir(dir)) != NULL)
		if (strcmp(entry->d_name, ".") != 0 && strcmp(entry->d_name, "..") != 0)
			count++;
	closedir(dir);
	return count;
}

double test_coordinate(const plume_vec3 *x, int k)
{
	const plume_vec3 *p = x + k / 3;
	return k % 3 == 0 ? p->x : k % 3 == 1 ? p->y : p->z;
}

void test_set_coordinate(plume_vec3 *x, int k, double value)
{
	plume_vec3 *p = x + k / 3;
	if (k % 3 == 0)
		p->x = value;
	else if (k % 3 == 1)
		p->y = value;
	else
		p->z = value;
}

double test_norm(const double *v, int n)
{
	double sum = 0.0;
	for (int i = 0; i < n; ++i)
		sum += v[i] * v[i];
	return sqrt(sum);
}
