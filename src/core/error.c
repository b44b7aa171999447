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
