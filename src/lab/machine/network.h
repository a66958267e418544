#pragma once
// A lumped thermal network integrated exactly: node temperatures T (degC) with
//   C dT/dt = -G T + G_b T_b(t) + Q(t),
// C diagonal heat capacities (J/K), G symmetric conductances (W/K: the couplings as a graph
// Laplacian plus each node's conductance to the boundaries on its diagonal), T_b the boundary
// temperatures (hall air, cabinet air; prescribed), Q the heat sources (W). With the inputs held
// over a step dt the solution is exact (no time-step error):
//   T(t + dt) = Phi(dt) T(t) + (I - Phi(dt)) G^-1 (G_b T_b + Q),
//   Phi(dt) = C^-1/2 V exp(-L dt) V' C^1/2,  S = C^-1/2 G C^-1/2 = V L V'
// (symmetric eigen-decomposition, Eigen::SelfAdjointEigenSolver). G is positive definite exactly
// when every node has a path of couplings to a boundary; Finalize() checks that and names a node
// that has none. Sources of the method: any text on linear state-space systems (the matrix
// exponential of a symmetric pencil), e.g. G. F. Franklin, J. D. Powell, M. Workman, "Digital
// Control of Dynamic Systems" (zero-order-hold discretization).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace whirl::machine {

class ThermalNetwork {
 public:
  /// Adds a node; returns its index. capacity_j_per_k > 0.
  int AddNode(const std::string& name, double capacity_j_per_k);
  /// Adds a boundary (prescribed temperature); returns its index among the boundaries.
  int AddBoundary(const std::string& name);
  /// Symmetric coupling between two nodes, W/K (>= 0; couplings add up).
  void Couple(int node_a, int node_b, double conductance_w_per_k);
  /// Coupling of a node to a boundary, W/K (>= 0).
  void CoupleBoundary(int node, int boundary, double conductance_w_per_k);
  /// Checks the network (positive capacities, finite non-negative conductances, a path to a
  /// boundary from every node) and decomposes it. InputError naming the offending node.
  void Finalize();

  int nodes() const { return static_cast<int>(names_.size()); }
  int boundaries() const { return static_cast<int>(boundary_names_.size()); }
  int NodeIndex(const std::string& name) const;  ///< InputError naming the node if unknown
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<std::string>& boundary_names() const { return boundary_names_; }
  const Eigen::VectorXd& capacity() const { return capacity_; }
  const Eigen::MatrixXd& conductance() const { return g_; }           ///< G (n x n)
  const Eigen::MatrixXd& boundary_conductance() const { return gb_; }  ///< G_b (n x boundaries)
  /// Steady state for constant inputs: G^-1 (G_b T_b + Q).
  Eigen::VectorXd SteadyState(const Eigen::VectorXd& boundary_c, const Eigen::VectorXd& q_w) const;
  /// Eigenvalues L of S (1/s, ascending; all > 0 after Finalize).
  const Eigen::VectorXd& rates_per_s() const { return rates_; }

 private:
  friend class Propagator;
  std::vector<std::string> names_, boundary_names_;
  Eigen::VectorXd capacity_;
  Eigen::MatrixXd g_, gb_;
  Eigen::MatrixXd v_;       // eigenvectors of S
  Eigen::VectorXd rates_;   // eigenvalues of S
  Eigen::MatrixXd g_inv_;   // G^-1
  bool finalized_ = false;
};

/// The exact one-step map of a finalized network for a fixed dt (inputs held over the step).
class Propagator {
 public:
  Propagator(const ThermalNetwork& network, double dt_s);
  double dt_s() const { return dt_s_; }
  /// T(t + dt) from T(t) with the boundary temperatures and sources held over the step.
  Eigen::VectorXd Step(const Eigen::VectorXd& t_c, const Eigen::VectorXd& boundary_c,
                       const Eigen::VectorXd& q_w) const;
  const Eigen::MatrixXd& phi() const { return phi_; }

 private:
  double dt_s_;
  Eigen::MatrixXd phi_;    // Phi(dt)
  Eigen::MatrixXd input_;  // (I - Phi) G^-1
  Eigen::MatrixXd gb_;
};

}  // namespace whirl::machine
