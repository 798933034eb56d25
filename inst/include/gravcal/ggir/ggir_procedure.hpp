// gravcal: GGIR's auto-calibration procedure (van Hees et al. 2014; GGIR
// 3.3's g.calibrate), one recording in one call.
//
// Stages, each once, in the order GGIR runs them:
//   [1] read a block (GGIR's block size, in the source's units) through the
//       one pump into GGIR's block rules and the segmenter (pipeline.hpp);
//   [2] check the block's temperature (first values, variation);
//   [3] add its windows to the window table (means, sds, norm, temperature,
//       the rest rule's flag; ggir_window_table.hpp);
//   [4] after a block that may end the reading, filter the table (missing
//       values, GGIR's fill value, duplicate windows, the first window: the
//       window table again), decide whether there is enough data, keep the
//       rest windows, check that they cover the sphere;
//   [5] fit scale, offset and temperature offset by weighted iterative
//       closest point (icp.hpp) and compute GGIR's error;
//   [6] stop once the error is small enough after minloadcrit hours, else
//       read on (gravcal's own mode may instead read the whole recording,
//       or stop when the host's enough() says so: GgirConfig::reading);
//   [7] after the last block, the QC outcome.
// GGIR-compatible mode keeps every rule as GGIR has it; gravcal's own mode
// departs where GGIR's behaviour is an accident (see R/ggir.R's header).
//
// The host (the R glue) supplies what belongs to R: its round() for GGIR's
// error, a least-squares routine (GGIR's lm.wfit), printing, warnings, a
// record after each block (GGIR's memory record) and interrupts.
#ifndef GRAVCAL_GGIR_PROCEDURE_HPP
#define GRAVCAL_GGIR_PROCEDURE_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/ggir/ggir_blocks.hpp"
#include "gravcal/ggir/ggir_config.hpp"
#include "gravcal/ggir/ggir_window_table.hpp"
#include "gravcal/ggir/icp.hpp"
#include "gravcal/mcu/model.hpp"
#include "gravcal/ggir/pipeline.hpp"
#include "gravcal/host/r_arith.hpp"
#include "gravcal/host/segmenter.hpp"

namespace gravcal {

// The QC outcome (R maps each to GGIR's message).
enum class GgirQc { none, done, done_no_temp, attempted, no_decrease, no_sphere,
                    no_rest, no_data, not_finite };

struct GgirOutcome;

class GgirHost {
 public:
  virtual ~GgirHost() = default;
  // R's round(x, digits)
  virtual double round_digits(double x, int digits) = 0;
  // R's least squares (icp.hpp's Solver contract)
  virtual void least_squares(double* X, const double* y, std::size_t n, int p,
                             double* coef, double* rsd) = 0;
  virtual void print(const std::string& s) { (void)s; }
  virtual void warn(const std::string& s) { (void)s; }
  // after block `i` (1-based) added windows to the table
  virtual void block_added(int i) { (void)i; }
  // true: abandon the run (an interrupt); may also throw
  virtual bool interrupted() { return false; }
  // the adaptive budget's stop rule (GgirConfig::reading == 2): after a
  // converged fit that meets GGIR's error target, true stops the reading
  // (o holds the fit and its table)
  virtual bool enough(const GgirOutcome& o) { (void)o; return false; }
};

struct GgirOutcome {
  double scale[3] = {1.0, 1.0, 1.0};
  double offset[3] = {0.0, 0.0, 0.0};
  double tempoffset[3] = {0.0, 0.0, 0.0};
  bool has_tempoffset = false;  // GGIR's tempoffset is NULL until a fit ran
  bool has_error_start = false, has_error_end = false, has_npoints = false;
  double error_start = 0.0, error_end = 0.0;
  double npoints = 0.0;
  double nhoursused = 0.0;
  GgirQc qc = GgirQc::none;
  bool use_temp = false, temp_available = false;
  // the last fit's table (GGIR's spheredata): its rows (1-based row numbers
  // of the window table) and columns (7, or 8 with the temperature column)
  bool has_table = false;
  std::vector<std::size_t> table_rows;
  std::vector<double> table;  // column-major
  int table_columns = 0;
  bool has_icp = false;
  IcpResult icp;
  double meantemp = 0.0;
  int blocks = 0;
  std::int64_t windows = 0;   // windows in the table
  std::int64_t samples = 0;   // samples read
  std::int64_t zeros = 0;     // of which idle-sleep zeros, removed (GGIR's rule)
  bool stopped = false;       // interrupted
  // own mode: rest windows of the last table left out by the guards, by
  // reason (GgirWhy: norm, clipped, identical)
  std::int64_t excluded[3] = {0, 0, 0};
  bool early = false;         // the reading stopped before the recording's end
};

class GgirProcedure {
 public:
  GgirProcedure(const GgirConfig& cfg, GgirHost& host)
      : cfg_(cfg), host_(host), L_(10.0 * cfg.sf), seg_(L_, false), table_(cfg) {
    // compatible mode: the window statistics in R's arithmetic, and R's sds
    // only where GGIR's rules can see them (the rest rule, the duplicate
    // filter): see Segmenter::lazy_r_sd()
    if (cfg_.compat) {
      buffer_.assign(3 * (static_cast<std::size_t>(std::ceil(L_)) + 1), 0.0);
      seg_.use_r_arithmetic(buffer_.data(), buffer_.size(), cfg_.r_long_double);
      seg_.keep_nonfinite(cfg_.nonfinite_in_sums);
    }
    if (cfg_.compat && cfg_.lazy) {
      held_.assign(buffer_.size(), 0.0);
      seg_.lazy_r_sd(cfg_.max_sd, &lazy_, held_.data(), held_.size());
    }
  }

