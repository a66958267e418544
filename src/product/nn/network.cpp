#include "nn/network.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/random.h"

namespace whirl::nn {

MapMinMax MapMinMax::Fit(const Eigen::MatrixXd& x) {
  if (x.cols() == 0) throw InputError("mapminmax: no samples to take ranges from");
  if (!x.allFinite()) throw InputError("mapminmax: data contain NaN or infinity");
  MapMinMax m;
  m.xmin = x.rowwise().minCoeff();
  m.xmax = x.rowwise().maxCoeff();
  return m;
}

MapMinMax MapMinMax::Identity(int size) {
  MapMinMax m;
  m.xmin = Eigen::VectorXd::Constant(size, -1.0);
  m.xmax = Eigen::VectorXd::Constant(size, 1.0);
  return m;
}

Eigen::VectorXd MapMinMax::HalfRange() const {
  Eigen::VectorXd h(size());
  for (int i = 0; i < size(); ++i) h(i) = IsConstant(i) ? 1.0 : 0.5 * (xmax(i) - xmin(i));
  return h;
}

Eigen::MatrixXd MapMinMax::Apply(const Eigen::MatrixXd& x) const {
  if (x.rows() != size())
    throw InputError("mapminmax: data have " + std::to_string(x.rows()) + " variables, scaling " +
                     std::to_string(size()));
  Eigen::MatrixXd y(x.rows(), x.cols());
  for (int i = 0; i < size(); ++i) {
    if (IsConstant(i)) {
      y.row(i) = x.row(i);
    } else {
      const double g = 2.0 / (xmax(i) - xmin(i));
      y.row(i) = ((x.row(i).array() - xmin(i)) * g - 1.0).matrix();
    }
  }
  return y;
}

Eigen::MatrixXd MapMinMax::Reverse(const Eigen::MatrixXd& y) const {
  if (y.rows() != size())
    throw InputError("mapminmax: data have " + std::to_string(y.rows()) + " variables, scaling " +
                     std::to_string(size()));
  Eigen::MatrixXd x(y.rows(), y.cols());
  for (int i = 0; i < size(); ++i) {
    if (IsConstant(i)) {
      x.row(i) = y.row(i);
    } else {
      const double h = 0.5 * (xmax(i) - xmin(i));
      x.row(i) = ((y.row(i).array() + 1.0) * h + xmin(i)).matrix();
    }
  }
  return x;
}

void MapMinMax::Validate(const char* what) const {
  if (xmin.size() != xmax.size())
    throw InputError(std::string(what) + ": 'min' has " + std::to_string(xmin.size()) +
                     " entries but 'max' has " + std::to_string(xmax.size()));
  for (int i = 0; i < size(); ++i) {
    if (!std::isfinite(xmin(i)) || !std::isfinite(xmax(i)))
      throw InputError(std::string(what) + ": entry " + std::to_string(i) + " is not finite");
    if (xmin(i) > xmax(i))
      throw InputError(std::string(what) + ": entry " + std::to_string(i) + " has min " +
                       std::to_string(xmin(i)) + " > max " + std::to_string(xmax(i)));
  }
}

Network Network::Zeros(const std::vector<int>& layer_sizes) {
  if (layer_sizes.size() < 2)
    throw InputError("network: layer_sizes needs at least an input and an output size, got " +
                     std::to_string(layer_sizes.size()) + " entries");
  for (std::size_t l = 0; l < layer_sizes.size(); ++l)
    if (layer_sizes[l] < 1)
      throw InputError("network: layer_sizes[" + std::to_string(l) +
                       "] = " + std::to_string(layer_sizes[l]) + " must be >= 1");
  Network net;
  net.layer_sizes = layer_sizes;
  for (std::size_t l = 0; l + 1 < layer_sizes.size(); ++l) {
    net.weights.push_back(Eigen::MatrixXd::Zero(layer_sizes[l + 1], layer_sizes[l]));
    net.biases.push_back(Eigen::VectorXd::Zero(layer_sizes[l + 1]));
  }
  return net;
}

int Network::ParameterCount() const {
  int n = 0;
  for (std::size_t l = 0; l + 1 < layer_sizes.size(); ++l)
    n += layer_sizes[l + 1] * (layer_sizes[l] + 1);
  return n;
}

int Network::BiasIndex(int layer, int r) const {
  int offset = 0;
  for (int l = 0; l < layer; ++l) offset += layer_sizes[l + 1] * (layer_sizes[l] + 1);
  return offset + r;
}

int Network::WeightIndex(int layer, int r, int c) const {
  return BiasIndex(layer, 0) + layer_sizes[layer + 1] + c * layer_sizes[layer + 1] + r;
}

Eigen::VectorXd Network::GetParameters() const {
  Eigen::VectorXd w(ParameterCount());
  int k = 0;
  for (int l = 0; l < LayerCount(); ++l) {
    w.segment(k, biases[l].size()) = biases[l];
    k += static_cast<int>(biases[l].size());
    w.segment(k, weights[l].size()) =
        Eigen::Map<const Eigen::VectorXd>(weights[l].data(), weights[l].size());
    k += static_cast<int>(weights[l].size());
  }
  return w;
}

void Network::SetParameters(const Eigen::VectorXd& w) {
  if (w.size() != ParameterCount())
    throw InputError("network: parameter vector has " + std::to_string(w.size()) +
                     " entries, the network needs " + std::to_string(ParameterCount()));
  int k = 0;
  for (int l = 0; l < LayerCount(); ++l) {
    biases[l] = w.segment(k, biases[l].size());
    k += static_cast<int>(biases[l].size());
    Eigen::Map<Eigen::VectorXd>(weights[l].data(), weights[l].size()) =
        w.segment(k, weights[l].size());
    k += static_cast<int>(weights[l].size());
  }
}

Eigen::MatrixXd Network::Forward(const Eigen::MatrixXd& x) const {
  ForwardCache cache;
  Forward(x, &cache);
  return cache.output();
}

void Network::Forward(const Eigen::MatrixXd& x, ForwardCache* cache) const {
  if (x.rows() != InputCount())
    throw InputError("network: input has " + std::to_string(x.rows()) + " rows, the network " +
                     std::to_string(InputCount()) + " inputs");
  const int L = LayerCount();
  cache->a.resize(L + 1);
  cache->a[0] = x;
  for (int l = 0; l < L; ++l) {
    Eigen::MatrixXd& out = cache->a[l + 1];
    out.resize(layer_sizes[l + 1], x.cols());
    out.noalias() = weights[l] * cache->a[l];
    out.colwise() += biases[l];
    if (l + 1 < L) out = out.array().tanh().matrix();
  }
}

void Network::Validate(const char* what) const {
  const std::string w(what);
  if (layer_sizes.size() < 2) throw InputError(w + ": 'layer_sizes' needs at least 2 entries");
  if (weights.size() + 1 != layer_sizes.size() || biases.size() + 1 != layer_sizes.size())
    throw InputError(w + ": " + std::to_string(weights.size()) + " weight matrices and " +
                     std::to_string(biases.size()) + " bias vectors for " +
                     std::to_string(layer_sizes.size()) + " layer sizes (need one fewer)");
  for (std::size_t l = 0; l + 1 < layer_sizes.size(); ++l) {
    const std::string at = w + ": layer " + std::to_string(l);
    if (layer_sizes[l] < 1 || layer_sizes[l + 1] < 1) throw InputError(at + ": sizes must be >= 1");
    if (weights[l].rows() != layer_sizes[l + 1] || weights[l].cols() != layer_sizes[l])
      throw InputError(at + ": weights are " + std::to_string(weights[l].rows()) + "x" +
                       std::to_string(weights[l].cols()) + ", layer_sizes say " +
                       std::to_string(layer_sizes[l + 1]) + "x" + std::to_string(layer_sizes[l]));
    if (biases[l].size() != layer_sizes[l + 1])
      throw InputError(at + ": biases have " + std::to_string(biases[l].size()) +
                       " entries, layer_sizes say " + std::to_string(layer_sizes[l + 1]));
    if (!weights[l].allFinite() || !biases[l].allFinite())
      throw InputError(at + ": weights or biases are not finite");
  }
}

void ErrorJacobian(const Network& net, const ForwardCache& cache, Eigen::MatrixXd* J_e_w) {
  const int L = net.LayerCount();
  const int S = net.OutputCount();
  const int Q = static_cast<int>(cache.a[0].cols());
  const int N = net.ParameterCount();
  J_e_w->resize(static_cast<Eigen::Index>(S) * Q, N);
  // Offsets of each layer's block in the flat vector.
  std::vector<int> offset(L + 1, 0);
  for (int l = 0; l < L; ++l)
    offset[l + 1] = offset[l] + net.layer_sizes[l + 1] * (net.layer_sizes[l] + 1);
  // delta[l] holds d y_k / d n_{l+1} for every sample (rows = layer l outputs, cols = samples).
  thread_local std::vector<Eigen::MatrixXd> delta;
  delta.resize(L);
  for (int k = 0; k < S; ++k) {
    delta[L - 1].setZero(S, Q);
    delta[L - 1].row(k).setOnes();
    for (int l = L - 1; l > 0; --l) {
      delta[l - 1].resize(net.layer_sizes[l], Q);
      delta[l - 1].noalias() = net.weights[l].transpose() * delta[l];
      delta[l - 1].array() *= 1.0 - cache.a[l].array().square();
    }
    for (int l = 0; l < L; ++l) {
      const int rows = net.layer_sizes[l + 1];
      const int cols = net.layer_sizes[l];
      const Eigen::MatrixXd& a_in = cache.a[l];
      for (int q = 0; q < Q; ++q) {
        const Eigen::Index row = static_cast<Eigen::Index>(q) * S + k;
        for (int r = 0; r < rows; ++r) (*J_e_w)(row, offset[l] + r) = -delta[l](r, q);
        for (int c = 0; c < cols; ++c) {
          const double a = a_in(c, q);
          const int base = offset[l] + rows + c * rows;
          for (int r = 0; r < rows; ++r) (*J_e_w)(row, base + r) = -delta[l](r, q) * a;
        }
      }
    }
  }
}

void ErrorGram(const Network& net, const ForwardCache& cache, const Eigen::MatrixXd& J_e_w,
               Eigen::MatrixXd* G) {
  const Eigen::Index n = J_e_w.rows();
  if (net.LayerCount() != 2) {
    G->resize(n, n);
    G->noalias() = J_e_w * J_e_w.transpose();
    G->triangularView<Eigen::StrictlyUpper>() = G->transpose();  // exactly symmetric
    return;
  }
  const int S = net.OutputCount();
  const int H = net.layer_sizes[1];
  const Eigen::MatrixXd& x = cache.a[0];  // R x Q
  const Eigen::MatrixXd& a = cache.a[1];  // H x Q
  const Eigen::Index Q = x.cols();
  if (n != S * Q)
    throw InputError("network: Jacobian has " + std::to_string(n) + " rows, the cache " +
                     std::to_string(S * Q) + " errors");
  const Eigen::MatrixXd& W1 = net.weights[1];
  // ut.col(q * S + k) = u_qk; the dot products below run over contiguous columns of length H.
  thread_local Eigen::MatrixXd ut, px, pa;
  ut.resize(H, n);
  for (Eigen::Index q = 0; q < Q; ++q)
    for (int k = 0; k < S; ++k)
      ut.col(q * S + k) =
          W1.row(k).transpose().cwiseProduct((1.0 - a.col(q).array().square()).matrix());
  px.resize(Q, Q);
  pa.resize(Q, Q);
  px.noalias() = x.transpose() * x;
  pa.noalias() = a.transpose() * a;
  G->resize(n, n);
  for (Eigen::Index c = 0; c < n; ++c) {
    const Eigen::Index qc = c / S, kc = c % S;
    for (Eigen::Index r = c; r < n; ++r) {
      const Eigen::Index qr = r / S, kr = r % S;
      double g = ut.col(r).dot(ut.col(c)) * (1.0 + px(qr, qc));
      if (kr == kc) g += 1.0 + pa(qr, qc);
      (*G)(r, c) = g;
      (*G)(c, r) = g;
    }
  }
}

Eigen::MatrixXd OutputJacobian(const Network& net, const Eigen::VectorXd& x) {
  ForwardCache cache;
  net.Forward(x, &cache);
  Eigen::MatrixXd J;
  ErrorJacobian(net, cache, &J);
  return -J;
}

void InitNguyenWidrow(std::uint64_t seed, Network* net) {
  Rng rng(seed);
  const int L = net->LayerCount();
  for (int l = 0; l + 1 < L; ++l) {
    const int S = net->layer_sizes[l + 1];
    const int R = net->layer_sizes[l];
    const double w_mag = 0.7 * std::pow(static_cast<double>(S), 1.0 / R);
    Eigen::MatrixXd& W = net->weights[l];
    for (int r = 0; r < S; ++r) {
      for (int c = 0; c < R; ++c) W(r, c) = rng.Uniform(-1.0, 1.0);
      const double norm = W.row(r).norm();
      // A zero row has probability 2^-53R; give it a direction rather than dividing by zero.
      if (norm == 0.0) W(r, 0) = 1.0;
      W.row(r) *= w_mag / (norm == 0.0 ? 1.0 : norm);
    }
    Eigen::VectorXd& b = net->biases[l];
    for (int r = 0; r < S; ++r) {
      const double lin = S == 1 ? 1.0 : -1.0 + 2.0 * r / (S - 1);
      const double sign = W(r, 0) > 0 ? 1.0 : (W(r, 0) < 0 ? -1.0 : 0.0);
      b(r) = w_mag * lin * sign;
    }
    W *= 2.0;
    b *= 2.0;
  }
  Eigen::MatrixXd& W = net->weights[L - 1];
  for (int r = 0; r < W.rows(); ++r)
    for (int c = 0; c < W.cols(); ++c) W(r, c) = rng.Uniform(-1.0, 1.0);
  Eigen::VectorXd& b = net->biases[L - 1];
  for (int r = 0; r < b.size(); ++r) b(r) = rng.Uniform(-1.0, 1.0);
}

}  // namespace whirl::nn
