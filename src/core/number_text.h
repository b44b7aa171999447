// Private: numbers written as text, for files that are read back and for messages.
#ifndef PLUME_CORE_NUMBER_TEXT_H
#define PLUME_CORE_NUMBER_TEXT_H

#include <stddef.h>

/// value in the fewest significant digits that read back as the same double: the first of
/// 15, 16, 17 (subnormals from 1); infinities and NaN as printf writes them. size >= 32.
const char *plume_number_shortest(char *text, size_t size, double value);

/// value with the digits it takes to show it outside [lo, hi]: "%g" prints 180.0001 as "180",
/// a value a message would then call not allowed. Six digits, then more until the text is no
/// bound (or reads back as value, or has 17).
const char *plume_number_outside(char *text, size_t size, double value, double lo, double hi);

#endif
