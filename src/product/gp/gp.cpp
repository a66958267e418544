#include "gp/gp.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"

namespace whirl::gp {
namespace {

constexpr double kSqrt5 = 2.2360679774997896964;
constexpr double kInf = std::numeric_limits<double>::infinity();

// KernelMatrices for K(z, z): the element-wise functions of the squared distances r2 on the
// lower triangle (column by column, vectorized), then mirrored.
void SymmetricKernel(Kernel kernel, const Eigen::MatrixXd& r2, double sf2, Eigen::MatrixXd* kf,
                     Eigen::MatrixXd* g) {
  const Eigen::Index n = r2.cols();
  kf->resize(n, n);
  if (g) g->resize(n, n);
  Eigen::ArrayXd s2_all(n), r_all(n), e_all(n);  // one column's terms, from index 0 (aligned)
  for (Eigen::Index q = 0; q < n; ++q) {
    const Eigen::Index m = n - q;
    auto s2 = s2_all.head(m), r = r_all.head(m), e = e_all.head(m);
    s2 = r2.col(q).tail(m).array();
    if (kernel == Kernel::kSquaredExponential) {
      kf->col(q).tail(m) = (sf2 * (-0.5 * s2).exp()).matrix();
      if (g) g->col(q).tail(m) = kf->col(q).tail(m);
      continue;
    }
    r = s2.sqrt();
    e = (-kSqrt5 * r).exp();
    kf->col(q).tail(m) = (sf2 * (1.0 + kSqrt5 * r + (5.0 / 3.0) * s2) * e).matrix();
    if (g) g->col(q).tail(m) = (sf2 * (5.0 / 3.0) * (1.0 + kSqrt5 * r) * e).matrix();
  }
  kf->triangularView<Eigen::StrictlyUpper>() = kf->transpose();
  if (g) g->triangularView<Eigen::StrictlyUpper>() = g->transpose();
}

// Kernel values K_f(p, q) and, in g, the factor with dK_f/d ln l_i = g * (dz_i / l_i)^2.
void KernelMatrices(Kernel kernel, const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                    const Eigen::VectorXd& length, double sf2, Eigen::MatrixXd* kf,
                    Eigen::MatrixXd* g) {
  const Eigen::MatrixXd as = length.cwiseInverse().asDiagonal() * a;
  const Eigen::MatrixXd bs = length.cwiseInverse().asDiagonal() * b;
  Eigen::MatrixXd r2 =
      (-2.0 * as.transpose() * bs).colwise() + as.colwise().squaredNorm().transpose();
  r2.rowwise() += bs.colwise().squaredNorm();
  r2 = r2.cwiseMax(0.0);
  if (&a == &b) return SymmetricKernel(kernel, r2, sf2, kf, g);
  if (kernel == Kernel::kSquaredExponential) {
    *kf = sf2 * (-0.5 * r2.array()).exp().matrix();
    if (g) *g = *kf;
    return;
  }
  const Eigen::ArrayXXd r = r2.array().sqrt(), e = (-kSqrt5 * r).exp();
  *kf = (sf2 * (1.0 + kSqrt5 * r + (5.0 / 3.0) * r2.array()) * e).matrix();
  if (g) *g = (sf2 * (5.0 / 3.0) * (1.0 + kSqrt5 * r) * e).matrix();
}

// H: n x m basis of the mean at the columns of z.
Eigen::MatrixXd Basis(Mean mean, const Eigen::MatrixXd& z) {
  Eigen::MatrixXd h(z.cols(), MeanSize(mean, static_cast<int>(z.rows())));
  h.col(0).setOnes();
  if (mean == Mean::kLinear) h.rightCols(z.rows()) = z.transpose();
  return h;
}

// Eigen's LLT of K = K_f + sigma_n^2 I, computed as LLT::compute does (Eigen 3.4: the same
// blocked in-place factorization of the lower triangle, so the same bits) but from K_f and the
// noise directly into the factor's own buffer, and without the L1 norm compute() takes for
// rcond() (never called here): one n x n pass and copy fewer per likelihood evaluation.
// It reads LLT's protected members and Eigen::internal, written against Eigen 3.4 (Debian 12's);
// any other Eigen takes the public path (one copy more, the same factorization).
#if EIGEN_VERSION_AT_LEAST(3, 4, 0) && !EIGEN_VERSION_AT_LEAST(3, 4, 90)
class KernelCholesky : public Eigen::LLT<Eigen::MatrixXd> {
 public:
  void Compute(const Eigen::MatrixXd& kf, double noise2) {
    m_matrix = kf;
    m_matrix.diagonal().array() += noise2;
    m_l1_norm = std::numeric_limits<double>::quiet_NaN();  // not computed
    m_isInitialized = true;
    const bool ok = Eigen::internal::llt_inplace<double, Eigen::Lower>::blocked(m_matrix) == -1;
    m_info = ok ? Eigen::Success : Eigen::NumericalIssue;
  }
};
#else
class KernelCholesky : public Eigen::LLT<Eigen::MatrixXd> {
 public:
  void Compute(const Eigen::MatrixXd& kf, double noise2) {
    k_ = kf;
    k_.diagonal().array() += noise2;
    compute(k_);
  }