  // The procedure on `src`. An interrupt (the host's interrupted()) ends it
  // with o.stopped set.
  GgirOutcome run(Source& src) {
    GgirOutcome o;
    try {
      blocks(src, o);
    } catch (const Interrupted&) {
      o.stopped = true;
    }
    o.windows = n_feat();
    return o;
  }

  // The procedure's last stages ([4] end to [7]) on points already chosen
  // (several recordings' rest windows, pooled): `table` column-major with n
  // rows and 7 columns (8 with a temperature column, to be used), `hours`
  // read; temp_available: some of the recordings had a temperature.
  GgirOutcome fit_table(const double* table, std::size_t n, bool temperature,
                        bool temp_available, double hours) {
    GgirOutcome o;
    o.temp_available = temp_available;
    o.use_temp = temperature;
    o.nhoursused = hours;
    o.table_columns = temperature ? 8 : 7;
    o.table.assign(table, table + static_cast<std::size_t>(o.table_columns) * n);
    o.table_rows.resize(n);
    for (std::size_t i = 0; i < n; ++i) o.table_rows[i] = i + 1;
    o.has_table = true;
    try {
      if (n < static_cast<std::size_t>(cfg_.min_rest)) {
        o.qc = GgirQc::no_rest;
      } else {
        fit_points(o, true);
      }
      finish(o);
    } catch (const Interrupted&) {
      o.stopped = true;
    }
    return o;
  }

 private:
  void blocks(Source& src, GgirOutcome& o) {
    const double per_hour = 3600.0 * cfg_.sf;
    const bool temp = cfg_.temperature && src.has_temperature();
#ifndef GRAVCAL_NO_THREADS
    Worker worker;  // (before the blocks: outlives them)
#endif
    GgirBlocks blocks(seg_, per_hour, cfg_.compat, temp, cfg_.temp_min_sd, cfg_.r_long_double);
#ifndef GRAVCAL_NO_THREADS
    if (cfg_.threads >= 2) blocks.async(&worker);  // the windows beside the decode
#endif
    BlocksStage stage(blocks, temp);
    const std::int64_t units = static_cast<std::int64_t>(cfg_.block_units);
    for (int i = 1;; ++i) {
      host_.print(i == 1 ? "\nLoading chunk: 1" : " " + std::to_string(i));
      // [1] a block through the pump
      table_.start_block();
      auto sink = [&](const WindowStats& w) { table_.hold(w); };
      const GgirBlockRead rd = read_ggir_block(src, blocks, stage, units, sink,
                                               [&] { return host_.interrupted(); });
      const PumpResult& p = rd.pump;
      const GgirBlockInfo& b = rd.info;
      if (p.stopped || host_.interrupted()) throw Interrupted();
      bool present = b.rows > 0;
      bool last = !present || p.done ||
                  (cfg_.short_block_rows > 0 && static_cast<double>(b.rows) < cfg_.short_block_rows);
      if (present) {
        o.samples += b.rows;
        o.zeros += b.zeros;
        const double two_hours = per_hour * 2 + 1;
        if (cfg_.compat && static_cast<double>(b.rows) < two_hours) {
          // GGIR: a short block is the last one; a short first block means
          // the file is too short to use
          last = true;
          if (i == 1) present = false;
        } else if (!cfg_.compat && last && static_cast<double>(o.samples) < two_hours) {
          // own mode: the recording, not its first block (whose size
          // chunksize scales), must hold two hours
          present = false;
          too_short_ = true;
        }
      }
      if (i == 1) o.use_temp = o.temp_available = present && temp;
      bool added = false;
      if (present && b.used > 0) {
        if (o.use_temp) o.use_temp = temperature_usable(b);  // [2]
        table_.add_block(o.temp_available, o.use_temp);      // [3]
        added = true;
        ++o.blocks;
        host_.block_added(i);
      }
      bool stop_loading = false;
      // GGIR fits after every block, but only the fit after the last
      // block, or one that can stop the loading (more than minloadcrit
      // hours), decides the result: the others are skipped (the table only
      // grows, so the last fit is the same either way). gravcal's own mode
      // refits before the last block only once the table has grown by a
      // quarter, so that time stays linear when the target is never met.
      bool due = added || i == 1;
      if (due && !last && defer()) {
        pending_ = true;
        due = false;
      }
      // own mode: the result is always a converged fit on the whole table,
      // also when the last block added nothing after a decision
      if (last && (pending_ || decided_)) due = true;
      if (due) stop_loading = fit(o, last);  // [4] - [6]
      if (last) break;
      if (stop_loading) {
        o.early = true;
        break;
      }
    }
    finish(o);  // [7]
  }

