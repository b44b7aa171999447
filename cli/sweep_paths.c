// plume sweep: JSON paths ("$.material.barb_fraction", "$.handles[0].x") into the base
// spec, and the nearest path or key for "did you mean".
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sweep.h"

// JSON paths: "$" followed by ".key" and "[index]" parts.

/// The value at path in root and its parent (for replacement); NULL when absent.
/// *settable: the path names a key the parent object lacks (a key left to its default).
json_t *sweep_path_lookup(json_t *root, const char *path, json_t **parent, char *key, size_t key_size, size_t *index,
                          bool *settable)
{
	*settable = false;
	if (path[0] != '$')
		return NULL;
	json_t *node = root;
	const char *p = path + 1;
	while (*p != '\0') {
		*parent = node;
		if (*p == '.') {
			++p;
			size_t length = strcspn(p, ".[");
			if (length == 0 || length >= key_size || !json_is_object(node))
				return NULL;
			memcpy(key, p, length);
			key[length] = '\0';
			node = json_object_get(node, key);
			p += length;
			*settable = node == NULL && *p == '\0';
		} else if (*p == '[') {
			char *end = NULL;
			long i = strtol(p + 1, &end, 10);
			if (end == p + 1 || *end != ']' || i < 0 || !json_is_array(node))
				return NULL;
			key[0] = '\0';
			*index = (size_t)i;
			node = json_array_get(node, (size_t)i);
			p = end + 1;
		} else
			return NULL;
		if (node == NULL)
			return NULL;
	}
	return node;
}

bool sweep_path_set(json_t *root, const char *path, json_t *value)
{
	json_t *parent = NULL;
	char key[256];
	size_t index = 0;
	bool settable;
	if ((sweep_path_lookup(root, path, &parent, key, sizeof key, &index, &settable) == NULL && !settable) ||
	    parent == NULL) {
		json_decref(value);
		return false;
	}
	if (json_is_object(parent))
		return json_object_set_new(parent, key, value) == 0;
	return json_array_set_new(parent, index, value) == 0;
}

/// The scalar path in root nearest to path (for "did you mean").
void sweep_nearest_path(const json_t *node, const char *prefix, const char *path, char *best, size_t *best_distance)
{
	char child[512];
	if (json_is_object(node)) {
		const char *key;
		json_t *value;
		json_object_foreach ((json_t *)node, key, value) {
			snprintf(child, sizeof child, "%s.%s", prefix, key);
			sweep_nearest_path(value, child, path, best, best_distance);
		}
	} else if (json_is_array(node)) {
		size_t i;
		json_t *value;
		json_array_foreach (node, i, value) {
			snprintf(child, sizeof child, "%s[%zu]", prefix, i);
			sweep_nearest_path(value, child, path, best, best_distance);
		}
	} else {
		size_t d = plume_edit_distance(prefix, path);
		if (d < *best_distance) {
			*best_distance = d;
			snprintf(best, 512, "%s", prefix);
		}
	}
}
