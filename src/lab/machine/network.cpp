#include "machine/network.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <queue>

#include "core/error.h"

namespace whirl::machine {

namespace {

void CheckConductance(double g, const std::string& what) {
  if (!std::isfinite(g) || g < 0)
    throw InputError("thermal network: conductance " + what + " must be finite and >= 0, got " +
                     std::to_string(g) + " W/K");
}

}  // namespace

int ThermalNetwork::AddNode(const std::string& name, double capacity_j_per_k) {
  if (!(capacity_j_per_k > 0) || !std::isfinite(capacity_j_per_k))
    throw InputError("thermal network: node '" + name + "' needs a capacity > 0 J/K, got " +
                     std::to_string(capacity_j_per_k));
  names_.push_back(name);
  const int n = nodes();
  capacity_.conservativeResize(n);
  capacity_(n - 1) = capacity_j_per_k;
  g_.conservativeResize(n, n);
  g_.row(n - 1).setZero();
  g_.col(n - 1).setZero();
  gb_.conservativeResize(n, boundaries());
  gb_.row(n - 1).setZero();
  finalized_ = false;
  return n - 1;
}

int ThermalNetwork::AddBoundary(const std::string& name) {
  boundary_names_.push_back(name);
  gb_.conservativeResize(nodes(), boundaries());
  gb_.col(boundaries() - 1).setZero();
  finalized_ = false;
  return boundaries() - 1;
}

void ThermalNetwork::Couple(int a, int b, double g) {
  CheckConductance(g, names_.at(a) + "-" + names_.at(b));
  if (a == b) throw InputError("thermal network: node '" + names_[a] + "' coupled to itself");
  g_(a, a) += g;
  g_(b, b) += g;
  g_(a, b) -= g;
  g_(b, a) -= g;
  finalized_ = false;
}

void ThermalNetwork::CoupleBoundary(int node, int boundary, double g) {
  CheckConductance(g, names_.at(node) + "-" + boundary_names_.at(boundary));
  g_(node, node) += g;
  gb_(node, boundary) += g;
  finalized_ = false;
}

int ThermalNetwork::NodeIndex(const std::string& name) const {
  for (int i = 0; i < nodes(); ++i)
    if (names_[i] == name) return i;
  throw InputError("thermal network: no node named '" + name + "'");
}

void ThermalNetwork::Finalize() {
  const int n = nodes();
  if (n == 0) throw InputError("thermal network: no nodes");
  // Every node needs a path to a boundary, else G is singular (its heat has nowhere to go).
  std::vector<bool> reached(n, false);
  std::queue<int> open;
  for (int i = 0; i < n; ++i)
    if (gb_.row(i).sum() > 0) reached[i] = true, open.push(i);
  while (!open.empty()) {
    const int i = open.front();
    open.pop();
    for (int j = 0; j < n; ++j)
      if (!reached[j] && g_(i, j) < 0) reached[j] = true, open.push(j);
  }
  for (int i = 0; i < n; ++i)
    if (!reached[i])
      throw InputError("thermal network: node '" + names_[i] +
                       "' has no path of couplings to a boundary (hall or cabinet air)");
  const Eigen::VectorXd s = capacity_.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd sym = s.asDiagonal() * g_ * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(sym);
  v_ = solver.eigenvectors();
  rates_ = solver.eigenvalues();
  g_inv_ = g_.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  finalized_ = true;
}

Eigen::VectorXd ThermalNetwork::SteadyState(const Eigen::VectorXd& boundary_c,
                                            const Eigen::VectorXd& q_w) const {
  if (!finalized_) throw InputError("thermal network: SteadyState before Finalize");
  return g_inv_ * (gb_ * boundary_c + q_w);
}

Propagator::Propagator(const ThermalNetwork& net, double dt_s) : dt_s_(dt_s), gb_(net.gb_) {
  if (!net.finalized_) throw InputError("thermal network: Propagator before Finalize");
  if (!(dt_s > 0)) throw InputError("thermal network: time step must be > 0 s");
  const Eigen::VectorXd c_half = net.capacity_.cwiseSqrt();
  const Eigen::VectorXd decay = (-net.rates_ * dt_s).array().exp().matrix();
  const Eigen::MatrixXd inner = net.v_ * decay.asDiagonal() * net.v_.transpose();
  phi_ = c_half.cwiseInverse().asDiagonal() * inner * c_half.asDiagonal();
  const int n = net.nodes();
  input_ = (Eigen::MatrixXd::Identity(n, n) - phi_) * net.g_inv_;
}

Eigen::VectorXd Propagator::Step(const Eigen::VectorXd& t_c, const Eigen::VectorXd& boundary_c,
                                 const Eigen::VectorXd& q_w) const {
  return phi_ * t_c + input_ * (gb_ * boundary_c + q_w);
}

}  // namespace whirl::machine