 private:
  Eigen::MatrixXd k_;
};
#endif

// Everything NLML and its gradient need at one theta, and the buffers they are computed in: one
// Factors serves every evaluation of a fit (same z), so that no n x n matrix is allocated per
// evaluation (at 100 rows a fresh one per step made the C library grow and trim its heap at
// every evaluation: a third of the fit's CPU time, docs/workpiece-model.md "Speed").
struct Factors {
  Eigen::MatrixXd h;              // the basis H of z (set by the first Factor)
  Eigen::MatrixXd scaled, r2;     // z / l per input; squared scaled distances
  Eigen::RowVectorXd sq;          // squared norms of the columns of `scaled`
  Eigen::MatrixXd kf, g;          // K_f, the gradient's factor of K_f (Matern)
  KernelCholesky chol;
  Eigen::LLT<Eigen::MatrixXd> a_chol;
  Eigen::MatrixXd k_inv_h;
  Eigen::VectorXd b, alpha, r;
  Eigen::MatrixXd l_inv, k_inv, w, wg;  // Gradient: L^-1, K^-1, alpha alpha' - K^-1, w .* g
  bool g_is_kf = false;                  // squared exponential: the gradient's factor is K_f
  // Gradient, up to kCachedDifferenceRows rows: per input i the squared differences
  // (z_ip - z_iq)^2, n x n, computed at the first gradient of the fit (they depend on z only).
  std::vector<Eigen::MatrixXd> dz2;
  Eigen::ArrayXd zi;  // Gradient from more rows: one input's row
};

// KernelMatrices(kernel, z, z, ...) into f->kf (and f->g) through f's buffers. The squared
// distances on the lower triangle only (all SymmetricKernel reads), each as Eigen's matrix product
// computes it from 20 rows + columns + inputs on (its block kernel without FMA: the products
// summed in input order from 0, times -2, added to 0; Eigen 3.4, checked by the model files
// staying byte-identical), without the product's packing of the upper triangle.
void OwnKernel(Kernel kernel, const Eigen::MatrixXd& z, const Eigen::VectorXd& length, double sf2,
               bool with_g, Factors* f) {
  const Eigen::Index d = z.rows(), n = z.cols();
  f->scaled.noalias() = length.cwiseInverse().asDiagonal() * z;
  if (d + 2 * n < 20) {  // Eigen's coefficient-based product, another summation order
    f->r2.noalias() = -2.0 * f->scaled.transpose() * f->scaled;
    f->r2.colwise() += f->scaled.colwise().squaredNorm().transpose();
    f->r2.rowwise() += f->scaled.colwise().squaredNorm();
    f->r2 = f->r2.cwiseMax(0.0);
  } else {
    f->sq = f->scaled.colwise().squaredNorm();
    f->r2.resize(n, n);
    const double* a = f->scaled.data();
    for (Eigen::Index q = 0; q < n; ++q)
      for (Eigen::Index p = q; p < n; ++p) {
        double acc = 0;
        for (Eigen::Index i = 0; i < d; ++i) acc = a[p * d + i] * a[q * d + i] + acc;
        const double r2 = ((0.0 + -2.0 * acc) + f->sq(p)) + f->sq(q);
        f->r2(p, q) = r2 < 0.0 ? 0.0 : r2;
      }
  }
  f->g_is_kf = kernel == Kernel::kSquaredExponential;  // SymmetricKernel's g would copy K_f
  SymmetricKernel(kernel, f->r2, sf2, &f->kf, with_g && !f->g_is_kf ? &f->g : nullptr);
}

// Fills f at theta; false if K or H'K^-1H is not PD.
bool Factor(Kernel kernel, Mean mean, const Eigen::MatrixXd& z, const Eigen::VectorXd& u,
            const Eigen::VectorXd& theta, double noise2, bool with_g, Factors* f) {
  const int d = static_cast<int>(z.rows());
  const Eigen::VectorXd length = theta.head(d).array().exp();
  const double sf2 = std::exp(2.0 * theta(d));
  if (!length.allFinite() || !std::isfinite(sf2) || !std::isfinite(noise2)) return false;
  OwnKernel(kernel, z, length, sf2, with_g, f);
  f->chol.Compute(f->kf, noise2);
  if (f->chol.info() != Eigen::Success) return false;
  if (f->h.rows() != z.cols()) f->h = Basis(mean, z);
  f->k_inv_h = f->chol.solve(f->h);
  f->a_chol.compute(f->h.transpose() * f->k_inv_h);
  if (f->a_chol.info() != Eigen::Success) return false;
  f->b = f->a_chol.solve(f->k_inv_h.transpose() * u);
  f->r = u - f->h * f->b;
  f->alpha = f->chol.solve(f->r);
  return f->alpha.allFinite();
}

// K^-1 from K = L L' in about 2n^3/3 flops: the triangular inverse X = L^-1 block column by
// block column (column block j of X is zero above row j), then K^-1 = X' X by rank updates (row
// block i of X is zero right of its diagonal block); solving with the identity takes 2n^3.
// x: the buffer of L^-1.
void InverseFromCholesky(const Eigen::LLT<Eigen::MatrixXd>& chol, Eigen::MatrixXd* x,
                         Eigen::MatrixXd* k_inv) {
  constexpr Eigen::Index kBlock = 32;
  const Eigen::Index n = chol.rows();
  x->setZero(n, n);
  for (Eigen::Index j = 0; j < n; j += kBlock) {
    const Eigen::Index b = std::min(kBlock, n - j), m = n - j;
    auto block = x->block(j, j, m, b);
    block.topRows(b).setIdentity();
    chol.matrixLLT().bottomRightCorner(m, m).triangularView<Eigen::Lower>().solveInPlace(block);
  }
  k_inv->setZero(n, n);
  for (Eigen::Index i = 0; i < n; i += kBlock) {
    const Eigen::Index b = std::min(kBlock, n - i), c = i + b;
    k_inv->topLeftCorner(c, c).selfadjointView<Eigen::Lower>().rankUpdate(
        x->block(i, 0, b, c).transpose());
  }
  k_inv->triangularView<Eigen::StrictlyUpper>() = k_inv->transpose();
}

Eigen::MatrixXd InverseFromCholesky(const Eigen::LLT<Eigen::MatrixXd>& chol) {
  Eigen::MatrixXd x, k_inv;
  InverseFromCholesky(chol, &x, &k_inv);
  return k_inv;
}

// Gradient keeps the squared input differences up to this many rows (the refits of tables below
// 70 rows: 16 rows at 20, where it saves CPU); from 100 rows their d n^2 values cost more to read
// than to recompute (measured in docs/workpiece-model.md, "Speed", fifth round).
constexpr int kCachedDifferenceRows = 64;

// -tr(W dK/dtheta_j) / 2 for every j, W = alpha alpha' - K^-1 (R&W eq. 5.9).
void Gradient(const Eigen::MatrixXd& z, const Eigen::VectorXd& theta, double dsn2_dtheta,
              Factors* factors, Eigen::VectorXd* gradient) {
  const int d = static_cast<int>(z.rows()), n = static_cast<int>(z.cols());
  Factors& f = *factors;
  InverseFromCholesky(f.chol, &f.l_inv, &f.k_inv);
  f.w.noalias() = f.alpha * f.alpha.transpose();
  f.w -= f.k_inv;
  f.wg = f.w.cwiseProduct(f.g_is_kf ? f.kf : f.g);
  const Eigen::MatrixXd& w = f.w;
  const Eigen::MatrixXd& wg = f.wg;
  Eigen::VectorXd& grad = *gradient;
  grad.resize(d + 2);
  const bool cached = n <= kCachedDifferenceRows;
  if (cached && (f.dz2.size() != static_cast<std::size_t>(d) || f.dz2[0].cols() != n)) {
    f.dz2.assign(static_cast<std::size_t>(d), Eigen::MatrixXd(n, n));
    for (int i = 0; i < d; ++i) {
      const Eigen::ArrayXd zi = z.row(i).transpose();
      for (int q = 0; q < n; ++q) f.dz2[i].col(q) = (zi - zi(q)).square().matrix();
    }
  }
  // Both branches sum the same products in the same order (the squares are exact either way).
  for (int i = 0; i < d; ++i) {
    double s = 0;
    if (cached) {
      const Eigen::MatrixXd& dz2 = f.dz2[static_cast<std::size_t>(i)];
      for (int q = 0; q < n; ++q) s += (wg.col(q).array() * dz2.col(q).array()).sum();
    } else {
      Eigen::ArrayXd& zi = f.zi;
      zi = z.row(i).transpose();  // contiguous: the inner loop vectorizes
      for (int q = 0; q < n; ++q) s += (wg.col(q).array() * (zi - zi(q)).square()).sum();
    }
    grad(i) = -0.5 * s * std::exp(-2.0 * theta(i));
  }
  grad(d) = -w.cwiseProduct(f.kf).sum();
  grad(d + 1) = -0.5 * w.trace() * dsn2_dtheta;
}

// NegLogMarginalLikelihood in the buffers f (of earlier evaluations on the same z, or empty).
double Nlml(Kernel kernel, Mean mean, const Eigen::MatrixXd& z, const Eigen::VectorXd& u,
            const Eigen::VectorXd& theta, double min_noise_variance, Eigen::VectorXd* gradient,
            Factors* f) {
  const int d = static_cast<int>(z.rows()), n = static_cast<int>(z.cols());
  const double sn2_free = std::exp(2.0 * theta(d + 1));
  if (!Factor(kernel, mean, z, u, theta, sn2_free + min_noise_variance, gradient != nullptr, f)) {
    if (gradient) gradient->setConstant(theta.size(), kInf);
    return kInf;
  }
  const double log_det_half = f->chol.matrixLLT().diagonal().array().log().sum();
  const double nlml = 0.5 * f->r.dot(f->alpha) + log_det_half + 0.5 * n * std::log(2.0 * kPi);
  if (gradient) Gradient(z, theta, 2.0 * sn2_free, f, gradient);
  return nlml;
}

void ValidateData(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, Mean mean) {
  if (x.cols() != y.size())
    throw InputError("gaussian process: " + std::to_string(x.cols()) + " input columns but " +
                     std::to_string(y.size()) + " targets");
  if (!x.allFinite() || !y.allFinite())
    throw InputError("gaussian process: the training data hold a non-finite value");
  const int m = MeanSize(mean, static_cast<int>(x.rows()));
  if (y.size() <= m + 1)
    throw InputError("gaussian process: " + std::to_string(y.size()) + " rows for a " +
                     ToString(mean) + " mean with " + std::to_string(m) +
                     " coefficients; needs at least " + std::to_string(m + 2));
}

// Standardization of the header comment (population sd; 1 for a constant column).
Gp Standardized(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& o) {
  Gp gp;
  gp.kernel = o.kernel;
  gp.mean = o.mean;
  gp.min_noise_variance = o.min_noise_variance;
  gp.input_shift = x.rowwise().mean();
  const Eigen::MatrixXd xc = x.colwise() - gp.input_shift;
  gp.input_scale = (xc.rowwise().squaredNorm() / static_cast<double>(x.cols())).cwiseSqrt();
  for (Eigen::Index i = 0; i < gp.input_scale.size(); ++i)
    if (!(gp.input_scale(i) > 0)) gp.input_scale(i) = 1.0;
  gp.z = gp.input_scale.cwiseInverse().asDiagonal() * xc;
  gp.target_shift = y.mean();
  const double sd = std::sqrt((y.array() - gp.target_shift).square().mean());
  gp.target_scale = sd > 0 ? sd : 1.0;
  gp.u = (y.array() - gp.target_shift) / gp.target_scale;
  return gp;
}

// Starting points (GpOptions::restarts): the first in standardized target units (signal sd 1,
// noise sd 0.1, length scales sqrt(d)); the second scaled to what the mean's least-squares fit
// leaves of the standardized targets (sd s: small where a power-law mean fits well): signal sd s,
// noise sd 0.1 s, length scales 2 sqrt(d); then two more of the first kind.
std::vector<Eigen::VectorXd> StartPoints(const Gp& gp, int count) {
  static const double kLength[kStartCount] = {1.0, 2.0, 0.5, 0.25};
  static const double kNoise[kStartCount] = {0.1, 0.1, 0.3, 0.5};
  const int d = gp.InputCount();
  const Eigen::MatrixXd h = Basis(gp.mean, gp.z);
  const Eigen::VectorXd left = gp.u - h * h.colPivHouseholderQr().solve(gp.u);
  const double s = std::sqrt(std::max(left.squaredNorm() / static_cast<double>(gp.u.size()), 1e-6));
  std::vector<Eigen::VectorXd> starts;
  for (int index = 0; index < count; ++index) {
    const double scale = index == 1 ? s : 1.0;
    Eigen::VectorXd theta(d + 2);
    theta.head(d).setConstant(std::log(kLength[index] * std::sqrt(static_cast<double>(d))));
    theta(d) = std::log(scale);
    theta(d + 1) = std::log(kNoise[index] * scale);
    starts.push_back(theta);
  }
  return starts;
}

// Minimizes NLML from each start; fills gp->theta with the best.
void Optimize(const GpOptions& o, const std::vector<Eigen::VectorXd>& starts, Gp* gp,
              GpSummary* summary) {
  const int d = gp->InputCount();
  Factors buffers;
  const SmoothObjective f = [&](const Eigen::VectorXd& t, Eigen::VectorXd* grad) {
    double v = Nlml(gp->kernel, gp->mean, gp->z, gp->u, t, gp->min_noise_variance, grad, &buffers);
    if (o.length_prior_sd > 0 && std::isfinite(v)) {
      const Eigen::ArrayXd dev = (t.head(d).array() - LengthPriorMean(d)) / o.length_prior_sd;
      v += 0.5 * dev.square().sum();
      if (grad) grad->head(d).array() += dev / o.length_prior_sd;
    }
    return v;
  };
  // Isotropic: (ln l, ln s_f, ln s_n) <-> theta with d equal length scales.
  const auto expand = [d](const Eigen::VectorXd& t3) {
    Eigen::VectorXd t(d + 2);
    t.head(d).setConstant(t3(0));
    t.tail(2) = t3.tail(2);
    return t;
  };
  const SmoothObjective f_iso = [&](const Eigen::VectorXd& t3, Eigen::VectorXd* grad3) {
    Eigen::VectorXd g;
    const double v = f(expand(t3), grad3 ? &g : nullptr);
    if (grad3) {
      grad3->resize(3);
      *grad3 << g.head(d).sum(), g(d), g(d + 1);
    }
    return v;
  };
  GpSummary s;
  s.nlml = kInf;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const Eigen::VectorXd& start = starts[i];
    Eigen::VectorXd t = start;
    if (o.isotropic) t = Eigen::Vector3d(start.head(d).mean(), start(d), start(d + 1));
    const BfgsSummary b = MinimizeBfgs(o.isotropic ? f_iso : f, &t,
                                       gp->u.size() < o.single_start_rows ? o.bfgs : o.bfgs_large);
    if (o.isotropic) t = expand(t);
    s.start_nlml.push_back(b.final_cost);
    if (b.final_cost < s.nlml || i == 0) {
      s.nlml = b.final_cost;
      s.optimizer = b;
      gp->theta = t;
    }
  }
  if (summary) *summary = s;
}

// m rows of n spread evenly by index: floor(j n / m), j = 0..m-1 (all rows if m <= 0 or m >= n).
std::vector<int> EvenRows(int n, int m) {
  std::vector<int> rows;
  if (m <= 0 || m >= n) return rows;
  for (int j = 0; j < m; ++j)
    rows.push_back(static_cast<int>(static_cast<long long>(j) * n / m));
  return rows;
}

// gp restricted to `rows` (its standardization kept).
Gp RowsOf(const Gp& gp, const std::vector<int>& rows) {
  Gp sub = gp;
  sub.z = gp.z(Eigen::all, rows);
  sub.u = gp.u(rows);
  return sub;
}

// `starts` empty: StartPoints of the (subset of) standardized data.
Gp FitFromStarts(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& o,
                 const std::vector<Eigen::VectorXd>& starts, GpSummary* summary) {
  o.Validate();
  ValidateData(x, y, o.mean);
  const int n = static_cast<int>(y.size());
  Gp gp = Standardized(x, y, o);
  gp.rows = EvenRows(n, o.max_rows);
  if (!gp.rows.empty()) gp = RowsOf(gp, gp.rows);
  const std::vector<int> hyper = EvenRows(static_cast<int>(gp.u.size()), o.hyperparameter_rows);
  Gp sub = hyper.empty() ? gp : RowsOf(gp, hyper);
  const int count = static_cast<int>(sub.u.size()) < o.single_start_rows ? o.restarts : 1;
  Optimize(o, starts.empty() ? StartPoints(sub, count) : starts, &sub, summary);
  gp.theta = sub.theta;
  // A noise sd the likelihood drove to 0 (ln below -30: exp(-60) = 9e-27 standardized variance,
  // far below min_noise_variance's 1e-12 floor) is written as -30, the rule a file's numbers
  // must keep (kThetaRange below): the same predictions, and a model file that loads. The same
  // for a signal sd driven to 0 (a linear-mean GP that found no departure from its mean: seen on
  // a 26-row table of a generator family in scripts/design_study.py, ln s_f = -30.09) and for
  // length scales beyond e^+-30 (an input the fit ignores): the kernel's share changes by less
  // than exp(-60).
  gp.theta = gp.theta.cwiseMax(-30.0).cwiseMin(30.0);
  gp.noise_variance = gp.SigmaN2();
  gp.Factorize();
  return gp;
}

// A JSON array of finite numbers named `name` in messages.
Eigen::VectorXd ArrayToVector(const nlohmann::json& a, const std::string& name) {
  const std::vector<double> v = RequireNumbers(a, "gaussian process: '" + name + "'");
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

Eigen::VectorXd JsonVector(const nlohmann::json& j, const char* key) {
  return ArrayToVector(RequireKey(j, key, "gaussian process"), key);
}

// Rules of a GP file's numbers: wide enough for any fit of whirl's tables, narrow enough that
// no prediction overflows (every value a fit writes is checked against them before it is saved).
constexpr Range kShiftRange{-1e7, 1e7, false, "", "a mean of transformed inputs or outputs"};
constexpr Range kScaleRange{0, 1e7, true, "", "an sd of transformed inputs or outputs"};
constexpr Range kThetaRange{-30, 30, false, "",
                            "the natural log of a length scale or sd, standardized units"};
constexpr Range kNoiseRange{0, 1e4, false, "",
                            "standardized target units: at most 100 times the training sd"};
constexpr Range kMinNoiseRange{1e-12, 1, false, "", "standardized target units"};
constexpr Range kStandardizedRange{-1e6, 1e6, false, "", "standardized units"};

void CheckEach(const Eigen::VectorXd& v, const Range& range, const std::string& key) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    CheckRange(v(i), range, key + "[" + std::to_string(i) + "]", "gaussian process");
}

}  // namespace

