#pragma once
// Small dense kernels for the N x N (N = 50 for 5-6-2) or n x n (LinearSystem::kErrors) systems
// of the epoch loop. Eigen's blocked LLT, triangular-matrix solve and rankUpdate pack their
// operands for GEMM kernels, which at this size costs more than the arithmetic; these plain loops
// over contiguous column segments (all in L1) do the same operations in a different order, so
// results agree to rounding.
//
// Used by trainbr's epoch loop (src/product/nn/trainbr.cpp) and measured on their own by
// tests/bench/bench_nn.cpp (BM_EpochLinearAlgebra: the per-epoch linear-algebra floor).
#include <Eigen/Core>

namespace whirl::nn::detail {

/// Lower triangle of jj = J'J (the strict upper triangle is left untouched); Jt receives J'.
void GramLower(const Eigen::MatrixXd& J, Eigen::MatrixXd* Jt, Eigen::MatrixXd* jj);

/// A = beta * jj + diag_add * I on the lower triangle (jj's lower triangle is read), then
/// A = L L' in place (lower triangle), inv_diag = 1 / diag(L). False when a pivot is not positive
/// (or NaN), like Eigen::LLT's NumericalIssue. A must be n x n.
bool FactorShifted(const Eigen::MatrixXd& jj, double beta, double diag_add, Eigen::MatrixXd* A,
                   Eigen::VectorXd* inv_diag);

/// x = (L L')^-1 b with the factor of FactorShifted.
void SolveFactored(const Eigen::MatrixXd& L, const Eigen::VectorXd& inv_diag,
                   const Eigen::VectorXd& b, Eigen::VectorXd* x);

/// trace((L L')^-1) = ||L^-1||_F^2 with the factor of FactorShifted; work is scratch space.
double TraceOfInverse(const Eigen::MatrixXd& L, const Eigen::VectorXd& inv_diag,
                      Eigen::VectorXd* work);

}  // namespace whirl::nn::detail