  std::int64_t n_feat() const { return static_cast<std::int64_t>(table_.size()); }

  int reading() const { return cfg_.compat ? 0 : cfg_.reading; }

  // whether the fit after a block that is not the last can wait
  bool defer() const {
    const double n = static_cast<double>(n_feat());
    switch (reading()) {
      case 1:
        return true;
      case 2:
        return n < next_fit_ || n < next_check_;
      default:
        return n * 10 / 3600 <= cfg_.minloadcrit || (!cfg_.compat && n < next_fit_);
    }
  }

  // [2] GGIR's temperature checks on a block's used samples: false, with a
  // warning, when the temperature cannot be used.
  bool temperature_usable(const GgirBlockInfo& b) {
    const char* why = nullptr;
    if (b.first_mean > cfg_.temp_max_first) {
      why = "its first values exceed 120 (not degrees C?)";
    } else if (std::isnan(b.temp_sd)) {
      why = "it has fewer than 2 values";
    } else if (b.temp_sd < cfg_.temp_min_sd) {
      why = "it does not vary (sd < 0.01)";
    }
    if (why == nullptr) return true;
    host_.warn(std::string("temperature not used for calibration: ") + why);
    return false;
  }

  // GGIR's calibration error: mean | |a| - 1 | over the rows' means after
  // calibration, in GGIR's arithmetic ((m + offset) / (1 / scale)), rounded
  // as GGIR rounds it.
  double ggir_error(const double* const* m, std::size_t n, const double* scale,
                    const double* offset, const double* tempoffset, const double* t,
                    double meantemp) {
    std::vector<double> d(n);
    for (std::size_t i = 0; i < n; ++i) {
      // without a temperature the term is +0 (0 / Inf): the same bits as
      // GGIR's expression without it
      const double dt = t != nullptr ? t[i] - meantemp : 0.0;
      double a[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = apply_model_ggir(m[k][i], offset[k], scale[k], dt,
                                t != nullptr ? tempoffset[k] : 0.0);
      }
      const double e = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      d[i] = std::fabs(e - 1.0);
    }
    const double mean = with_r_acc(cfg_.r_long_double, [&](auto acc) {
      return r_mean<decltype(acc)>(d.data(), n);
    });
    return host_.round_digits(mean, cfg_.error_digits);
  }

  // [4] - [6] filter the table, check it, fit; true when the reading may
  // stop
  bool fit(GgirOutcome& o, bool last) {
    pending_ = false;
    decided_ = false;
    next_fit_ = static_cast<double>(n_feat()) * cfg_.refit_growth;
    next_check_ = static_cast<double>(n_feat()) + cfg_.check_hours * 3600 / 10;
    // the filters, then the rest windows to fit (ggir_window_table.hpp)
    const std::vector<std::size_t> idx = table_.usable(o.excluded);
    const std::vector<std::size_t> keep = table_.rest(idx);
    o.has_table = false;
    o.nhoursused = 0;
    const double n = static_cast<double>(idx.size());
    const bool enough = cfg_.compat ? n > (cfg_.minloadcrit - cfg_.enough_offset)
                                    : !too_short_ && n * 10 >= cfg_.min_hours * 3600;
    if (!enough) {
      o.qc = GgirQc::no_data;
      take_table(o, idx);
      return false;
    }
    o.nhoursused = (n * 10) / 3600;
    if (keep.size() < static_cast<std::size_t>(cfg_.min_rest)) {
      o.qc = GgirQc::no_rest;
      return false;
    }
    take_table(o, keep);
    return fit_points(o, last);
  }