std::string ToString(Kernel k) {
  return k == Kernel::kSquaredExponential ? "squared_exponential" : "matern52";
}
std::string ToString(Mean m) { return m == Mean::kConstant ? "constant" : "linear"; }
Kernel ParseKernel(const std::string& s) {
  if (s == "squared_exponential") return Kernel::kSquaredExponential;
  if (s == "matern52") return Kernel::kMatern52;
  throw InputError("gaussian process kernel '" + s + "': must be squared_exponential or matern52");
}
Mean ParseMean(const std::string& s) {
  if (s == "constant") return Mean::kConstant;
  if (s == "linear") return Mean::kLinear;
  throw InputError("gaussian process mean '" + s + "': must be constant or linear");
}

void GpOptions::Validate() const {
  if (single_start_rows < 0)
    throw InputError("gaussian process single_start_rows " + std::to_string(single_start_rows) +
                     ": must be >= 0");
  if (restarts < 1 || restarts > kStartCount)
    throw InputError("gaussian process restarts " + std::to_string(restarts) + ": must be in 1.." +
                     std::to_string(kStartCount));
  if (!(length_prior_sd >= 0) || !std::isfinite(length_prior_sd))
    throw InputError("gaussian process length_prior_sd " + MessageNumber(length_prior_sd) +
                     ": must be finite and >= 0");
  if (!(min_noise_variance > 0) || !std::isfinite(min_noise_variance))
    throw InputError("gaussian process min_noise_variance " + MessageNumber(min_noise_variance) +
                     ": must be a finite number > 0");
  if (max_rows < 0 || hyperparameter_rows < 0 || (max_rows > 0 && max_rows < 8) ||
      (hyperparameter_rows > 0 && hyperparameter_rows < 8))
    throw InputError("gaussian process max_rows " + std::to_string(max_rows) +
                     " and hyperparameter_rows " + std::to_string(hyperparameter_rows) +
                     ": each must be 0 (all rows) or at least 8");
}

