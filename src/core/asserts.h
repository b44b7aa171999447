// Private: asserts for programmer errors (Box2D's B2_ASSERT). A caller that passes an
// index out of range, a NULL or destroyed handle, a negative size or a definition struct
// that was never initialised from its *_default_def() has a bug that no error status can
// report usefully: the library stops at once with the file, line and condition on stderr.
// On in every build type, Release included; configure with -DPLUME_DISABLE_ASSERTS=ON to
// compile them out (the condition is then not evaluated).
#ifndef PLUME_ASSERTS_H
#define PLUME_ASSERTS_H

#include "plume/core.h"

/// Prints "plume: file:line: assertion failed: expression" to stderr and aborts.
void plume_assert_fail(const char *expression, const char *file, int line)
#if defined(__GNUC__)
    __attribute__((noreturn, cold))
#endif
    ;

#ifdef PLUME_DISABLE_ASSERTS
// sizeof keeps the operands "used" (no warnings) without evaluating them.
#define PLUME_ASSERT(condition) ((void)sizeof(condition))
#else
#define PLUME_ASSERT(condition) ((condition) ? (void)0 : plume_assert_fail(#condition, __FILE__, __LINE__))
#endif

/// A definition struct passed by pointer: not NULL and started from its *_default_def().
#define PLUME_ASSERT_DEF(def) PLUME_ASSERT((def) != NULL && (def)->cookie == PLUME_DEF_COOKIE)
/// The same where NULL means "the defaults".
#define PLUME_ASSERT_DEF_OR_NULL(def) PLUME_ASSERT((def) == NULL || (def)->cookie == PLUME_DEF_COOKIE)

/// Set in a live handle's `magic` field by its create function and cleared by its destroy
/// function, so that a NULL handle, or one destroyed while its memory has not yet been reused,
/// stops at the first use instead of reading freed memory further.
#define PLUME_HANDLE_MAGIC 0x706c6831u
#define PLUME_ASSERT_HANDLE(handle) PLUME_ASSERT((handle) != NULL && (handle)->magic == PLUME_HANDLE_MAGIC)

/// 0 <= index < count.
#define PLUME_ASSERT_INDEX(index, count) PLUME_ASSERT((index) >= 0 && (index) < (count))

#endif
