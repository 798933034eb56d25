// Rcpp glue for the one pump (pipeline.hpp): makes a source, runs one stage
// over it (the segmenter, GGIR's procedure, or a collector of samples) and
// converts the result. Nothing here decides anything about the samples.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "gravcal/ggir/ggir_procedure.hpp"
#include "gravcal/ggir/pipeline.hpp"
#include "gravcal/host/threads.hpp"
#include "meta_ahead.h"
#include "r_services.h"
#include "sources_glue.h"
#include "windows_glue.h"

using gravcal_glue::SourceBox;

namespace {

SourceBox* source(SEXP ptr) {
  Rcpp::XPtr<SourceBox> p(ptr);
  if (p.get() == nullptr || !p->src) Rcpp::stop("the source is closed");
  return p.get();
}

// A stage's options (gc_pump()'s `opts`, an R list), read once where the
// stage starts: each key through one of the readers below, and done()
// rejects any key none of them read (a misspelt option would otherwise be
// ignored without a word).
class OptionReader {
 public:
  explicit OptionReader(const Rcpp::List& o) : o_(o) {}
  // a required number
  double num(const char* name) {
    if (!has(name)) Rcpp::stop("option '%s' is missing", name);
    return Rcpp::as<double>(o_[name]);
  }
  // a required switch (a number, 0: off)
  bool flag(const char* name) { return num(name) != 0; }
  // an optional number
  double num_or(const char* name, double fallback) {
    return has(name) ? Rcpp::as<double>(o_[name]) : fallback;
  }
  // a required numeric vector
  Rcpp::NumericVector vec(const char* name) {
    if (!has(name)) Rcpp::stop("option '%s' is missing", name);
    return o_[name];
  }
  // an optional R function (absent or NULL: none)
  Rcpp::Nullable<Rcpp::Function> function(const char* name) {
    if (!has(name)) return R_NilValue;
    SEXP f = o_[name];
    if (Rf_isNull(f)) return R_NilValue;
    return Rcpp::Function(f);
  }
  // every key of the list was read
  void done() const {
    if (o_.size() == 0) return;
    const SEXP names = o_.names();
    for (R_xlen_t i = 0; i < o_.size(); ++i) {
      const std::string key = Rf_isNull(names) ? "" : CHAR(STRING_ELT(names, i));
      if (std::find(read_.begin(), read_.end(), key) == read_.end())
        Rcpp::stop("unknown option '%s'", key.c_str());
    }
  }