double LengthPriorMean(int d) {
  return std::sqrt(2.0) + 0.5 * std::log(static_cast<double>(d)) + 0.5 * std::log(12.0);
}

int MeanSize(Mean mean, int inputs) { return mean == Mean::kConstant ? 1 : 1 + inputs; }

double NegLogMarginalLikelihood(Kernel kernel, Mean mean, const Eigen::MatrixXd& z,
                                const Eigen::VectorXd& u, const Eigen::VectorXd& theta,
                                double min_noise_variance, Eigen::VectorXd* gradient) {
  Factors f;
  return Nlml(kernel, mean, z, u, theta, min_noise_variance, gradient, &f);
}

double Gp::SigmaN2() const { return std::exp(2.0 * theta(InputCount() + 1)) + min_noise_variance; }

void Gp::Factorize() {
  Factors f;
  if (!Factor(kernel, mean, z, u, theta, SigmaN2(), false, &f))
    throw InputError("gaussian process: the covariance matrix is not positive definite");
  chol = f.chol;
  a_chol = f.a_chol;
  k_inv_h = f.k_inv_h;
  b = f.b;
  alpha = f.alpha;
}

std::string GpSummary::BriefReport() const {
  std::string starts;
  for (double v : start_nlml) starts += (starts.empty() ? "" : ", ") + MessageNumber(v);
  return "gp: nlml " + MessageNumber(nlml) + " (starts " + starts + "); " + optimizer.BriefReport();
}

