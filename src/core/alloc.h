// Private: libplume's allocation functions (they honour plume_set_allocator
// and keep the byte counter) and a growth helper for dynamic arrays.
#ifndef PLUME_ALLOC_H
#define PLUME_ALLOC_H

#include <stddef.h>

void *plume_alloc(size_t size);
/// Zero-filled count * size bytes; NULL on overflow or failure.
void *plume_calloc(size_t count, size_t size);
void *plume_realloc(void *memory, size_t size);
void plume_free(void *memory);

/// Ensures *items can hold needed elements of item_size bytes, growing the
/// capacity geometrically. Returns 0, or -1 when memory runs out (the array is
/// then unchanged).
int plume_grow(void **items, int *capacity, int needed, size_t item_size);

#define PLUME_GROW(array, capacity, needed) plume_grow((void **)&(array), &(capacity), (needed), sizeof *(array))

#endif
