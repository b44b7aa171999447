// The failure path of PLUME_ASSERT (asserts.h).
#include <stdio.h>
#include <stdlib.h>

#include "asserts.h"

void plume_assert_fail(const char *expression, const char *file, int line)
{
	fprintf(stderr, "plume: %s:%d: assertion failed: %s\n", file, line, expression);
	fflush(stderr);
	abort();
}
