// gravcal: the GGIR auto-calibration fit (van Hees et al. 2014), iterative
// closest point with weights and a temperature term.
//
// Model, per axis k:  a_k = (v_k + offset_k) * scale_k + t * tempoffset_k,
// t = temperature - mean temperature of the fitted windows.
//
// One iteration: project the current calibrated points onto the unit sphere
// (their closest points); per axis, weighted least squares of the closest
// point on [1, current value, t]; compose the small correction into offset,
// scale and tempoffset; new weights min(1 / |residual|, max_weight).
//
// Stopping. GGIR stops when its statistic
//   res = sum_i w_i |a_i - p_i|^2 / (n * sum_i w_i)
// changes by less than `tol` (1e-10) between iterations. The statistic is
// divided by the sum of the weights, so it is tiny and this rule usually
// fires after 5-10 iterations, well before the parameters have settled
// (GGIR-compatible mode, StopRule::ggir). gravcal's own rule
// (StopRule::parameters) stops when no parameter moves by more than `tol`
// (tempoffset measured over the temperature range), which is convergence.
//
// The arithmetic follows GGIR's R code where that decides a bit: the
// calibrated value is (v + o) / (1 / s) + t / (1 / to), as R's scale()
// computes it. The per-axis least squares use a Householder QR of the
// weighted design (R's lm.wfit uses a Householder QR too). With
// IcpConfig::r_arithmetic every other step is done as GGIR's R code does it
// too (row sums and means in long double, fitted values from the weighted
// residuals, the statistic element by element), so that a solver computing
// what R's lm.wfit computes (the caller may pass one: the R glue passes R's
// own LINPACK routine) gives GGIR's coefficients to the last bit.
//
// Uses Eigen (header-only); no R.
#ifndef GRAVCAL_ICP_HPP
#define GRAVCAL_ICP_HPP

#include <Eigen/Dense>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "model.hpp"
#include "r_arith.hpp"

namespace gravcal {

enum class StopRule { ggir, parameters };

struct IcpConfig {
  int max_iter = 1000;        // GGIR: 1000
  double tol = 1e-10;         // GGIR: 1e-10
  double max_weight = 100.0;  // GGIR: 1 / 0.01
  bool use_temp = true;
  StopRule stop = StopRule::ggir;
  bool r_arithmetic = false;  // GGIR's R arithmetic, step by step (above)
};

struct IcpResult {
  double offset[3] = {0.0, 0.0, 0.0};
  double scale[3] = {1.0, 1.0, 1.0};
  double tempoffset[3] = {0.0, 0.0, 0.0};
  double meantemp = 0.0;
  int iterations = 0;
  bool converged = false;
  bool finite = true;
  bool temp_used = false;  // false when asked but the temperature of the
                           // points does not vary (rank deficient)
  double statistic = 0.0;  // last value of GGIR's res
};

// Whether an iteration's statistic and coefficients are all finite.
inline bool icp_finite(const IcpResult& r, double res) {
  bool finite = std::isfinite(res);
  for (int k = 0; k < 3; ++k) {
    finite = finite && std::isfinite(r.offset[k]) && std::isfinite(r.scale[k]) &&
             std::isfinite(r.tempoffset[k]);
  }
  return finite;
}

// Weighted least squares by Householder QR. X: n x p, column-major, rows
// already multiplied by sqrt(weight); y likewise. Writes the p coefficients
// (NaN for a column that adds nothing, as R gives NA) and the weighted
// residuals y - X coef. May overwrite X.
struct EigenLeastSquares {
  void operator()(double* X, const double* y, std::size_t n, int p,
                  double* coef, double* rsd) const {
    const Eigen::Index N = static_cast<Eigen::Index>(n);
    Eigen::Map<Eigen::MatrixXd> A(X, N, p);
    Eigen::Map<const Eigen::VectorXd> b(y, N);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    qr.setThreshold(1e-7);
    Eigen::VectorXd beta = qr.solve(b);
    Eigen::Map<Eigen::VectorXd> r(rsd, N);
    r = b - A * beta;
    const Eigen::Index rank = qr.rank();
    for (int j = 0; j < p; ++j) coef[j] = beta(j);
    // columns beyond the rank, in pivot order, are aliased
    for (Eigen::Index j = rank; j < p; ++j) {
      coef[qr.colsPermutation().indices()(j)] =
          std::numeric_limits<double>::quiet_NaN();
    }
  }
};

// The loops of gravcal's own fit (fit_icp()), element by element. (SSE2
// versions saved less than 5 % of a week's calibrate(method = "ggir"):
// bench/results/ab-kernels.md.)

// out[i] = apply_model_ggir(v[i], o, s, t ? t[i] : 0, to)
inline void icp_apply_column(const double* v, const double* t, std::size_t n, double o, double s,
                             double to, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = apply_model_ggir(v[i], o, s, t != nullptr ? t[i] : 0.0, to);
}

// p = c / |c|, |c| = sqrt(c0^2 + c1^2 + c2^2)
inline void icp_project(const double* c0, const double* c1, const double* c2, std::size_t n,
                        double* p0, double* p1, double* p2) {
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::sqrt(c0[i] * c0[i] + c1[i] * c1[i] + c2[i] * c2[i]);
    p0[i] = c0[i] / r;
    p1[i] = c1[i] / r;
    p2[i] = c2[i] / r;
  }
}

