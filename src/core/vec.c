// Vectors and 3x3 matrices (the inline basics live in plume/core.h).
#include <math.h>

#include "plume/core.h"
#include "vec_inline.h"

double plume_v3_length(plume_vec3 a) { return core_v3_length(a); }

double plume_v3_distance(plume_vec3 a, plume_vec3 b) { return core_v3_distance(a, b); }

plume_vec3 plume_v3_normalize(plume_vec3 a) { return core_v3_normalize(a); }

plume_mat3 plume_m3_identity(void) { return (plume_mat3){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }

plume_mat3 plume_m3_mul(plume_mat3 a, plume_mat3 b)
{
	plume_mat3 c;
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			c.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
	return c;
}

plume_mat3 plume_m3_transpose(plume_mat3 a)
{
	plume_mat3 t;
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			t.m[i][j] = a.m[j][i];
	return t;
}

plume_vec3 plume_m3_apply(plume_mat3 a, plume_vec3 v) { return core_m3_apply(&a, v); }

double plume_m3_det(plume_mat3 a)
{
	return a.m[0][0] * (a.m[1][1] * a.m[2][2] - a.m[1][2] * a.m[2][1]) -
	       a.m[0][1] * (a.m[1][0] * a.m[2][2] - a.m[1][2] * a.m[2][0]) +
	       a.m[0][2] * (a.m[1][0] * a.m[2][1] - a.m[1][1] * a.m[2][0]);
}

plume_mat3 plume_m3_rotation(plume_vec3 axis, double angle)
{
	return core_m3_rotation_cs(axis, cos(angle), sin(angle));
}
