// Symmetric eigen-decomposition of the small element Hessians and their projection onto
// the positive semidefinite cone (projected Newton). Plain loops, no allocation, no
// threads: the same input gives the same bits.
#include "../core/asserts.h"
#include "sim/dense.h"

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <string.h>

// Householder reduction to tridiagonal form, A = Q T Q^T (Golub & Van Loan, Matrix
// Computations, section 8.3.1): d the diagonal of T, e[i] its entry (i, i+1), Q row-major.
static void tridiagonalize(const double *matrix, int n, double *d, double *e, double *Q)
{
	double a[PLUME_DENSE_MAX * PLUME_DENSE_MAX];
	memcpy(a, matrix, (size_t)(n * n) * sizeof(double));
	for (int i = 0; i < n * n; ++i)
		Q[i] = 0.0;
	for (int i = 0; i < n; ++i)
		Q[i * n + i] = 1.0;
	for (int k = 0; k + 2 < n; ++k) {
		// v reflects x = a[k+1.., k] onto -sign(x0) |x| e1.
		double v[PLUME_DENSE_MAX], norm2 = 0.0;
		for (int i = k + 1; i < n; ++i) {
			v[i] = a[i * n + k];
			norm2 += v[i] * v[i];
		}
		double tail2 = norm2 - v[k + 1] * v[k + 1];
		if (!(tail2 > 0.0))
			continue; // already tridiagonal in this column
		double alpha = v[k + 1] >= 0.0 ? -sqrt(norm2) : sqrt(norm2);
		v[k + 1] -= alpha;
		double vv = tail2 + v[k + 1] * v[k + 1];
		double beta = 2.0 / vv;
		// A <- P A P with P = I - beta v v^T on rows and columns k+1..n-1:
		// p = beta A v, w = p - (beta/2)(v^T p) v, A <- A - v w^T - w v^T.
		double p[PLUME_DENSE_MAX], vp = 0.0;
		for (int i = k + 1; i < n; ++i) {
			double sum = 0.0;
			for (int j = k + 1; j < n; ++j)
				sum += a[i * n + j] * v[j];
			p[i] = beta * sum;
			vp += v[i] * p[i];
		}
		for (int i = k + 1; i < n; ++i)
			p[i] -= 0.5 * beta * vp * v[i];
		for (int i = k + 1; i < n; ++i)
			for (int j = k + 1; j < n; ++j)
				a[i * n + j] -= v[i] * p[j] + p[i] * v[j];
		a[(k + 1) * n + k] = alpha;
		a[k * n + k + 1] = alpha;
		for (int i = k + 2; i < n; ++i) {
			a[i * n + k] = 0.0;
			a[k * n + i] = 0.0;
		}
		// Q <- Q P.
		for (int r = 0; r < n; ++r) {
			double sum = 0.0;
			for (int j = k + 1; j < n; ++j)
				sum += Q[r * n + j] * v[j];
			sum *= beta;
			for (int j = k + 1; j < n; ++j)
				Q[r * n + j] -= sum * v[j];
		}
	}
	for (int i = 0; i < n; ++i) {
		d[i] = a[i * n + i];
		e[i] = i + 1 < n ? a[i * n + i + 1] : 0.0;
	}
}

void plume_symmetric_eigen(const double *matrix, int n, double *values, double *vectors)
{
	// Tridiagonal reduction, then the implicit QL iteration with Wilkinson-type shifts
	// (the tql2 algorithm of EISPACK; Golub & Van Loan section 8.3). About five times
	// cheaper than cyclic Jacobi at n = 9..12, and just as accurate for the projection.
	PLUME_ASSERT(n >= 1 && n <= PLUME_DENSE_MAX);
	double d[PLUME_DENSE_MAX], e[PLUME_DENSE_MAX], z[PLUME_DENSE_MAX * PLUME_DENSE_MAX];
	tridiagonalize(matrix, n, d, e, z);
	for (int l = 0; l < n; ++l) {
		for (int iteration = 0; iteration < 60; ++iteration) {
			int m = l;
			for (; m + 1 < n; ++m) {
				double scale = fabs(d[m]) + fabs(d[m + 1]);
				if (fabs(e[m]) <= DBL_EPSILON * scale)
					break;
			}
			if (m == l)
				break;
			// Shift from the leading 2x2 block, then chase the bulge from m up to l.
			double g = (d[l + 1] - d[l]) / (2.0 * e[l]);
			double r = sqrt(g * g + 1.0);
			g = d[m] - d[l] + e[l] / (g + (g >= 0.0 ? r : -r));
			double s = 1.0, c = 1.0, p = 0.0;
			int i = m - 1;
			bool underflow = false;
			for (; i >= l; --i) {
				double f = s * e[i], b = c * e[i];
				r = sqrt(f * f + g * g); // no hypot: entries are far from overflow, and hypot is slow
				e[i + 1] = r;
				if (r == 0.0) {
					d[i + 1] -= p;
					e[m] = 0.0;
					underflow = true;
					break;
				}
				s = f / r;
				c = g / r;
				g = d[i + 1] - p;
				r = (d[i] - g) * s + 2.0 * c * b;
				p = s * r;
				d[i + 1] = g + p;
				g = c * r - b;
				for (int k = 0; k < n; ++k) {
					double zk1 = z[k * n + i + 1], zk = z[k * n + i];
					z[k * n + i + 1] = s * zk + c * zk1;
					z[k * n + i] = c * zk - s * zk1;
				}
			}
			if (underflow)
				continue;
			d[l] -= p;
			e[l] = g;
			e[m] = 0.0;
		}
	}
	memcpy(values, d, (size_t)n * sizeof(double));
	if (vectors)
		memcpy(vectors, z, (size_t)(n * n) * sizeof(double));
}