 private:
  bool has(const char* name) {
    read_.push_back(name);
    return o_.containsElementNamed(name);
  }
  const Rcpp::List& o_;
  std::vector<std::string> read_;
};

bool interrupt_tick() {
  Rcpp::checkUserInterrupt();  // throws on Ctrl-C
  return false;
}

// The segmenter over the source, block by block (block_units units; < 0:
// one block), on_block(samples, windows) after each block but the last
// (windows: the table so far when want_table, else NULL) returning TRUE to
// stop.
Rcpp::List run_windows(gravcal::Source& src, const Rcpp::List& o,
                       Rcpp::Nullable<Rcpp::Function> on_block) {
  OptionReader opt(o);
  const double L = opt.num("window_samples");
  if (!(L >= 1.0 && L < 1e7)) Rcpp::stop("window_samples must be in [1, 1e7)");
  const bool skip_zero = opt.flag("skip_zero"), r_arithmetic = opt.flag("r_arithmetic");
  Rcpp::NumericVector par = opt.vec("par");
  const int rule = static_cast<int>(opt.num("rule"));
  const bool temperature = opt.flag("temperature");
  const double bu = opt.num("block_units");
  const bool want_table = opt.flag("want_table");
  opt.done();
  gravcal_glue::SegmenterBox box(L, skip_zero, r_arithmetic);
  const gravcal_glue::RestRule is_rest(rule, par);
  gravcal::SegmenterStage stage(box.seg, temperature);
  gravcal_glue::WindowTable table;
  auto sink = [&](const gravcal::WindowStats& w) { table.add(w, is_rest(w)); };
  const std::int64_t units = bu < 0 ? -1 : static_cast<std::int64_t>(bu);
  double samples = 0;
  bool stopped = false;
  std::vector<double> per_block;  // units and samples of each block
  for (;;) {
    const gravcal::PumpResult r = gravcal::pump(src, stage, units, sink, interrupt_tick);
    samples += static_cast<double>(r.samples);
    per_block.push_back(static_cast<double>(r.units));
    per_block.push_back(static_cast<double>(r.samples));
    if (r.done || (r.samples == 0 && r.units == 0)) break;
    if (on_block.isNotNull()) {
      Rcpp::Function f(on_block.get());
      SEXP tab = want_table ? Rcpp::RObject(table.to_list()) : Rcpp::RObject(R_NilValue);
      if (Rcpp::as<bool>(f(samples, tab))) {
        stopped = true;
        break;
      }
    }
  }
  const gravcal::Segmenter& s = box.seg;
  return Rcpp::List::create(
      Rcpp::Named("windows") = table.to_list(), Rcpp::Named("samples") = samples,
      Rcpp::Named("stopped") = stopped, Rcpp::Named("blocks") = Rcpp::wrap(per_block),
      Rcpp::Named("skipped_zero") = static_cast<double>(s.skipped_zero()),
      Rcpp::Named("pending") = static_cast<double>(s.pending()));
}

// The keys of GGIR's block rules, in the "ggir" and "blocks" stages alike.
void parse_block_rules(OptionReader& opt, gravcal::GgirConfig& c) {
  c.sf = opt.num("sf");
  if (!(10 * c.sf >= 1 && 10 * c.sf < 1e7)) Rcpp::stop("sf out of range");
  c.compat = opt.flag("compat");
  c.temperature = opt.flag("temperature");
  c.temp_min_sd = opt.num("temp_min_sd");
  c.block_units = opt.num("block_units");
}

// GGIR's block rules alone over the source, one block of block_units units
// at a time, with the segmenter behind them: per block, its windows and what
// the rules saw (for the tests of the rules; the procedure is run_ggir()).
Rcpp::List run_blocks(gravcal::Source& src, const Rcpp::List& o) {
  OptionReader opt(o);
  gravcal::GgirConfig c;
  parse_block_rules(opt, c);
  const double per_hour = opt.num("per_hour");
  Rcpp::NumericVector par = opt.vec("par");
  opt.done();
  gravcal_glue::SegmenterBox box(10 * c.sf, false, c.compat);
  const bool temp = c.temperature && src.has_temperature();
  gravcal::GgirBlocks blocks(box.seg, per_hour, c.compat, temp, c.temp_min_sd,
                             gravcal_glue::r_long_double());
  gravcal::BlocksStage stage(blocks, temp);
  const gravcal_glue::RestRule is_rest(1, par);
  const std::int64_t units = static_cast<std::int64_t>(c.block_units);
  Rcpp::List out;
  for (;;) {
    gravcal_glue::WindowTable table;
    auto sink = [&](const gravcal::WindowStats& w) { table.add(w, is_rest(w)); };
    const gravcal::GgirBlockRead r =
        gravcal::read_ggir_block(src, blocks, stage, units, sink, interrupt_tick);
    if (r.pump.units == 0 && r.pump.samples == 0) break;
    Rcpp::List b = gravcal_glue::block_result(table, r.info);
    b["units"] = static_cast<double>(r.pump.units);
    b["done"] = r.pump.done;
    out.push_back(b);
    if (r.pump.done) break;
  }
  return out;
}

// Every sample of the source into R vectors: x, y, z, temperature (when the
// source has it), time (option time), light (option light, default 1, when
// the source has it).
Rcpp::List run_samples(gravcal::Source& src, const Rcpp::List& o) {
  OptionReader opt(o);
  const double chunk = opt.num_or("chunk", 65536.0);
  if (!(chunk >= 1 && chunk <= 1e8)) Rcpp::stop("chunk must be in [1, 1e8]");
  const bool light = opt.num_or("light", 1) != 0 && src.has_light();
  const bool time = opt.flag("time");
  opt.done();
  gravcal::CollectStage stage(src.has_temperature(), time, static_cast<std::size_t>(chunk),
                              light);
  gravcal::pump(src, stage, -1, [](const gravcal::WindowStats&) {}, interrupt_tick);
  using C = gravcal::CollectStage;
  const char* names[C::kColumns] = {"x", "y", "z", "temperature", "time", "light"};
  const bool on[C::kColumns] = {true, true, true, stage.temperature(), time, light};
  Rcpp::List out;
  for (int c = 0; c < C::kColumns; ++c) {
    if (!on[c]) continue;
    out[names[c]] = Rcpp::NumericVector(stage.col[c].begin(), stage.col[c].end());
    std::vector<double>().swap(stage.col[c]);
  }
  return out;
}

class RHost;
Rcpp::List outcome_list(const gravcal::GgirOutcome& r, const RHost& host);

// What GGIR's procedure borrows from R.
class RHost : public gravcal::GgirHost {
 public:
  RHost(bool verbose, Rcpp::Nullable<Rcpp::Function> on_block,
        Rcpp::Nullable<Rcpp::Function> on_fit = R_NilValue)
      : verbose_(verbose), on_block_(on_block), on_fit_(on_fit) {}
  double round_digits(double x, int digits) override {
    return R::fround(x, static_cast<double>(digits));
  }
  void least_squares(double* X, const double* y, std::size_t n, int p, double* coef,
                     double* rsd) override {
    ls_(X, y, n, p, coef, rsd);
  }
  void print(const std::string& s) override {
    if (verbose_) Rprintf("%s", s.c_str());
  }
  void warn(const std::string& s) override { warnings.push_back(s); }
  void block_added(int i) override {
    if (on_block_.isNotNull()) Rcpp::Function(on_block_.get())(i);
  }
  bool interrupted() override { return interrupt_tick(); }
  // the adaptive budget's rule: R's on_fit(outcome) (see ggir_run())
  bool enough(const gravcal::GgirOutcome& o) override;
  std::vector<std::string> warnings;

