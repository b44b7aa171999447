// Numbers written as text, for files that are read back and for messages.
#include "number_text.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

const char *plume_number_shortest(char *text, size_t size, double value)
{
	// A normal double whose shortest round-trip form has 15 digits or fewer is given back by
	// "%.15g" (DBL_DIG is 15, and %g drops the trailing zeros), so trying 15, 16 and 17
	// digits finds the shortest form: "0.1", not "0.10000000000000001". Subnormals hold
	// fewer digits (5e-324 is "5e-324", not "4.94065645841247e-324"): they try from 1.
	for (int digits = fabs(value) < DBL_MIN && value != 0.0 ? 1 : 15; digits <= 17; ++digits) {
		snprintf(text, size, "%.*g", digits, value);
		if (!isfinite(value) || strtod(text, NULL) == value)
			break;
	}
	return text;
}

const char *plume_number_outside(char *text, size_t size, double value, double lo, double hi)
{
	for (int digits = 6;; ++digits) {
		snprintf(text, size, "%.*g", digits, value);
		double printed = strtod(text, NULL);
		if (digits >= 17 || printed == value || (printed != lo && printed != hi))
			return text;
	}
}