  // [4] (end) - [6] on the points in o.table: the error before, the sphere
  // check, the fit, the error after; true when the reading may stop
  bool fit_points(GgirOutcome& o, bool last) {
    const std::size_t n = o.table_rows.size();
    o.has_npoints = true;
    o.npoints = static_cast<double>(n);
    const double* m[3] = {&o.table[1 * n], &o.table[2 * n], &o.table[3 * n]};
    const double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    o.error_start = ggir_error(m, n, one, zero, nullptr, nullptr, 0);
    o.has_error_start = true;
    int tel = 0;
    for (int a = 0; a < 3; ++a) {
      double lo = m[a][0], hi = m[a][0];
      for (std::size_t i = 1; i < n; ++i) {
        lo = std::min(lo, m[a][i]);
        hi = std::max(hi, m[a][i]);
      }
      if (lo < -cfg_.spherecrit && hi > cfg_.spherecrit) ++tel;
    }
    if (tel < 3) {
      o.qc = GgirQc::no_sphere;
      return false;
    }
    // [5] compatible mode fits as GGIR does; gravcal's own mode decides
    // whether to read on with a fit converged to cfg_.decide_tol, started
    // from the previous decision's coefficients (so that each decision
    // costs a few passes over at most cfg_.decide_windows windows, and the
    // decisions together stay a small share of the time however the refits
    // fall), and
    // fits to convergence, from the identity, only for a result it keeps
    // (the adaptive budget judges converged fits only)
    const bool adaptive = reading() == 2;
    IcpResult r = icp(o, cfg_.compat ? Rule::ggir_r
                         : (last || adaptive) ? Rule::converge : Rule::decide);
    if (!cfg_.compat && !last && !adaptive) {
      if (judge(o, r, last)) {
        r = icp(o, Rule::converge);
      } else {
        decided_ = true;
      }
    }
    o.has_icp = true;
    o.icp = r;
    for (int k = 0; k < 3; ++k) {
      o.scale[k] = r.scale[k];
      o.offset[k] = r.offset[k];
      o.tempoffset[k] = r.tempoffset[k];
    }
    o.has_tempoffset = true;
    o.meantemp = r.meantemp;
    o.error_end = error_;
    o.has_error_end = true;
    // [6]
    if (judge(o, r, last)) {
      o.qc = o.use_temp == o.temp_available ? GgirQc::done : GgirQc::done_no_temp;
      return reading() != 1;
    }
    if (o.nhoursused > cfg_.minloadcrit) {
      host_.print("\nnew calibration error: " + r_number(o.error_end) + " g");
      host_.print("\nnpoints around sphere: " + r_number(o.npoints));
    }
    o.qc = GgirQc::attempted;
    return false;
  }

  enum class Rule { ggir_r, decide, converge };  // GGIR's fit; own mode's decision; its result

