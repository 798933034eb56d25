// What the core borrows from R where R's own numbers are promised: R's
// least-squares routine (lm.wfit's dqrls) for GGIR's fit.
#ifndef GRAVCAL_GLUE_R_SERVICES_H
#define GRAVCAL_GLUE_R_SERVICES_H

#include <Rcpp.h>
#include <R_ext/Applic.h>

#include <cstddef>
#include <vector>

namespace gravcal_glue {

// R's accumulator (its LDOUBLE, in mean(), sum(), cumsum(), var(),
// rowSums()): long double (true), or double in an R built without long
// double (capabilities("long.double") FALSE). Set from R when the package
// loads (R/fp-build.R, gc_set_r_long_double()); each call that replays R's
// arithmetic reads it once and passes it to the core.
inline bool& r_long_double() {
  static bool on = true;
  return on;
}

// Weighted least squares by R's own LINPACK routine dqrls, with lm.wfit's
// tolerance and its handling of aliased columns: the numbers GGIR's lm.wfit
// calls get, to the last bit (see icp.hpp, IcpConfig::r_arithmetic).
struct RLeastSquares {
  mutable std::vector<double> qty, qraux, work, b;
  mutable std::vector<int> jpvt;
  void operator()(double* X, const double* y, std::size_t n, int p,
                  double* coef, double* rsd) const {
    int nn = static_cast<int>(n), pp = p, ny = 1, rank = 0;
    double tol = 1e-7;
    qty.assign(n, 0.0);
    qraux.assign(static_cast<std::size_t>(p), 0.0);
    work.assign(2 * static_cast<std::size_t>(p), 0.0);
    b.assign(static_cast<std::size_t>(p), 0.0);
    jpvt.resize(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) jpvt[static_cast<std::size_t>(j)] = j + 1;
    std::vector<double> yy(y, y + n);
    F77_CALL(dqrls)(X, &nn, &pp, yy.data(), &ny, &tol, b.data(), rsd,
                    qty.data(), &rank, jpvt.data(), qraux.data(), work.data());
    for (int j = 0; j < p; ++j) coef[j] = NA_REAL;
    for (int j = 0; j < rank; ++j) coef[jpvt[static_cast<std::size_t>(j)] - 1] = b[static_cast<std::size_t>(j)];
  }
};

}  // namespace gravcal_glue

#endif
