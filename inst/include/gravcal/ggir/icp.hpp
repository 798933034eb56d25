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
// computes it. gravcal's own fit solves each axis's weighted least squares
// from its normal equations (below); with
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
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "gravcal/mcu/model.hpp"
#include "gravcal/host/r_arith.hpp"

namespace gravcal {

enum class StopRule { ggir, parameters };

struct IcpConfig {
  int max_iter = 1000;        // GGIR: 1000
  double tol = 1e-10;         // GGIR: 1e-10
  double max_weight = 100.0;  // GGIR: 1 / 0.01
  bool use_temp = true;
  StopRule stop = StopRule::ggir;
  bool r_arithmetic = false;  // GGIR's R arithmetic, step by step (above)
  bool r_long_double = true;  // ... with R's accumulator long double (R's
                              // default), else double (R without long double)
  // gravcal's own fit only: start from these coefficients (a fit on part of
  // the same windows, whose temperature was centred on start_meantemp)
  // rather than from the identity
  bool warm = false;
  double start_offset[3] = {0.0, 0.0, 0.0};
  double start_scale[3] = {1.0, 1.0, 1.0};
  double start_tempoffset[3] = {0.0, 0.0, 0.0};
  double start_meantemp = 0.0;
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

// gravcal's own fit streams through the points twice per iteration and
// keeps no per-point matrices: each axis's weighted least squares of the
// closest point p on [1, c, t] is solved from its normal equations, whose
// sums one pass gathers (IcpSums), and a second pass computes GGIR's
// statistic and the next weights. Its memory traffic is five columns per
// pass whatever the number of points, so its time per iteration grows
// linearly (a Householder QR of each axis's n x 3 design made some ten
// passes over 14 columns, and slowed down per point once those left the
// cache). The columns are centred (t on the mean temperature, c near the
// unit sphere), so the 3 x 3 equations are well conditioned.

// Sums are gathered per block of points and the block sums added, so that
// rounding grows with the block length and the number of blocks, not n.
constexpr std::size_t kIcpBlock = 1024;

// The sums of one axis: w, w c, w t, w c c, w c t, w t t, w p, w c p, w t p.
struct IcpSums {
  double s[3][9] = {};
  // one point: weight wi, current point c, closest point p, temperature ti
  void add_point(double wi, const double* c, const double* p, double ti) {
    for (int k = 0; k < 3; ++k) {
      double* a = s[k];
      const double wc = wi * c[k], wt = wi * ti;
      a[0] += wi;
      a[1] += wc;
      a[2] += wt;
      a[3] += wc * c[k];
      a[4] += wc * ti;
      a[5] += wt * ti;
      a[6] += wi * p[k];
      a[7] += wc * p[k];
      a[8] += wt * p[k];
    }
  }
  void add(const IcpSums& o) {
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 9; ++j) s[k][j] += o.s[k][j];
  }
};

// The current calibrated point c and its closest point p on the sphere.
inline void icp_point(const double* const* in, const double* t, std::size_t i,
                      const double* o, const double* s, const double* to, double* c,
                      double* p) {
  const double ti = t != nullptr ? t[i] : 0.0;
  for (int k = 0; k < 3; ++k) c[k] = apply_model_ggir(in[k][i], o[k], s[k], ti, t != nullptr ? to[k] : 0.0);
  const double r = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  for (int k = 0; k < 3; ++k) p[k] = c[k] / r;
}

// Pass 1: the normal equations' sums at the parameters (o, s, to), with
// weights w; false when a closest point is not finite.
inline bool icp_sums(const double* const* in, const double* t, std::size_t n, const double* o,
                     const double* s, const double* to, const double* w, IcpSums& sums) {
  bool finite = true;
  for (std::size_t b = 0; b < n; b += kIcpBlock) {
    const std::size_t e = std::min(n, b + kIcpBlock);
    IcpSums blk;
    for (std::size_t i = b; i < e; ++i) {
      double c[3], p[3];
      icp_point(in, t, i, o, s, to, c, p);
      finite = finite && std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
      const double wi = w[i], ti = t != nullptr ? t[i] : 0.0;
      blk.add_point(wi, c, p, ti);
    }
    sums.add(blk);
  }
  return finite;
}

// Solves one axis's normal equations for ncol (2 or 3) coefficients; false
// when they do not determine them.
inline bool icp_solve(const double* a, int ncol, double* beta) {
  Eigen::Matrix3d M;
  Eigen::Vector3d v;
  M << a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5];
  v << a[6], a[7], a[8];
  const Eigen::Index m = ncol;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(M.topLeftCorner(m, m));
  if (qr.rank() < m) return false;
  const Eigen::VectorXd x = qr.solve(Eigen::VectorXd(v.head(m)));
  beta[0] = x(0);
  beta[1] = x(1);
  beta[2] = m == 3 ? x(2) : 0.0;
  return std::isfinite(beta[0]) && std::isfinite(beta[1]) && std::isfinite(beta[2]);
}