// c = b0 + b1 c (+ b2 t when t is not null)
inline void icp_fitted(double b0, double b1, double b2, const double* t, std::size_t n,
                       double* c) {
  for (std::size_t i = 0; i < n; ++i) {
    double f = b0 + b1 * c[i];
    if (t != nullptr) f += b2 * t[i];
    c[i] = f;
  }
}

// d2 = |c - p|^2; wd2 = w d2 (GGIR's statistic); next = min(1 / sqrt(d2),
// max_weight)
inline void icp_weights(const double* c0, const double* c1, const double* c2, const double* p0,
                        const double* p1, const double* p2, std::size_t n, double max_weight,
                        const double* w, double* next, double* wd2) {
  for (std::size_t i = 0; i < n; ++i) {
    const double a = c0[i] - p0[i], b = c1[i] - p1[i], c = c2[i] - p2[i];
    const double d2 = a * a + b * b + c * c;
    wd2[i] = w[i] * d2;
    const double wi = 1.0 / std::sqrt(d2);
    next[i] = wi < max_weight ? wi : max_weight;
  }
}

// GGIR's loop with R's arithmetic (IcpConfig::r_arithmetic). As GGIR: the
// design always has the temperature column (zeros without temperature), a
// temperature that does not vary gives NA coefficients (reported as not
// finite), the statistic is 3 * mean(w * (a - p)^2 / sum(w)) over all 3n
// elements, the weights min(1 / sqrt(rowSums((a - p)^2)), max_weight).
template <class Observer, class Solver>
IcpResult fit_icp_r(const double* x, const double* y, const double* z,
                    const double* temp, std::size_t n, const IcpConfig& cfg,
                    Observer& obs, const Solver& solve) {
  IcpResult r;
  if (n < 3) {
    r.finite = false;
    return r;
  }
  const double* in[3] = {x, y, z};
  const bool use_temp = cfg.use_temp && temp != nullptr;
  std::vector<double> t(n, 0.0);
  if (use_temp) {
    r.meantemp = r_mean(temp, n);
    for (std::size_t i = 0; i < n; ++i) t[i] = temp[i] - r.meantemp;
    r.temp_used = true;
  }
  std::vector<double> cur(3 * n), cp(3 * n), w(n, 1.0), sw(n), X(3 * n), yw(n),
      rsd(n), e(3 * n);
  double res_prev = std::numeric_limits<double>::infinity();
  for (int it = 1; it <= cfg.max_iter; ++it) {
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        cur[k * n + i] = apply_model_ggir(in[k][i], r.offset[k], r.scale[k], t[i],
                                          r.tempoffset[k]);
      }
    }
    // closest points: curr / sqrt(rowSums(curr^2))
    for (std::size_t i = 0; i < n; ++i) {
      long double ss = 0.0L;
      for (int k = 0; k < 3; ++k) {
        const double c = cur[k * n + i];
        ss += c * c;
      }
      const double nrm = std::sqrt(static_cast<double>(ss));
      for (int k = 0; k < 3; ++k) cp[k * n + i] = cur[k * n + i] / nrm;
    }
    for (std::size_t i = 0; i < n; ++i) sw[i] = std::sqrt(w[i]);
    double d_off[3], d_scale[3], d_temp[3] = {0.0, 0.0, 0.0};
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        X[i] = 1.0 * sw[i];
        X[n + i] = cur[k * n + i] * sw[i];
        X[2 * n + i] = t[i] * sw[i];
        yw[i] = cp[k * n + i] * sw[i];
        finite = finite && std::isfinite(X[n + i]) && std::isfinite(yw[i]);
      }
      if (!finite) break;
      double coef[3];
      solve(X.data(), yw.data(), n, 3, coef, rsd.data());
      d_off[k] = coef[0];
      d_scale[k] = coef[1];
      if (use_temp) d_temp[k] = coef[2];
      for (std::size_t i = 0; i < n; ++i) {
        cur[k * n + i] = cp[k * n + i] - rsd[i] / sw[i];
      }
    }
    if (!finite) {
      r.finite = false;
      break;
    }
    for (int k = 0; k < 3; ++k) {
      r.offset[k] = r.offset[k] + d_off[k] / (r.scale[k] * d_scale[k]);
      if (use_temp) r.tempoffset[k] = r.tempoffset[k] * d_scale[k] + d_temp[k];
      r.scale[k] = r.scale[k] * d_scale[k];
    }
    long double wsum_l = 0.0L;
    for (std::size_t i = 0; i < n; ++i) wsum_l += w[i];
    const double wsum = static_cast<double>(wsum_l);
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const double d = cur[k * n + i] - cp[k * n + i];
        e[k * n + i] = w[i] * (d * d) / wsum;
      }
    }
    const double res = 3.0 * r_mean(e.data(), 3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      long double ss = 0.0L;
      for (int k = 0; k < 3; ++k) {
        const double d = cur[k * n + i] - cp[k * n + i];
        ss += d * d;
      }
      const double wi = 1.0 / std::sqrt(static_cast<double>(ss));
      w[i] = wi < cfg.max_weight ? wi : cfg.max_weight;
    }
    r.iterations = it;
    r.statistic = res;
    obs(it, static_cast<const IcpResult&>(r));
    finite = icp_finite(r, res);
    if (!finite) {
      r.finite = false;
      break;
    }
    if (std::fabs(res - res_prev) < cfg.tol) {
      r.converged = true;
      break;
    }
    res_prev = res;
  }
  return r;
}