 private:
  bool verbose_;
  Rcpp::Nullable<Rcpp::Function> on_block_;
  Rcpp::Nullable<Rcpp::Function> on_fit_;
  gravcal_glue::RLeastSquares ls_;
};

const char* qc_name(gravcal::GgirQc q) {
  switch (q) {
    case gravcal::GgirQc::done: return "done";
    case gravcal::GgirQc::done_no_temp: return "done_no_temp";
    case gravcal::GgirQc::attempted: return "attempted";
    case gravcal::GgirQc::no_decrease: return "no_decrease";
    case gravcal::GgirQc::no_sphere: return "no_sphere";
    case gravcal::GgirQc::no_rest: return "no_rest";
    case gravcal::GgirQc::no_data: return "no_data";
    case gravcal::GgirQc::not_finite: return "not_finite";
    case gravcal::GgirQc::none: break;
  }
  return "";
}

Rcpp::RObject vec3(const double* v, bool present) {
  if (!present) return R_NilValue;
  return Rcpp::NumericVector(v, v + 3);
}

Rcpp::RObject scalar(double v, bool present) {
  if (!present) return R_NilValue;
  return Rcpp::NumericVector::create(v);
}

// GGIR's procedure's options from R (ggir_options()'s list, R/ggir.R),
// parsed once: the core's settings and the host's (printing, the adaptive
// budget's rule). Every key of the list is read here (those of GGIR's block
// rules through parse_block_rules()) and nowhere else; a key not read here
// is an error.
struct GgirOptions {
  gravcal::GgirConfig cfg;
  bool verbose = false;
  Rcpp::Nullable<Rcpp::Function> on_fit = R_NilValue;  // RHost::enough()
};

GgirOptions parse_ggir_options(const Rcpp::List& o) {
  OptionReader opt(o);
  GgirOptions g;
  g.verbose = opt.flag("verbose");
  g.on_fit = opt.function("on_fit");
  gravcal::GgirConfig& c = g.cfg;
  parse_block_rules(opt, c);
  c.lazy = opt.flag("lazy");
  c.nonfinite_in_sums = opt.num_or("nonfinite_in_sums", 0) != 0;
  c.threads = static_cast<int>(opt.num_or("threads", 1));
  if (c.threads < 1) Rcpp::stop("threads must be at least 1");
  c.r_long_double = gravcal_glue::r_long_double();
  c.min_rest = static_cast<int>(opt.num("min_rest"));
  c.error_digits = static_cast<int>(opt.num("error_digits"));
  c.max_iter = static_cast<int>(opt.num("max_iter"));
  c.reading = static_cast<int>(opt.num("reading"));
  if (c.reading < 0 || c.reading > 2) Rcpp::stop("reading must be 0, 1 or 2");
  const struct {
    const char* name;
    double* field;
  } numbers[] = {
      {"short_block_rows", &c.short_block_rows}, {"spherecrit", &c.spherecrit},
      {"minloadcrit", &c.minloadcrit}, {"max_sd", &c.max_sd},
      {"max_abs_mean", &c.max_abs_mean}, {"enough_offset", &c.enough_offset},
      {"min_hours", &c.min_hours}, {"max_error", &c.max_error},
      {"temp_max_first", &c.temp_max_first}, {"temp_missing", &c.temp_missing},
      {"fill", &c.fill}, {"tol", &c.tol}, {"max_weight", &c.max_weight},
      {"refit_growth", &c.refit_growth},
      {"guard_norm", &c.guard_norm}, {"guard_clip", &c.guard_clip},
      {"guard_repeat", &c.guard_repeat}, {"check_hours", &c.check_hours}};
  for (const auto& f : numbers) *f.field = opt.num(f.name);
  opt.done();
  return g;
}

// The procedure's outcome for R (ggir_run() shapes GGIR's list from it).
Rcpp::List outcome_list(const gravcal::GgirOutcome& r, const RHost& host) {
  Rcpp::RObject table = R_NilValue, rows = R_NilValue;
  if (r.has_table) {
    const int n = static_cast<int>(r.table_rows.size());
    Rcpp::NumericMatrix m(n, r.table_columns);
    std::copy(r.table.begin(), r.table.end(), m.begin());
    table = m;
    rows = Rcpp::IntegerVector(r.table_rows.begin(), r.table_rows.end());
  }
  Rcpp::RObject icp = R_NilValue;
  if (r.has_icp) {
    icp = Rcpp::List::create(
        Rcpp::Named("scale") = Rcpp::NumericVector(r.icp.scale, r.icp.scale + 3),
        Rcpp::Named("offset") = Rcpp::NumericVector(r.icp.offset, r.icp.offset + 3),
        Rcpp::Named("tempoffset") = Rcpp::NumericVector(r.icp.tempoffset, r.icp.tempoffset + 3),
        Rcpp::Named("meantemp") = r.icp.meantemp,
        Rcpp::Named("temp_used") = r.icp.temp_used,
        Rcpp::Named("iterations") = r.icp.iterations,
        Rcpp::Named("converged") = r.icp.converged,
        Rcpp::Named("finite") = r.icp.finite);
  }
  Rcpp::List out = Rcpp::List::create(
      Rcpp::Named("scale") = Rcpp::NumericVector(r.scale, r.scale + 3),
      Rcpp::Named("offset") = Rcpp::NumericVector(r.offset, r.offset + 3),
      Rcpp::Named("tempoffset") = vec3(r.tempoffset, r.has_tempoffset),
      Rcpp::Named("cal.error.start") = scalar(r.error_start, r.has_error_start),
      Rcpp::Named("cal.error.end") = scalar(r.error_end, r.has_error_end),
      Rcpp::Named("table") = table, Rcpp::Named("rows") = rows,
      Rcpp::Named("npoints") = r.has_npoints
          ? Rcpp::RObject(Rcpp::IntegerVector::create(static_cast<int>(r.npoints)))
          : Rcpp::RObject(R_NilValue),
      Rcpp::Named("nhoursused") = r.nhoursused,
      Rcpp::Named("qc") = std::string(qc_name(r.qc)),
      Rcpp::Named("use.temp") = r.use_temp,
      Rcpp::Named("temp.available") = r.temp_available,
      Rcpp::Named("icp") = icp);
  out["meantemp"] = r.meantemp;
  out["blocks"] = r.blocks;
  out["windows"] = static_cast<double>(r.windows);
  out["samples"] = static_cast<double>(r.samples);
  out["zeros"] = static_cast<double>(r.zeros);
  out["warnings"] = Rcpp::wrap(host.warnings);
  out["stopped"] = r.stopped;
  out["excluded"] = Rcpp::NumericVector::create(
      Rcpp::Named("norm") = static_cast<double>(r.excluded[0]),
      Rcpp::Named("clipped") = static_cast<double>(r.excluded[1]),
      Rcpp::Named("identical") = static_cast<double>(r.excluded[2]));
  out["early"] = r.early;
  return out;
}

bool RHost::enough(const gravcal::GgirOutcome& o) {
  if (on_fit_.isNull()) return false;
  Rcpp::LogicalVector v = Rcpp::Function(on_fit_.get())(outcome_list(o, *this));
  return v.size() == 1 && v[0] == TRUE;
}

// GGIR's procedure over the source (ggir_procedure.hpp).
Rcpp::List run_ggir(gravcal::Source& src, const Rcpp::List& o,
                    Rcpp::Nullable<Rcpp::Function> on_block) {
  const GgirOptions g = parse_ggir_options(o);
  RHost host(g.verbose, on_block, g.on_fit);
  gravcal::GgirProcedure proc(g.cfg, host);
  return outcome_list(proc.run(src), host);
}

}  // namespace

