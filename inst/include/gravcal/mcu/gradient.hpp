// gravcal: forward-difference gradient descent for the 9-parameter model
// (Farago, Maczak & Gingl 2024, Sec. II-C, Eq. 12-16).
//
// Objective over N calibration points:
//   f(p) = w * sum_i r_i^2,   r_i = |a_i(p)|^2 - 1   (square root omitted)
//                             r_i = |a_i(p)| - 1     (use_sqrt)
// with w = 1 / N (scale = MEAN, gravcal's default) or w = 1 (scale = SUM, as
// printed in Eq. 12). With the paper's learning rates the plain sum diverges
// on 18 points: the curvature of f along an offset is about 8 N / 3 for the
// squared form, so alpha_o = 0.2 overshoots by a factor of ~5; the mean
// divides the curvature by N and the paper's rates then converge in 20-30
// iterations, as its Fig. 9 shows.
//
// Gradient by forward differences, g_i = (f(p + h e_i) - f(p)) / h (Eq. 13),
// by central differences, or in closed form (gradient_analytic.hpp: no step,
// and in fixed point computed so that 16 bits fit as well as double);
// update p <- p - alpha * g with per-group rates (Eq. 14, 16):
// alpha_s = 0.3 (k_xx, k_yy, k_zz), alpha_m = 0.8 (k_xy, k_xz, k_yz),
// alpha_o = 0.2 (o_x, o_y, o_z); h = 1e-5 (double, float, 32-bit fixed point)
// or 0.01 (16-bit fixed point); at most M = 50 iterations.
//
// Header-only, no heap; T is double, float or a gravcal fixed-point type.
#ifndef GRAVCAL_GRADIENT_HPP
#define GRAVCAL_GRADIENT_HPP

#include <cmath>

#include "gravcal/mcu/gradient_analytic.hpp"
#include "gravcal/mcu/model.hpp"

namespace gravcal {

enum ObjectiveScale { SCALE_MEAN = 0, SCALE_SUM = 1 };

// How the gradient is obtained:
//   GRADIENT_FORWARD   (f(p + h e_i) - f(p)) / h, the paper's Eq. 13: N + 9 N
//                      model evaluations per iteration, biased by about h / 2
//                      times the curvature;
//   GRADIENT_CENTRAL   (f(p + h e_i) - f(p - h e_i)) / 2h: twice the
//                      evaluations, without that bias;
//   GRADIENT_ANALYTIC  the closed form (gradient_analytic.hpp), one pass over
//                      the points, no h. In fixed point it keeps its own
//                      scaling and the parameters in the wide type between
//                      steps: fixed16 then fits as well as double.
enum GradientMode { GRADIENT_FORWARD = 0, GRADIENT_CENTRAL = 1, GRADIENT_ANALYTIC = 2 };

template <typename T>
struct GradientConfig {
  int max_iter = 50;
  T h = T(1e-5);
  T rate[NPARAM] = {T(0.3), T(0.3), T(0.3), T(0.8), T(0.8),
                    T(0.8), T(0.2), T(0.2), T(0.2)};
  bool use_sqrt = false;
  ObjectiveScale scale = SCALE_MEAN;
  // Stop early when every |step| is below tol (0: always run max_iter).
  T tol = T(0);
  // The paper's forward differences by default. The forward difference's
  // bias of about h / 2 per parameter matters with the 16-bit step h = 0.01;
  // central differences remove it, the analytic gradient needs no h at all.
  GradientMode gradient = GRADIENT_FORWARD;
};

// divide_by_count(f, n), f / n: gradient_analytic.hpp.

// f(p) over n points given as coordinate arrays.
template <typename T>
inline T gradient_objective(const T* p, const T* x, const T* y, const T* z,
                            int n, bool use_sqrt, ObjectiveScale scale) {
  using std::sqrt;
  T f = T(0);
  for (int i = 0; i < n; ++i) {
    const Vec3<T> a = apply_model(p, Vec3<T>{x[i], y[i], z[i]});
    T r = norm2(a);
    r = use_sqrt ? sqrt(r) - T(1) : r - T(1);
    f = f + r * r;
  }
  if (scale == SCALE_MEAN && n > 0) f = divide_by_count(f, n);
  return f;
}

struct GradientResult {
  int iterations;  // iterations run
  bool converged;  // stopped by tol (false when tol = 0 or max_iter reached)
  bool finite;     // parameters stayed finite
};

struct NoObserver {
  template <typename T>
  void operator()(int, const T*, const T&) const {}
};

// Fit p in place (p holds the start on entry, usually identity_params()).
// observe(iteration, p, f) is called after every update, iteration from 1,
// with f the objective before that update. It is also the way to stop a long
// fit from outside: observe may throw, and since the core holds no resources
// (no heap, no locks) the fit unwinds cleanly. The R glue does so on Ctrl-C
// (Rcpp::checkUserInterrupt()); the core itself stays free of R.
template <typename T, class Observer = NoObserver>
inline GradientResult fit_gradient(T* p, const T* x, const T* y, const T* z,
                                   int n, const GradientConfig<T>& cfg,
                                   Observer&& observe = Observer()) {
  GradientResult res{0, false, true};
  T g[NPARAM];
  AnalyticDescent<T> analytic(p);
  const bool mean = cfg.scale == SCALE_MEAN;
  for (int it = 1; it <= cfg.max_iter; ++it) {
    const T f0 = gradient_objective(p, x, y, z, n, cfg.use_sqrt, cfg.scale);
    bool small;
    if (cfg.gradient == GRADIENT_ANALYTIC) {
      small = analytic.step(p, x, y, z, n, cfg.use_sqrt, mean, cfg.rate, cfg.tol);
    } else {
      for (int i = 0; i < NPARAM; ++i) {
        const T saved = p[i];
        p[i] = saved + cfg.h;
        const T fi = gradient_objective(p, x, y, z, n, cfg.use_sqrt, cfg.scale);
        if (cfg.gradient == GRADIENT_CENTRAL) {
          p[i] = saved - cfg.h;
          const T fm = gradient_objective(p, x, y, z, n, cfg.use_sqrt, cfg.scale);
          p[i] = saved;
          g[i] = (fi - fm) / (cfg.h + cfg.h);
        } else {
          p[i] = saved;
          g[i] = (fi - f0) / cfg.h;
        }
      }
      small = descend(p, g, cfg.rate, cfg.tol);
    }
    res.iterations = it;
    observe(it, static_cast<const T*>(p), f0);
    for (int i = 0; i < NPARAM; ++i) {
      if (!(p[i] == p[i]) || p[i] - p[i] != T(0)) {  // NaN or infinite
        res.finite = false;
        return res;
      }
    }
    if (small) {
      res.converged = true;
      break;
    }
  }
  return res;
}

}  // namespace gravcal

#endif  // GRAVCAL_GRADIENT_HPP
