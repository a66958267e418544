#pragma once
// Feed-forward network of the paper (5-6-2, Li, Ma and Jiang; MATLAB): tansig hidden layers, a
// linear output layer, mapminmax scaling, Nguyen-Widrow initialization and the analytic Jacobian of
// the errors that trainbr needs.
//
// Conventions (every other module codes against these):
//   - Layer l = 0..L-1 maps a_l (size layer_sizes[l]) to a_{l+1} (size layer_sizes[l+1]):
//       n_{l+1} = W_l a_l + b_l,  a_{l+1} = tansig(n_{l+1}) = tanh(n_{l+1}) for hidden layers,
//       a_L = n_L (purelin) for the output layer.
//     W_l has rows = outputs of the layer (layer_sizes[l+1]) and columns = its inputs.
//   - Inputs and outputs of the network are in the normalized (mapminmax) space, one sample per
//     column: x is R x Q, y is S x Q.
//   - Flat parameter order (MATLAB getwb/formwb order for a feed-forward net): for each layer
//     l = 0..L-1, first its bias b_l (layer_sizes[l+1] entries), then its weights W_l in
//     column-major order (W_l(r, c) at offset + c * rows + r). For 5-6-2:
//       [b_0 (6), W_0 (6x5 = 30), b_1 (2), W_1 (2x6 = 12)]   -> N = 50.
//   - Errors e = t - y are flattened sample-major (column-major flattening of the S x Q error
//     matrix, MATLAB's e(:)): flat index of (output k, sample q) = q * S + k.
//   - J_e_w = de/dw (n x N, n = S * Q) = -dy/dw.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace whirl::nn {

/// MATLAB mapminmax with ymin = -1, ymax = 1, per variable (row):
///   y = 2 (x - xmin) / (xmax - xmin) - 1,   x = (y + 1) (xmax - xmin) / 2 + xmin.
/// A constant variable (xmax == xmin) is passed through unchanged (y = x), as MATLAB's mapminmax.
struct MapMinMax {
  Eigen::VectorXd xmin;  ///< per variable minimum of the fitted data, original units
  Eigen::VectorXd xmax;  ///< per variable maximum of the fitted data, original units

  /// Ranges of the rows of `x` (variables x samples). Throws InputError if x has no column or a
  /// non-finite entry.
  static MapMinMax Fit(const Eigen::MatrixXd& x);
  /// Identity scaling for `size` variables (xmin = -1, xmax = 1).
  static MapMinMax Identity(int size);

  int size() const { return static_cast<int>(xmin.size()); }
  bool IsConstant(int i) const { return xmax(i) == xmin(i); }
  /// dy/dx^-1 per variable: (xmax - xmin) / 2, or 1 for a constant variable. A standard deviation
  /// in normalized units times this is a standard deviation in original units.
  Eigen::VectorXd HalfRange() const;
  /// Original -> normalized, column-wise (x: size() x Q).
  Eigen::MatrixXd Apply(const Eigen::MatrixXd& x) const;
  /// Normalized -> original, column-wise.
  Eigen::MatrixXd Reverse(const Eigen::MatrixXd& y) const;
  /// Throws InputError unless sizes agree, entries are finite and xmin <= xmax.
  void Validate(const char* what) const;
};

/// Activations of one forward pass, kept for the Jacobian: a[0] = x, a[L] = y. Reused between
/// calls without reallocation when the sizes stay the same.
struct ForwardCache {
  std::vector<Eigen::MatrixXd> a;
  const Eigen::MatrixXd& output() const { return a.back(); }
};

struct Network {
  std::vector<int> layer_sizes;          ///< {inputs, hidden..., outputs}, e.g. {5, 6, 2}
  std::vector<Eigen::MatrixXd> weights;  ///< W_l, layer_sizes[l+1] x layer_sizes[l]
  std::vector<Eigen::VectorXd> biases;   ///< b_l, layer_sizes[l+1]

  /// A network of the given sizes with all weights and biases zero. Throws InputError unless
  /// there are at least two sizes (inputs, outputs) and every size is >= 1.
  static Network Zeros(const std::vector<int>& layer_sizes);

