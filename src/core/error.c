// Status names and error messages.
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "plume/core.h"

const char *plume_status_name(plume_status status)
{
	switch (status) {
	case PLUME_OK: return "ok";
	case PLUME_ERROR_IO: return "io";
	case PLUME_ERROR_SYNTAX: return "syntax";
	case PLUME_ERROR_SPEC: return "spec";
	case PLUME_ERROR_MEMORY: return "memory";
	case PLUME_ERROR_NUMERIC: return "numeric";
	case PLUME_ERROR_UNSUPPORTED: return "unsupported";
	case PLUME_ERROR_LIMIT: return "limit";
	}
	return "unknown";
}

plume_status plume_error_set(plume_error *err, plume_status status, const char *format, ...)
{
	if (err != NULL) {
		err->status = status;
		va_list args;
		va_start(args, format);
		vsnprintf(err->message, sizeof err->message, format, args);
		va_end(args);
	}
	return status;
}

void plume_error_prefix(plume_error *err, const char *prefix)
{
	if (err == NULL || prefix == NULL)
		return;
	// Shift the message right and copy the prefix in front; truncate at the end.
	size_t size = sizeof err->message, prefix_length = strlen(prefix) + 2;
	if (prefix_length >= size)
		prefix_length = size - 1;
	size_t message_length = strnlen(err->message, size - 1);
	if (prefix_length + message_length >= size)
		message_length = size - 1 - prefix_length;
	memmove(err->message + prefix_length, err->message, message_length);
	err->message[prefix_length + message_length] = '\0';
	memcpy(err->message, prefix, prefix_length - 2);
	err->message[prefix_length - 2] = ':';
	err->message[prefix_length - 1] = ' ';
}

// One rolling row of the dynamic programme; the row lives on the stack, so a misspelt key
// costs no allocation (and cannot fail), and inputs are cut at EDIT_DISTANCE_MAX bytes.
enum { EDIT_DISTANCE_MAX = 255 };

size_t plume_edit_distance(const char *a, const char *b)
{
	size_t n = strnlen(b, EDIT_DISTANCE_MAX), m = strnlen(a, EDIT_DISTANCE_MAX);
	size_t row[EDIT_DISTANCE_MAX + 1];
	for (size_t j = 0; j <= n; ++j)
		row[j] = j;
	for (size_t i = 1; i <= m; ++i) {
		size_t diagonal = row[0];
		row[0] = i;
		for (size_t j = 1; j <= n; ++j) {
			size_t above = row[j];
			size_t best = diagonal + (a[i - 1] != b[j - 1]);
			if (above + 1 < best)
				best = above + 1;
			if (row[j - 1] + 1 < best)
				best = row[j - 1] + 1;
			row[j] = best;
			diagonal = above;
		}
	}
	return row[n];
}