// A source over an open device file (gc_decoder_open()'s ptr).
// [[Rcpp::export(rng = false)]]
SEXP gc_source_decoder(SEXP file) {
  gravcal_glue::OpenFile* f = gravcal_glue::open_file(file);
  std::unique_ptr<SourceBox> b(new SourceBox());
  b->src.reset(new gravcal::DecoderSource(*f->decoder));
  b->keep = file;
  return Rcpp::XPtr<SourceBox>(b.release(), true);
}

// A source over columns in memory (temperature may be NULL); the vectors
// are read where they are.
// [[Rcpp::export(rng = false)]]
SEXP gc_source_columns(SEXP x, SEXP y, SEXP z, SEXP temperature) {
  const R_xlen_t n = Rf_xlength(x);
  std::unique_ptr<SourceBox> b(new SourceBox());
  b->src.reset(new gravcal::ColumnsSource(
      gravcal_glue::column(x, n, false, "x"), gravcal_glue::column(y, n, false, "y"),
      gravcal_glue::column(z, n, false, "z"),
      gravcal_glue::column(temperature, n, true, "temperature"),
      static_cast<std::size_t>(n)));
  b->keep = Rcpp::List::create(x, y, z, temperature);
  return Rcpp::XPtr<SourceBox>(b.release(), true);
}

