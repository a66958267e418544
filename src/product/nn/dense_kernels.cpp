#include "nn/dense_kernels.h"

#include <algorithm>
#include <cmath>

namespace whirl::nn::detail {
namespace {

using ConstSeg = Eigen::Map<const Eigen::VectorXd>;
using Seg = Eigen::Map<Eigen::VectorXd>;

// y[0..m) -= f * x[0..m) and the same with four columns at once (one pass over y for four
// updates). Plain loops the compiler vectorizes without call overhead: the segments are short
// (25 entries on average) and all in L1.
inline void AxpyNeg(double f, const double* __restrict x, double* __restrict y, Eigen::Index m) {
  for (Eigen::Index i = 0; i < m; ++i) y[i] -= f * x[i];
}
inline void Axpy4Neg(const double* f, const double* __restrict x0, const double* __restrict x1,
                     const double* __restrict x2, const double* __restrict x3, double* __restrict y,
                     Eigen::Index m) {
  const double f0 = f[0], f1 = f[1], f2 = f[2], f3 = f[3];
  for (Eigen::Index i = 0; i < m; ++i)
    y[i] -= (f0 * x0[i] + f1 * x1[i]) + (f2 * x2[i] + f3 * x3[i]);
}

// Solves L[s:, s:] x[s:] = x[s:] in place (forward substitution, four columns of L per pass;
// d = 1 / diag(L)).
void ForwardSubstitute(const double* a, const double* d, Eigen::Index n, Eigen::Index s,
                       double* x) {
  Eigen::Index k0 = s;
  for (; k0 + 4 <= n; k0 += 4) {
    for (Eigen::Index k = k0; k < k0 + 4; ++k) {
      x[k] *= d[k];
      for (Eigen::Index i = k + 1; i < k0 + 4; ++i) x[i] -= x[k] * a[k * n + i];
    }
    const Eigen::Index m = n - k0 - 4;
    const double* c0 = a + k0 * n + k0 + 4;
    Axpy4Neg(x + k0, c0, c0 + n, c0 + 2 * n, c0 + 3 * n, x + k0 + 4, m);
  }
  for (Eigen::Index k = k0; k < n; ++k) {
    x[k] *= d[k];
    AxpyNeg(x[k], a + k * n + k + 1, x + k + 1, n - k - 1);
  }
}

}  // namespace

// Lower triangle of jj = J'J (the strict upper triangle is left untouched), as a sum of the
// outer products of the rows of J, four rows per pass; Jt = J' makes the rows contiguous.
void GramLower(const Eigen::MatrixXd& J, Eigen::MatrixXd* Jt, Eigen::MatrixXd* jj) {
  const Eigen::Index N = J.cols();
  const Eigen::Index n = J.rows();
  *Jt = J.transpose();
  for (Eigen::Index j = 0; j < N; ++j) jj->col(j).tail(N - j).setZero();
  const double* t = Jt->data();
  double* g = jj->data();
  Eigen::Index r0 = 0;
  for (; r0 + 4 <= n; r0 += 4) {
    const double *x0 = t + r0 * N, *x1 = x0 + N, *x2 = x1 + N, *x3 = x2 + N;
    for (Eigen::Index j = 0; j < N; ++j) {
      const double f[4] = {-x0[j], -x1[j], -x2[j], -x3[j]};  // y -= (-f) x is y += f x exactly
      Axpy4Neg(f, x0 + j, x1 + j, x2 + j, x3 + j, g + j * N + j, N - j);
    }
  }
  for (; r0 < n; ++r0) {
    const double* x = t + r0 * N;
    for (Eigen::Index j = 0; j < N; ++j) AxpyNeg(-x[j], x + j, g + j * N + j, N - j);
  }
}

// A = beta * jj + diag_add * I on the lower triangle, then A = L L' in place: right-looking,
// four columns of L per pass over the trailing matrix. Returns false when a pivot is not
// positive (or NaN): the matrix is not numerically positive definite, like Eigen::LLT's
// NumericalIssue.
bool FactorShifted(const Eigen::MatrixXd& jj, double beta, double diag_add, Eigen::MatrixXd* A,
                   Eigen::VectorXd* inv_diag) {
  const Eigen::Index n = jj.rows();
  inv_diag->resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    A->col(j).tail(n - j) = beta * jj.col(j).tail(n - j);
    (*A)(j, j) += diag_add;
  }
  double* a = A->data();
  for (Eigen::Index k0 = 0; k0 < n; k0 += 4) {
    const Eigen::Index kend = std::min<Eigen::Index>(k0 + 4, n);
    for (Eigen::Index k = k0; k < kend; ++k) {  // the panel, already updated by earlier panels
      double* ck = a + k * n;
      const double d = ck[k];
      if (!(d > 0)) return false;
      const double l = std::sqrt(d);
      const double inv = 1.0 / l;
      ck[k] = l;
      (*inv_diag)(k) = inv;
      for (Eigen::Index i = k + 1; i < n; ++i) ck[i] *= inv;
      for (Eigen::Index j = k + 1; j < kend; ++j) AxpyNeg(ck[j], ck + j, a + j * n + j, n - j);
    }
    if (kend - k0 == 4) {
      const double *c0 = a + k0 * n, *c1 = c0 + n, *c2 = c1 + n, *c3 = c2 + n;
      for (Eigen::Index j = kend; j < n; ++j) {
        const double f[4] = {c0[j], c1[j], c2[j], c3[j]};
        Axpy4Neg(f, c0 + j, c1 + j, c2 + j, c3 + j, a + j * n + j, n - j);
      }
    } else {
      for (Eigen::Index k = k0; k < kend; ++k)
        for (Eigen::Index j = kend; j < n; ++j)
          AxpyNeg(a[k * n + j], a + k * n + j, a + j * n + j, n - j);
    }
  }
  return true;
}

// x = (L L')^-1 b with the factor of FactorShifted.
void SolveFactored(const Eigen::MatrixXd& L, const Eigen::VectorXd& inv_diag,
                   const Eigen::VectorXd& b, Eigen::VectorXd* x) {
  const Eigen::Index n = L.rows();
  const double* a = L.data();
  *x = b;
  double* y = x->data();
  ForwardSubstitute(a, inv_diag.data(), n, 0, y);
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    const double s = ConstSeg(a + k * n + k + 1, n - k - 1).dot(ConstSeg(y + k + 1, n - k - 1));
    y[k] = (y[k] - s) * inv_diag(k);
  }
}

// trace((L L')^-1) = ||L^-1||_F^2, column j of L^-1 by forward substitution from row j.
double TraceOfInverse(const Eigen::MatrixXd& L, const Eigen::VectorXd& inv_diag,
                      Eigen::VectorXd* work) {
  const Eigen::Index n = L.rows();
  work->resize(n);
  double* x = work->data();
  double sum = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    Seg(x + j, n - j).setZero();
    x[j] = 1.0;
    ForwardSubstitute(L.data(), inv_diag.data(), n, j, x);
    sum += Seg(x + j, n - j).squaredNorm();
  }
  return sum;
}

}  // namespace whirl::nn::detail