// Replaces a symmetric matrix by its projection on the PSD cone (negative eigenvalues
// dropped). Returns false, leaving it untouched, when it already is PSD up to rounding.
static bool project_if_indefinite(double *matrix, int n)
{
	double values[PLUME_DENSE_MAX];
	double vectors[PLUME_DENSE_MAX * PLUME_DENSE_MAX];
	plume_symmetric_eigen(matrix, n, values, vectors);
	double largest = 0.0, smallest = INFINITY;
	for (int k = 0; k < n; ++k) {
		largest = fmax(largest, fabs(values[k]));
		smallest = fmin(smallest, values[k]);
	}
	// Negative only by rounding (the zero eigenvalues of rigid motions come out as
	// +-1e-17 relative): rebuilding would only add rounding, so keep the matrix as it is.
	if (smallest >= -16.0 * DBL_EPSILON * largest)
		return false;
	for (int i = 0; i < n; ++i) {
		for (int j = i; j < n; ++j) {
			double sum = 0.0;
			for (int k = 0; k < n; ++k)
				if (values[k] > 0.0)
					sum += vectors[i * n + k] * values[k] * vectors[j * n + k];
			matrix[i * n + j] = sum;
			matrix[j * n + i] = sum;
		}
	}
	return true;
}

void plume_project_psd(double *matrix, int n)
{
	PLUME_ASSERT(n >= 1 && n <= PLUME_DENSE_MAX);
	project_if_indefinite(matrix, n);
}

// Orthonormal basis of the vectors of R^m whose entries sum to zero (Helmert): column k
// (k = 0 .. m-2) has k + 1 entries 1, then -(k + 1), then zeros, over sqrt((k+1)(k+2)).
static void helmert_basis(int m, double U[4][3])
{
	for (int i = 0; i < m; ++i)
		for (int k = 0; k + 1 < m; ++k) {
			double scale = 1.0 / sqrt((double)((k + 1) * (k + 2)));
			U[i][k] = i <= k ? scale : i == k + 1 ? -(double)(k + 1) * scale : 0.0;
		}
}

void plume_project_psd_translation_free(double *matrix, int vertex_count)
{
	PLUME_ASSERT(vertex_count >= 2 && vertex_count <= PLUME_DENSE_MAX / 3);
	int m = vertex_count, n = 3 * m, r = 3 * (m - 1);
	double U[4][3];
	helmert_basis(m, U);
	// reduced = (U x I3)^T H (U x I3), block by block.
	double reduced[PLUME_DENSE_MAX * PLUME_DENSE_MAX];
	for (int a = 0; a < m - 1; ++a)
		for (int b = 0; b < m - 1; ++b)
			for (int p = 0; p < 3; ++p)
				for (int q = 0; q < 3; ++q) {
					double sum = 0.0;
					for (int i = 0; i < m; ++i)
						for (int j = 0; j < m; ++j)
							sum += U[i][a] * U[j][b] * matrix[(3 * i + p) * n + 3 * j + q];
					reduced[(3 * a + p) * r + 3 * b + q] = sum;
				}
	for (int i = 0; i < r; ++i)
		for (int j = 0; j < i; ++j) {
			double mean = 0.5 * (reduced[i * r + j] + reduced[j * r + i]);
			reduced[i * r + j] = mean;
			reduced[j * r + i] = mean;
		}
	if (!project_if_indefinite(reduced, r))
		return;
	// Back from the projected reduced matrix: H = (U x I3) P (U x I3)^T.
	for (int i = 0; i < m; ++i)
		for (int j = i; j < m; ++j)
			for (int p = 0; p < 3; ++p)
				for (int q = 0; q < 3; ++q) {
					double sum = 0.0;
					for (int a = 0; a < m - 1; ++a)
						for (int b = 0; b < m - 1; ++b)
							sum += U[i][a] * U[j][b] * reduced[(3 * a + p) * r + 3 * b + q];
					matrix[(3 * i + p) * n + 3 * j + q] = sum;
					matrix[(3 * j + q) * n + 3 * i + p] = sum;
				}
}

bool plume_is_positive_semidefinite(const double *matrix, int n)
{
	double work[144], scale = 0;
	for (int i = 0; i < n; ++i)
		scale = fmax(scale, fabs(matrix[i * n + i]));
	if (scale == 0)
		return true;
	double threshold = 1e-12 * scale;
	memcpy(work, matrix, sizeof(double) * (size_t)(n * n));
	// Right-looking LDL^T: a pivot within the threshold of zero is a null direction
	// (rigid motions make element Hessians singular); its column must then vanish too.
	for (int k = 0; k < n; ++k) {
		double pivot = work[k * n + k];
		if (pivot < -threshold)
			return false;
		if (pivot <= threshold) {
			for (int i = k + 1; i < n; ++i)
				if (fabs(work[i * n + k]) > threshold)
					return false;
			continue;
		}
		for (int i = k + 1; i < n; ++i) {
			double factor = work[i * n + k] / pivot;
			for (int j = k + 1; j <= i; ++j)
				work[i * n + j] -= factor * work[j * n + k];
		}
	}
	return true;
}