// A source over blocks an R function reads (see RBlockSource).
// [[Rcpp::export(rng = false)]]
SEXP gc_source_blocks(const Rcpp::List& first, const Rcpp::Function& fetch) {
  std::unique_ptr<SourceBox> b(new SourceBox());
  b->src.reset(new gravcal_glue::RBlockSource(first, fetch));
  b->keep = Rcpp::List::create(first, fetch);
  return Rcpp::XPtr<SourceBox>(b.release(), true);
}

// The one pump: runs `stage` ("windows", "ggir", "blocks" or "samples") over the
// source with the options `opts`; on_block is the stage's callback (see
// run_windows() and RHost::block_added()), or NULL. `beside`: a block of
// g.getmeta()'s read on a second thread meanwhile (meta_ahead.h), joined
// before this returns or its error leaves; without a thread to be had,
// not read (g.getmeta() reads it then).
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_pump(SEXP src, const std::string& stage, const Rcpp::List& opts,
                   Rcpp::Nullable<Rcpp::Function> on_block = R_NilValue,
                   Rcpp::Nullable<Rcpp::List> beside = R_NilValue) {
  SourceBox* b = source(src);
#ifndef GRAVCAL_NO_THREADS
  std::thread side;
  const gravcal::JoinGuard join{side};
  if (beside.isNotNull()) {
    std::function<void()> read = gravcal_glue::meta_read_beside(Rcpp::List(beside.get()));
    try {
      side = std::thread(std::move(read));
    } catch (const std::system_error&) {
      // no thread: g.getmeta() reads the block itself
    }
  }
#endif
  if (stage == "windows") return run_windows(*b->src, opts, on_block);
  if (stage == "ggir") return run_ggir(*b->src, opts, on_block);
  if (stage == "samples") return run_samples(*b->src, opts);
  if (stage == "blocks") return run_blocks(*b->src, opts);
  Rcpp::stop("stage must be \"windows\", \"ggir\", \"blocks\" or \"samples\"");
}

// GGIR's procedure's last stages on points already chosen (pooled rest
// windows): `table` has 7 columns (8 with a temperature to use), `hours`
// were read, temp_available: some of the recordings had a temperature.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_ggir_fit_table(const Rcpp::NumericMatrix& table, bool temp_available,
                             double hours, const Rcpp::List& opts) {
  if (table.ncol() != 7 && table.ncol() != 8) Rcpp::stop("the table needs 7 or 8 columns");
  const GgirOptions g = parse_ggir_options(opts);
  RHost host(g.verbose, R_NilValue, g.on_fit);
  gravcal::GgirProcedure proc(g.cfg, host);
  return outcome_list(proc.fit_table(table.begin(), static_cast<std::size_t>(table.nrow()),
                                     table.ncol() == 8, temp_available, hours),
                      host);
}