Gp FitGp(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& options,
         GpSummary* summary) {
  return FitFromStarts(x, y, options, {}, summary);  // StartPoints
}

Gp FitGpFrom(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& options,
             const Eigen::VectorXd& theta_start, GpSummary* summary) {
  if (theta_start.size() != x.rows() + 2)
    throw InputError("gaussian process: a warm start needs " + std::to_string(x.rows() + 2) +
                     " hyperparameters, got " + std::to_string(theta_start.size()));
  return FitFromStarts(x, y, options, {theta_start}, summary);
}

Eigen::VectorXd GpPrediction::Stddev() const {
  return (latent_variance.array() + noise_variance).sqrt().matrix();
}

GpPrediction PredictGp(const Gp& gp, const Eigen::MatrixXd& x) {
  const int d = gp.InputCount();
  if (x.rows() != d)
    throw InputError("gaussian process: predictions need " + std::to_string(d) + " inputs, got " +
                     std::to_string(x.rows()));
  const Eigen::MatrixXd zs =
      gp.input_scale.cwiseInverse().asDiagonal() * (x.colwise() - gp.input_shift);
  const Eigen::VectorXd length = gp.theta.head(d).array().exp();
  const double sf2 = std::exp(2.0 * gp.theta(d));
  Eigen::MatrixXd ks;
  KernelMatrices(gp.kernel, gp.z, zs, length, sf2, &ks, nullptr);  // n x q
  const Eigen::MatrixXd hs = Basis(gp.mean, zs);                   // q x m
  GpPrediction p;
  p.mean = (hs * gp.b + ks.transpose() * gp.alpha).array() * gp.target_scale + gp.target_shift;
  const Eigen::MatrixXd v = gp.chol.matrixL().solve(ks);
  const Eigen::MatrixXd r = hs.transpose() - gp.k_inv_h.transpose() * ks;  // m x q
  const Eigen::MatrixXd ar = gp.a_chol.matrixL().solve(r);
  const Eigen::ArrayXd latent =
      (sf2 - v.colwise().squaredNorm().array() + ar.colwise().squaredNorm().array()).max(0.0);
  p.latent_variance = (latent * gp.target_scale * gp.target_scale).matrix();
  p.noise_variance = gp.noise_variance * gp.target_scale * gp.target_scale;
  return p;
}