// Pass 2: at the same parameters, the fitted values f = b0 + b1 c + b2 t of
// each axis against the closest points: GGIR's statistic's sums (w |f - p|^2
// and w) and, in place, the next weights min(1 / |f - p|, max_weight).
inline void icp_reweight(const double* const* in, const double* t, std::size_t n,
                         const double* o, const double* s, const double* to,
                         const double (*beta)[3], double max_weight, double* w, double& num,
                         double& wsum) {
  num = 0.0;
  wsum = 0.0;
  for (std::size_t b = 0; b < n; b += kIcpBlock) {
    const std::size_t e = std::min(n, b + kIcpBlock);
    double bn = 0.0, bw = 0.0;
    for (std::size_t i = b; i < e; ++i) {
      double c[3], p[3];
      icp_point(in, t, i, o, s, to, c, p);
      const double ti = t != nullptr ? t[i] : 0.0;
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = beta[k][0] + beta[k][1] * c[k] + beta[k][2] * ti - p[k];
        d2 += d * d;
      }
      bn += w[i] * d2;
      bw += w[i];
      const double wi = 1.0 / std::sqrt(d2);
      w[i] = wi < max_weight ? wi : max_weight;
    }
    num += bn;
    wsum += bw;
  }
}

// GGIR's loop with R's arithmetic (IcpConfig::r_arithmetic). As GGIR: the
// design always has the temperature column (zeros without temperature), a
// temperature that does not vary gives NA coefficients (reported as not
// finite), the statistic is 3 * mean(w * (a - p)^2 / sum(w)) over all 3n
// elements, the weights min(1 / sqrt(rowSums((a - p)^2)), max_weight).
// Acc: R's accumulator (IcpConfig::r_long_double).
template <class Acc, class Observer, class Solver>
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
    r.meantemp = r_mean<Acc>(temp, n);
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
      Acc ss = 0.0;
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
    Acc wsum_l = 0.0;
    for (std::size_t i = 0; i < n; ++i) wsum_l += w[i];
    const double wsum = static_cast<double>(wsum_l);
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const double d = cur[k * n + i] - cp[k * n + i];
        e[k * n + i] = w[i] * (d * d) / wsum;
      }
    }
    const double res = 3.0 * r_mean<Acc>(e.data(), 3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      Acc ss = 0.0;
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
// gravcal's converged fit (StopRule::parameters). GGIR's iteration weighs
// each point by min(1 / |f - p|, max_weight), f its fitted value and p the
// closest point of the iteration before; at a fixed point f = c and
// |c - p| = | |c| - 1 |, so its fixed points are the coefficients where
//   sum_i psi(|c_i| - 1) d|c_i| / d(coefficients) = 0,
// psi(d) = min(1 / |d|, max_weight) d: the stationary points of
//   sum_i rho(|c_i| - 1), rho(d) = max_weight d^2 / 2 for |d| < 1 / max_weight,
//   |d| - 1 / (2 max_weight) beyond
// (Huber's loss, of the distance to the sphere). The map F below takes the
// weights at the current coefficients instead (iteratively reweighted least
// squares for that loss: each step lowers it), which has the same fixed
// points, and is accelerated by SQUAREM (Varadhan & Roland 2008, scheme S3)
// with rho as its merit: a fixed point reached in tens of passes over the
// windows where the plain iteration needs hundreds, so that the time of a
// fit does not depend on how slowly the plain iteration would have
// converged on a recording the model does not fit well.
struct IcpCoefs {
  double o[3] = {0.0, 0.0, 0.0}, s[3] = {1.0, 1.0, 1.0}, to[3] = {0.0, 0.0, 0.0};
};

// F(a) -> b, with the merit rho at a; false when not finite.
inline bool icp_map(const double* const* in, const double* t, std::size_t n, int ncol,
                    double max_weight, const IcpCoefs& a, IcpCoefs& b, double& merit) {
  IcpSums sums;
  const double half = 0.5 / max_weight;
  merit = 0.0;
  bool finite = true;
  for (std::size_t b0 = 0; b0 < n; b0 += kIcpBlock) {
    const std::size_t e = std::min(n, b0 + kIcpBlock);
    IcpSums blk;
    double bm = 0.0;
    for (std::size_t i = b0; i < e; ++i) {
      double c[3], p[3];
      icp_point(in, t, i, a.o, a.s, a.to, c, p);
      const double r = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      const double d = std::fabs(r - 1.0);
      const double wi = d * max_weight > 1.0 ? 1.0 / d : max_weight;
      bm += d * max_weight > 1.0 ? d - half : 0.5 * max_weight * d * d;
      finite = finite && std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
      const double ti = t != nullptr ? t[i] : 0.0;
      blk.add_point(wi, c, p, ti);
    }
    sums.add(blk);
    merit += bm;
  }
  if (!finite || !std::isfinite(merit)) return false;
  for (int k = 0; k < 3; ++k) {
    double beta[3];
    if (!icp_solve(sums.s[k], ncol, beta)) return false;
    b.o[k] = a.o[k] + beta[0] / (a.s[k] * beta[1]);
    b.s[k] = a.s[k] * beta[1];
    b.to[k] = t != nullptr ? a.to[k] * beta[1] + beta[2] : 0.0;
  }
  return true;
}

// The coefficients as one vector for SQUAREM, the temperature terms
// measured over the temperature range (as the stopping rule measures them).
inline void icp_vec(const IcpCoefs& a, double trange, double* v) {
  for (int k = 0; k < 3; ++k) {
    v[k] = a.o[k];
    v[3 + k] = a.s[k];
    v[6 + k] = a.to[k] * trange;
  }
}
inline IcpCoefs icp_unvec(const double* v, double trange) {
  IcpCoefs a;
  for (int k = 0; k < 3; ++k) {
    a.o[k] = v[k];
    a.s[k] = v[3 + k];
    a.to[k] = trange > 0 ? v[6 + k] / trange : 0.0;
  }
  return a;
}

// GGIR's statistic at a fixed point: sum w d^2 / (n sum w), d = |c| - 1,
// w = min(1 / |d|, max_weight).
inline double icp_statistic(const double* const* in, const double* t, std::size_t n,
                            double max_weight, const IcpCoefs& a) {
  double num = 0.0, den = 0.0;
  for (std::size_t b0 = 0; b0 < n; b0 += kIcpBlock) {
    const std::size_t e = std::min(n, b0 + kIcpBlock);
    double bn = 0.0, bd = 0.0;
    for (std::size_t i = b0; i < e; ++i) {
      double c[3], p[3];
      icp_point(in, t, i, a.o, a.s, a.to, c, p);
      const double d = std::fabs(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - 1.0);
      const double wi = d * max_weight > 1.0 ? 1.0 / d : max_weight;
      bn += wi * d * d;
      bd += wi;
    }
    num += bn;
    den += bd;
  }
  return num / (static_cast<double>(n) * den);
}

// The converged fit from r's coefficients: SQUAREM on icp_map(); r.iterations
// counts the passes (maps) made.
template <class Observer>
void icp_converge(const double* const* in, const double* t, std::size_t n, int ncol,
                  double trange, const IcpConfig& cfg, Observer& obs, IcpResult& r) {
  auto take = [&](const IcpCoefs& a) {
    for (int k = 0; k < 3; ++k) {
      r.offset[k] = a.o[k];
      r.scale[k] = a.s[k];
      r.tempoffset[k] = a.to[k];
    }
  };
  auto change = [&](const IcpCoefs& a, const IcpCoefs& b) {
    double c = 0.0;
    for (int k = 0; k < 3; ++k) {
      c = std::fmax(c, std::fabs(b.o[k] - a.o[k]));
      c = std::fmax(c, std::fabs(b.s[k] - a.s[k]));
      c = std::fmax(c, std::fabs(b.to[k] - a.to[k]) * trange);
    }
    return c;
  };
  int evals = 0;
  // one map, reported; false when it is not finite
  auto step = [&](const IcpCoefs& a, IcpCoefs& b, double& merit) {
    if (!icp_map(in, t, n, ncol, cfg.max_weight, a, b, merit)) return false;
    ++evals;
    take(b);
    r.iterations = evals;
    obs(evals, static_cast<const IcpResult&>(r));
    return icp_finite(r, 0.0);
  };
  IcpCoefs x0, x1, x2, x3, xs;
  for (int k = 0; k < 3; ++k) {
    x0.o[k] = r.offset[k];
    x0.s[k] = r.scale[k];
    x0.to[k] = r.tempoffset[k];
  }
  double m0 = 0.0, m1 = 0.0, ms = 0.0;
  // the longest step tried: grows fourfold after a step of that length is
  // kept, shrinks to a quarter of a step that is refused (SQUAREM's
  // adaptive step bound), so that a refused extrapolation is not tried
  // again at the same length
  double step_max = 4.0;
  while (evals < cfg.max_iter) {
    if (!step(x0, x1, m0)) {
      r.finite = false;
      return;
    }
    if (change(x0, x1) < cfg.tol) {
      r.converged = true;
      x0 = x1;
      break;
    }
    if (evals >= cfg.max_iter) {
      x0 = x1;
      break;
    }
    if (!step(x1, x2, m1)) {
      r.finite = false;
      return;
    }
    if (change(x1, x2) < cfg.tol) {
      r.converged = true;
      x0 = x2;
      break;
    }
    // S3's step length, at least the plain two steps (alpha = -1 gives x2)
    double v0[9], v1[9], v2[9], rr = 0.0, vv = 0.0;
    icp_vec(x0, trange, v0);
    icp_vec(x1, trange, v1);
    icp_vec(x2, trange, v2);
    for (int j = 0; j < 9; ++j) {
      const double a = v1[j] - v0[j], b = v2[j] - 2.0 * v1[j] + v0[j];
      rr += a * a;
      vv += b * b;
    }
    const double alpha = vv > 0.0 ? std::fmax(-std::sqrt(rr / vv), -step_max) : -1.0;
    if (!(alpha < -1.0) || evals >= cfg.max_iter) {
      x0 = x2;
      continue;
    }
    double vs[9];
    for (int j = 0; j < 9; ++j) {
      const double a = v1[j] - v0[j], b = v2[j] - 2.0 * v1[j] + v0[j];
      vs[j] = v0[j] - 2.0 * alpha * a + alpha * alpha * b;
    }
    xs = icp_unvec(vs, trange);
    // the extrapolated point is kept, after one more map, only when its
    // loss is no higher than that of x1 (each map lowers it: x2's is lower)
    const int before = evals;
    if (step(xs, x3, ms) && ms <= m1) {
      if (-alpha >= step_max) step_max *= 4.0;
      if (change(xs, x3) < cfg.tol) {
        r.converged = true;
        x0 = x3;
        break;
      }
      x0 = x3;
    } else {
      evals = before + 1;  // the pass was made, its result is not kept
      step_max = std::fmax(1.0, -alpha / 4.0);
      x0 = x2;
    }
  }
  take(x0);
  r.iterations = evals;
  r.statistic = icp_statistic(in, t, n, cfg.max_weight, x0);
}

template <class Observer, class Solver = EigenLeastSquares>
IcpResult fit_icp(const double* x, const double* y, const double* z,
                  const double* temp, std::size_t n, const IcpConfig& cfg,
                  Observer&& obs, const Solver& solve = Solver()) {
  IcpResult r;
  if (cfg.r_arithmetic) {
    return with_r_acc(cfg.r_long_double, [&](auto acc) {
      return fit_icp_r<decltype(acc)>(x, y, z, temp, n, cfg, obs, solve);
    });
  }
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

  const int ncol = use_temp ? 3 : 2;
  if (cfg.warm) {
    // the same mapping with the temperature centred on this table's mean:
    // (v + o') s + (T - m') to = (v + o) s + (T - m) to
    for (int k = 0; k < 3; ++k) {
      r.scale[k] = cfg.start_scale[k];
      r.tempoffset[k] = use_temp ? cfg.start_tempoffset[k] : 0.0;
      r.offset[k] = cfg.start_offset[k] +
                    (use_temp ? (r.meantemp - cfg.start_meantemp) * r.tempoffset[k] / r.scale[k] : 0.0);
    }
  }
  const double* tp = use_temp ? t.data() : nullptr;
  if (cfg.stop == StopRule::parameters) {
    icp_converge(in, tp, n, ncol, trange, cfg, obs, r);
    if (r.finite) r.finite = icp_finite(r, r.statistic);
    return r;
  }
  std::vector<double> w(n, 1.0);
  double res_prev = std::numeric_limits<double>::infinity();
  for (int it = 1; it <= cfg.max_iter; ++it) {
    // the calibrated points (apply_model_ggir()), their closest points on
    // the sphere, and each axis's regression of the one on the other
    const double o_old[3] = {r.offset[0], r.offset[1], r.offset[2]};
    const double s_old[3] = {r.scale[0], r.scale[1], r.scale[2]};
    const double t_old[3] = {r.tempoffset[0], r.tempoffset[1], r.tempoffset[2]};
    IcpSums sums;
    bool finite = icp_sums(in, tp, n, o_old, s_old, t_old, w.data(), sums);
    double beta[3][3];
    for (int k = 0; k < 3 && finite; ++k) finite = icp_solve(sums.s[k], ncol, beta[k]);
    if (!finite) {
      r.finite = false;
      break;
    }
    double d_off[3], d_scale[3], d_temp[3];
    for (int k = 0; k < 3; ++k) {
      d_off[k] = beta[k][0];
      d_scale[k] = beta[k][1];
      d_temp[k] = beta[k][2];
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
    double num = 0.0, wsum = 0.0;
    icp_reweight(in, tp, n, o_old, s_old, t_old, beta, cfg.max_weight, w.data(), num, wsum);
    const double res = num / (static_cast<double>(n) * wsum);
    r.iterations = it;
    r.statistic = res;
    obs(it, static_cast<const IcpResult&>(r));
    if (!icp_finite(r, res)) {
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