  // the fit on the last table, with GGIR's error after it (error_). Own
  // mode's decisions to read on fit at most cfg_.decide_windows evenly
  // spaced windows of it (their error estimates the table's to well under
  // a mg), so that the decisions, whose number grows with the log of the
  // recording's length, cost a fixed time each: the converged fit on the
  // whole table, when the reading stops, decides the result.
  IcpResult icp(const GgirOutcome& o, Rule rule) {
    std::size_t n = o.table_rows.size();
    const double* col[4] = {&o.table[1 * n], &o.table[2 * n], &o.table[3 * n],
                            o.use_temp ? &o.table[7 * n] : nullptr};
    std::vector<double> sub;
    if (rule == Rule::decide && n > cfg_.decide_windows && cfg_.decide_windows >= 3) {
      const std::size_t m = cfg_.decide_windows;
      sub.resize(4 * m);
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t i = j * n / m;  // evenly spaced, first row first
        for (int c = 0; c < 4; ++c) sub[c * m + j] = col[c] != nullptr ? col[c][i] : 0.0;
      }
      for (int c = 0; c < 4; ++c) {
        if (col[c] != nullptr) col[c] = &sub[c * m];
      }
      n = m;
    }
    const double* t = col[3];
    IcpConfig c;
    c.max_iter = cfg_.max_iter;
    c.tol = cfg_.tol;
    c.max_weight = cfg_.max_weight;
    c.use_temp = o.use_temp;
    c.stop = rule == Rule::ggir_r ? StopRule::ggir : StopRule::parameters;
    c.r_arithmetic = rule == Rule::ggir_r;
    c.r_long_double = cfg_.r_long_double;
    // a decision (own mode) needs the error to a fraction of a mg, not the
    // coefficients to 1e-10: converged to decide_tol
    if (rule == Rule::decide) c.tol = cfg_.decide_tol;
    if (rule == Rule::decide && has_warm_) {
      c.warm = true;
      for (int k = 0; k < 3; ++k) {
        c.start_offset[k] = warm_.offset[k];
        c.start_scale[k] = warm_.scale[k];
        c.start_tempoffset[k] = warm_.tempoffset[k];
      }
      c.start_meantemp = warm_.meantemp;
    }
    HostSolver solve{&host_};
    IcpResult r = fit_icp(
        col[0], col[1], col[2], t, n, c,
        [&](int it, const IcpResult&) {
          if ((it & 15) == 0 && host_.interrupted()) throw Interrupted();
        },
        solve);
    if (!o.use_temp) r.meantemp = 0;
    if (rule == Rule::decide) {
      has_warm_ = r.finite && r.temp_used == o.use_temp;
      warm_ = r;
    }
    error_ = ggir_error(col, n, r.scale, r.offset, r.tempoffset, t, r.meantemp);
    return r;
  }

  bool judge(const GgirOutcome& o, const IcpResult& r, bool last) {
    // NaN compares false, as R's isTRUE() of NA
    const bool good = error_ < o.error_start && error_ < cfg_.max_error;
    if (reading() == 2 && !last) {
      // the adaptive budget: the host's rule in place of minloadcrit, on a
      // finite fit (at the last block, GGIR's rule says whether it is done)
      // (o already holds this fit's coefficients and error)
      return good && r.finite && host_.enough(o);
    }
    return good && o.nhoursused > cfg_.minloadcrit;
  }

  // [7]
  void finish(GgirOutcome& o) const {
    if (o.has_icp && !o.icp.finite) {
      // the last fit did not stay finite (a temperature term the rest
      // windows cannot determine, for one): GGIR stops with an error here;
      // gravcal returns no correction and says why
      for (int k = 0; k < 3; ++k) {
        o.scale[k] = 1;
        o.offset[k] = 0;
        o.tempoffset[k] = 0;
      }
      o.has_tempoffset = o.use_temp;
      o.error_end = o.error_start;
      o.has_error_end = o.has_error_start;
      o.qc = GgirQc::not_finite;
    } else if (o.has_error_end && o.has_error_start && o.error_end > o.error_start) {
      o.qc = GgirQc::no_decrease;
    }
  }

  // the table's rows `rows` as the last fit's table
  void take_table(GgirOutcome& o, const std::vector<std::size_t>& rows) const {
    const int nc = o.temp_available ? 8 : 7;
    const std::size_t n = rows.size();
    table_.copy(rows, nc, o.table);
    o.table_rows.resize(n);
    for (std::size_t i = 0; i < n; ++i) o.table_rows[i] = rows[i] + 1;
    o.table_columns = nc;
    o.has_table = true;
  }

  // a number as R's paste0() prints it (15 significant digits)
  static std::string r_number(double x) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.15g", x);
    return buf;
  }

  struct Interrupted {};
  struct HostSolver {
    GgirHost* host;
    void operator()(double* X, const double* y, std::size_t n, int p, double* coef,
                    double* rsd) const {
      host->least_squares(X, y, n, p, coef, rsd);
    }
  };

  GgirConfig cfg_;
  GgirHost& host_;
  IcpResult warm_;         // own mode: the last decision's fit, and
  bool has_warm_ = false;  // whether the next decision may start from it
  double L_;
  std::vector<double> buffer_, held_;
  LazySd lazy_;
  Segmenter seg_;
  GgirWindowTable table_;
  bool pending_ = false;
  bool decided_ = false;    // own mode: the last fit was a decision's
  bool too_short_ = false;  // own mode: the recording holds under two hours
  double next_fit_ = 0.0;
  double next_check_ = 0.0;  // adaptive budget: the next check, in windows
  double error_ = 0.0;
};

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_PROCEDURE_HPP