Eigen::MatrixXd PosteriorCovariance(const Gp& gp, const Eigen::MatrixXd& x) {
  const int d = gp.InputCount();
  if (x.rows() != d)
    throw InputError("gaussian process: covariances need " + std::to_string(d) +
                     " inputs, got " + std::to_string(x.rows()));
  const Eigen::MatrixXd zs =
      gp.input_scale.cwiseInverse().asDiagonal() * (x.colwise() - gp.input_shift);
  const Eigen::VectorXd length = gp.theta.head(d).array().exp();
  const double sf2 = std::exp(2.0 * gp.theta(d));
  Eigen::MatrixXd ks, kss;
  KernelMatrices(gp.kernel, gp.z, zs, length, sf2, &ks, nullptr);  // n x q
  KernelMatrices(gp.kernel, zs, zs, length, sf2, &kss, nullptr);   // q x q
  const Eigen::MatrixXd v = gp.chol.matrixL().solve(ks);
  const Eigen::MatrixXd r = Basis(gp.mean, zs).transpose() - gp.k_inv_h.transpose() * ks;
  const Eigen::MatrixXd ar = gp.a_chol.matrixL().solve(r);
  const Eigen::MatrixXd c = kss - v.transpose() * v + ar.transpose() * ar;
  return c * (gp.target_scale * gp.target_scale);
}

