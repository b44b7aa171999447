// Small dense symmetric matrices (element Hessians, n <= 12).
#ifndef PLUME_SIM_DENSE_H
#define PLUME_SIM_DENSE_H

#include <stdbool.h>

enum { PLUME_DENSE_MAX = 12 };

/// Eigen-decomposition of a symmetric n x n matrix (row-major, n <= 12) by Householder
/// tridiagonalisation and the implicit QL method: values[k] with eigenvector k in column k
/// of vectors (row-major n x n).
/// vectors may be NULL. Eigenvalues are in no particular order. Deterministic.
void plume_symmetric_eigen(const double *matrix, int n, double *values, double *vectors);

/// Projects a symmetric n x n matrix (row-major, n <= 12) to the nearest positive
/// semidefinite one (in the Frobenius norm) by clamping negative eigenvalues to zero
/// (eigen-decomposition as above).
/// A matrix whose eigenvalues are all >= -16 eps max|lambda| (positive semidefinite up to
/// rounding) is left exactly as it is. Deterministic.
void plume_project_psd(double *matrix, int n);

/// plume_project_psd for the Hessian of an energy of vertex_count points (n = 3 vertex_count
/// <= 12) that does not change when all points move together, so that the translations
/// are exact null vectors (every shell element energy). The projection is done on the
/// 3 (vertex_count - 1) dimensional complement of the translations, where all the
/// non-zero spectrum lives: the same result as plume_project_psd up to rounding, about
/// 2.5 (hinges) to 3 (triangles) times faster.
void plume_project_psd_translation_free(double *matrix, int vertex_count);

/// True when the symmetric n x n matrix (n <= 12) is positive semidefinite to rounding:
/// an LDL^T factorisation without pivoting meets no pivot below -1e-12 of the largest
/// diagonal. A cheap test that spares the eigen-decomposition of most tension elements.
bool plume_is_positive_semidefinite(const double *matrix, int n);

#endif // PLUME_SIM_DENSE_H
