// Allocation with an optional user hook and a byte counter.
//
// Each block carries a small header with its size so that frees can be
// counted; the header is 16 bytes to keep the payload aligned for any type.
#include "alloc.h"

#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "plume/core.h"

enum { HEADER_SIZE = 16 };

static plume_alloc_fn *s_alloc = NULL;
static plume_free_fn *s_free = NULL;
static _Atomic int64_t s_bytes_in_use = 0;

void plume_set_allocator(plume_alloc_fn *alloc_fn, plume_free_fn *free_fn)
{
	s_alloc = alloc_fn;
	s_free = free_fn;
}

int64_t plume_bytes_in_use(void) { return atomic_load(&s_bytes_in_use); }

void *plume_alloc(size_t size)
{
	if (size > SIZE_MAX - HEADER_SIZE)
		return NULL;
	unsigned char *block = s_alloc != NULL ? s_alloc(size + HEADER_SIZE) : malloc(size + HEADER_SIZE);
	if (block == NULL)
		return NULL;
	memcpy(block, &size, sizeof size);
	atomic_fetch_add(&s_bytes_in_use, (int64_t)size);
	return block + HEADER_SIZE;
}

void *plume_calloc(size_t count, size_t size)
{
	if (size != 0 && count > SIZE_MAX / size)
		return NULL;
	void *memory = plume_alloc(count * size);
	if (memory != NULL)
		memset(memory, 0, count * size);
	return memory;
}

void plume_free(void *memory)
{
	if (memory == NULL)
		return;
	unsigned char *block = (unsigned char *)memory - HEADER_SIZE;
	size_t size;
	memcpy(&size, block, sizeof size);
	atomic_fetch_sub(&s_bytes_in_use, (int64_t)size);
	if (s_free != NULL)
		s_free(block);
	else
		free(block);
}

void *plume_realloc(void *memory, size_t size)
{
	if (memory == NULL)
		return plume_alloc(size);
	size_t old_size;
	memcpy(&old_size, (unsigned char *)memory - HEADER_SIZE, sizeof old_size);
	// Through alloc + copy + free so that a user hook needs no realloc.
	void *grown = plume_alloc(size);
	if (grown == NULL)
		return NULL;
	memcpy(grown, memory, old_size < size ? old_size : size);
	plume_free(memory);
	return grown;
}

int plume_grow(void **items, int *capacity, int needed, size_t item_size)
{
	if (needed <= *capacity)
		return 0;
	int grown = *capacity > 0 ? *capacity : 16;
	while (grown < needed) {
		if (grown > INT32_MAX / 2)
			return -1;
		grown *= 2;
	}
	void *memory = plume_realloc(*items, (size_t)grown * item_size);
	if (memory == NULL)
		return -1;
	*items = memory;
	*capacity = grown;
	return 0;
}