// The diagonal of P = K^-1 - K^-1 H (H' K^-1 H)^-1 H' K^-1 (the header's leave-one-out comment).
Eigen::ArrayXd ProjectionDiagonal(const Gp& gp) {
  const Eigen::MatrixXd k_inv = InverseFromCholesky(gp.chol);
  const Eigen::MatrixXd ah = gp.a_chol.matrixL().solve(gp.k_inv_h.transpose());  // m x n
  return k_inv.diagonal().array() - ah.colwise().squaredNorm().transpose().array();
}

double EffectiveDegreesOfFreedom(const Gp& gp) {
  return static_cast<double>(gp.u.size()) - gp.SigmaN2() * ProjectionDiagonal(gp).sum();
}

double LogMarginalLikelihood(const Gp& gp) {
  const Eigen::VectorXd r = gp.u - Basis(gp.mean, gp.z) * gp.b;
  const double log_det_half = gp.chol.matrixLLT().diagonal().array().log().sum();
  return -(0.5 * r.dot(gp.alpha) + log_det_half +
           0.5 * static_cast<double>(gp.u.size()) * std::log(2.0 * kPi));
}

LeaveOneOut LeaveOneOutGp(const Gp& gp) {
  const Eigen::ArrayXd p_diag = ProjectionDiagonal(gp);
  LeaveOneOut loo;
  loo.residual = (gp.alpha.array() / p_diag * gp.target_scale).matrix();
  loo.latent_variance =
      ((1.0 / p_diag - gp.SigmaN2()).max(0.0) * gp.target_scale * gp.target_scale).matrix();
  return loo;
}