  int LayerCount() const { return static_cast<int>(weights.size()); }  ///< L
  int InputCount() const { return layer_sizes.front(); }
  int OutputCount() const { return layer_sizes.back(); }
  /// N = sum over layers of rows * (cols + 1); 50 for 5-6-2.
  int ParameterCount() const;
  /// Flat index of b_l(r) and of W_l(r, c) in the order documented at the top of this file.
  int BiasIndex(int layer, int r) const;
  int WeightIndex(int layer, int r, int c) const;

  /// All weights and biases in the flat order (MATLAB getwb).
  Eigen::VectorXd GetParameters() const;
  /// Inverse of GetParameters (MATLAB setwb); throws InputError if w.size() != N.
  void SetParameters(const Eigen::VectorXd& w);

  /// y = f(x), x normalized (InputCount() x Q), y normalized (OutputCount() x Q).
  Eigen::MatrixXd Forward(const Eigen::MatrixXd& x) const;
  /// Same, keeping the activations in `cache` (no allocation when sizes repeat).
  void Forward(const Eigen::MatrixXd& x, ForwardCache* cache) const;

  /// Throws InputError (naming `what`) unless sizes are consistent and every entry is finite.
  void Validate(const char* what) const;
};

/// Analytic J_e_w = de/dw for e = t - y (rows sample-major q * S + k, columns in flat order),
/// by back-propagation through the activations of the last Forward(x, cache) call:
///   delta_L = unit vector of output k, delta_l = (W_l^T delta_{l+1}) .* (1 - a_l.^2),
///   dy_k/db_l = delta_{l+1}, dy_k/dW_l = delta_{l+1} a_l^T,  J = -dy/dw.
/// `J_e_w` is resized to (S * Q) x N if needed.
void ErrorJacobian(const Network& net, const ForwardCache& cache, Eigen::MatrixXd* J_e_w);

/// G = J_e_w J_e_w' (n x n, n = S * Q, symmetric), the Gram matrix of the error Jacobian
/// `J_e_w` = ErrorJacobian(net, cache) of the last Forward(x, cache) call. With one hidden layer
/// (H tansig neurons) the rows of J_e_w have a product structure, so with x_q = a_0(:, q),
/// a_q = a_1(:, q) and u_qk = W_1(k, :)' .* (1 - a_q.^2) (row q * S + k):
///   G[(q,k), (q',k')] = (u_qk . u_q'k') (1 + x_q . x_q') + [k == k'] (1 + a_q . a_q'),
/// which costs O(n^2 (H + R)) instead of O(n^2 N) and does not read J_e_w. Other depths:
/// J_e_w J_e_w'. The two agree to rounding (tested).
void ErrorGram(const Network& net, const ForwardCache& cache, const Eigen::MatrixXd& J_e_w,
               Eigen::MatrixXd* G);

/// dy/dw for one input (normalized): S x N, row k = gradient of output k (= -J_e_w rows).
Eigen::MatrixXd OutputJacobian(const Network& net, const Eigen::VectorXd& x);

/// Nguyen-Widrow initialization as MATLAB initnw (Nguyen and Widrow, "Improving the learning
/// speed of 2-layer neural networks by choosing initial values of the adaptive weights").
/// For each hidden (tansig) layer with S neurons and R inputs (assumed in [-1, 1]):
///   wMag = 0.7 S^(1/R); each row of W = a uniform(-1, 1) row scaled to unit length times wMag;
///   b = wMag * linspace(-1, 1, S) .* sign(W(:, 1)) (linspace of one point = 1);
///   then W and b times 2 (tansig's active input range is [-2, 2]).
/// Output (purelin) layer: W and b uniform(-1, 1).
/// Random draws, in order: per hidden layer its W row by row; then the output layer's W row by
/// row, then its b, each Rng(seed).Uniform(-1, 1) (core/random.h). Same seed and sizes =>
/// identical weights on every platform.
void InitNguyenWidrow(std::uint64_t seed, Network* net);

}  // namespace whirl::nn