// x, y, z: the n window means; temp: their temperatures (may be null, or
// ignored when cfg.use_temp is false). Observer is called after each
// iteration as obs(iteration, result-so-far). obs may throw to abandon the
// fit (the R glue does on Ctrl-C); the Eigen matrices the fit allocated are
// freed by their destructors on the way out.
template <class Observer, class Solver = EigenLeastSquares>
IcpResult fit_icp(const double* x, const double* y, const double* z,
                  const double* temp, std::size_t n, const IcpConfig& cfg,
                  Observer&& obs, const Solver& solve = Solver()) {
  IcpResult r;
  if (cfg.r_arithmetic) return fit_icp_r(x, y, z, temp, n, cfg, obs, solve);
  if (n < 3) {
    r.finite = false;
    return r;
  }
  const double* in[3] = {x, y, z};
  std::vector<double> t(n, 0.0);
  bool use_temp = cfg.use_temp && temp != nullptr;
  if (use_temp) {
    r.meantemp = r_mean(temp, n);
    for (std::size_t i = 0; i < n; ++i) t[i] = temp[i] - r.meantemp;
    double tmin = t[0], tmax = t[0];
    for (std::size_t i = 1; i < n; ++i) {
      if (t[i] < tmin) tmin = t[i];
      if (t[i] > tmax) tmax = t[i];
    }
    if (!(tmax > tmin)) use_temp = false;  // constant: no temperature term
    r.temp_used = use_temp;
  }
  double trange = 0.0;
  if (use_temp) {
    double tmin = t[0], tmax = t[0];
    for (std::size_t i = 1; i < n; ++i) {
      if (t[i] < tmin) tmin = t[i];
      if (t[i] > tmax) tmax = t[i];
    }
    trange = tmax - tmin;
  }

  const Eigen::Index N = static_cast<Eigen::Index>(n);
  const int ncol = use_temp ? 3 : 2;
  Eigen::MatrixXd cur(N, 3), cp(N, 3);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(N);
  Eigen::MatrixXd X(N, ncol);
  Eigen::VectorXd b(N), sw(N);
  // one QR for all the fits: compute() reuses its storage (the same
  // arithmetic as a new X.householderQr() each time)
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(N, ncol);
  double res_prev = std::numeric_limits<double>::infinity();

  std::vector<double> wd2(n);  // w * d^2 of each point, for GGIR's statistic
  Eigen::VectorXd w_next(N);   // the weights of the next iteration
  const double* tp = use_temp ? t.data() : nullptr;
  for (int it = 1; it <= cfg.max_iter; ++it) {
    // the calibrated points (apply_model_ggir()), then their closest points
    // on the sphere; column by column
    for (int k = 0; k < 3; ++k) {
      icp_apply_column(in[k], tp, n, r.offset[k], r.scale[k],
                       use_temp ? r.tempoffset[k] : 0.0, cur.col(k).data());
    }
    icp_project(cur.col(0).data(), cur.col(1).data(), cur.col(2).data(), n,
                cp.col(0).data(), cp.col(1).data(), cp.col(2).data());
    if (!cp.allFinite()) {
      r.finite = false;
      break;
    }
    sw = w.cwiseSqrt();
    double d_off[3], d_scale[3], d_temp[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
      X.col(0) = sw;
      X.col(1) = sw.cwiseProduct(cur.col(k));
      if (use_temp) X.col(2) = sw.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(tp, N));
      b = sw.cwiseProduct(cp.col(k));
      qr.compute(X);
      const Eigen::VectorXd beta = qr.solve(b);
      d_off[k] = beta(0);
      d_scale[k] = beta(1);
      if (use_temp) d_temp[k] = beta(2);
      icp_fitted(beta(0), beta(1), use_temp ? beta(2) : 0.0, tp, n, cur.col(k).data());
    }
    double change = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double o_new = r.offset[k] + d_off[k] / (r.scale[k] * d_scale[k]);
      const double s_new = r.scale[k] * d_scale[k];
      const double t_new = use_temp ? r.tempoffset[k] * d_scale[k] + d_temp[k] : 0.0;
      change = std::fmax(change, std::fabs(o_new - r.offset[k]));
      change = std::fmax(change, std::fabs(s_new - r.scale[k]));
      change = std::fmax(change, std::fabs(t_new - r.tempoffset[k]) * trange);
      r.offset[k] = o_new;
      r.scale[k] = s_new;
      r.tempoffset[k] = t_new;
    }
    // GGIR's statistic, with the weights of this iteration; then new weights.
    icp_weights(cur.col(0).data(), cur.col(1).data(), cur.col(2).data(),
                cp.col(0).data(), cp.col(1).data(), cp.col(2).data(), n,
                cfg.max_weight, w.data(), w_next.data(), wd2.data());
    long double num = 0.0L, wsum = 0.0L;
    for (std::size_t i = 0; i < n; ++i) {  // two chains of long double sums
      wsum += w(static_cast<Eigen::Index>(i));
      num += wd2[i];
    }
    w.swap(w_next);
    const double res = static_cast<double>(num / (static_cast<long double>(n) * wsum));
    r.iterations = it;
    r.statistic = res;
    obs(it, static_cast<const IcpResult&>(r));
    const bool finite = icp_finite(r, res);
    if (!finite) {
      r.finite = false;
      break;
    }
    if (cfg.stop == StopRule::ggir) {
      if (std::fabs(res - res_prev) < cfg.tol) {
        r.converged = true;
        break;
      }
    } else if (change < cfg.tol) {
      r.converged = true;
      break;
    }
    res_prev = res;
  }
  return r;
}

inline IcpResult fit_icp(const double* x, const double* y, const double* z,
                         const double* temp, std::size_t n, const IcpConfig& cfg) {
  return fit_icp(x, y, z, temp, n, cfg, [](int, const IcpResult&) {});
}

}  // namespace gravcal

#endif  // GRAVCAL_ICP_HPP