void to_json(nlohmann::json& j, const Gp& gp) {
  auto vec = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index q = 0; q < gp.z.cols(); ++q) rows.push_back(vec(gp.z.col(q)));
  j = {{"kernel", ToString(gp.kernel)},
       {"mean", ToString(gp.mean)},
       {"input_shift", vec(gp.input_shift)},
       {"input_scale", vec(gp.input_scale)},
       {"target_shift", gp.target_shift},
       {"target_scale", gp.target_scale},
       {"theta", vec(gp.theta)},
       {"min_noise_variance", gp.min_noise_variance},
       {"noise_variance", gp.noise_variance},
       {"inputs_standardized", rows},
       {"targets_standardized", vec(gp.u)}};
}

void from_json(const nlohmann::json& j, Gp& gp) {
  const std::string what = "gaussian process";
  if (!j.is_object()) throw InputError(what + ": must be a JSON object");
  if (!j.contains("kernel") || !j.at("kernel").is_string() || !j.contains("mean") ||
      !j.at("mean").is_string())
    throw InputError(what + ": 'kernel' and 'mean' must be strings");
  gp.kernel = ParseKernel(j.at("kernel").get<std::string>());
  gp.mean = ParseMean(j.at("mean").get<std::string>());
  gp.input_shift = JsonVector(j, "input_shift");
  gp.input_scale = JsonVector(j, "input_scale");
  gp.theta = JsonVector(j, "theta");
  gp.u = JsonVector(j, "targets_standardized");
  gp.target_shift = RequireNumber(j, "target_shift", what);
  gp.target_scale = RequireNumber(j, "target_scale", what);
  gp.min_noise_variance = RequireNumber(j, "min_noise_variance", what);
  gp.noise_variance = RequireNumber(j, "noise_variance", what);
  const auto d = gp.input_shift.size();
  if (gp.input_scale.size() != d || gp.theta.size() != d + 2 || d == 0)
    throw InputError(what + ": 'input_scale' (one per input) and 'theta' (inputs + 2) must match "
                            "'input_shift' (at least one input)");
  CheckEach(gp.input_shift, kShiftRange, "input_shift");
  CheckEach(gp.input_scale, kScaleRange, "input_scale");
  CheckEach(gp.theta, kThetaRange, "theta");
  CheckEach(gp.u, kStandardizedRange, "targets_standardized");
  CheckRange(gp.target_shift, kShiftRange, "target_shift", what);
  CheckRange(gp.target_scale, kScaleRange, "target_scale", what);
  CheckRange(gp.min_noise_variance, kMinNoiseRange, "min_noise_variance", what);
  CheckRange(gp.noise_variance, kNoiseRange, "noise_variance", what);
  if (!j.contains("inputs_standardized") || !j.at("inputs_standardized").is_array() ||
      j.at("inputs_standardized").size() != static_cast<std::size_t>(gp.u.size()))
    throw InputError(what + ": 'inputs_standardized' must hold one row per target");
  gp.z.resize(d, gp.u.size());
  for (Eigen::Index q = 0; q < gp.u.size(); ++q) {
    const std::string name = "inputs_standardized[" + std::to_string(q) + "]";
    const Eigen::VectorXd row = ArrayToVector(j.at("inputs_standardized")[q], name);
    if (row.size() != d) throw InputError(what + ": '" + name + "' must hold one value per input");
    CheckEach(row, kStandardizedRange, name);
    gp.z.col(q) = row;
  }
  gp.Factorize();
}

}  // namespace whirl::gp
