// Rcpp glue for GGIR part 1's blocks (ggir_block_store.hpp) and their
// epoch signals (ggir_epochs.hpp). Converts and checks shapes only.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "gravcal/ggir/ggir_block_store.hpp"
#include "gravcal/ggir/ggir_epochs.hpp"
#include "meta_ahead.h"
#include "r_services.h"
#include "sources_glue.h"

namespace {

// A read made beside the pump (meta_read_beside()), waiting for
// gc_meta_store_read(): its arguments, the store's rows before it, and the
// rows read or its error.
struct ReadBeside {
  bool ready = false;
  const gravcal_glue::OpenFile* decoder = nullptr;
  std::int64_t units = 0;
  std::size_t chunk = 0;
  bool want_time = false;
  std::size_t before = 0, got = 0;
  std::exception_ptr error;
};

// The block store (ggir_block_store.hpp), and a read made beside the pump.
struct Store : gravcal::ggir_part1::BlockStore {
  using BlockStore::BlockStore;
  ReadBeside beside;
};

Rcpp::NumericVector as_r(const std::vector<double>& v) {
  return Rcpp::NumericVector(v.begin(), v.end());
}

double na_if_nan(double v) { return std::isnan(v) ? NA_REAL : v; }

// What R's block logic reads after rows were added: see gc_meta_store_read().
Rcpp::List read_info(const Store& s, std::size_t before, std::size_t got) {
  Rcpp::NumericVector head;
  if (s.has(Store::kT) && got > 0) {
    const std::size_t k = std::min<std::size_t>(got, 10);
    head = Rcpp::NumericVector(k);
    for (std::size_t i = 0; i < k; ++i) head[static_cast<R_xlen_t>(i)] = s.value(Store::kT, before + i);
  }
  return Rcpp::List::create(
      Rcpp::Named("n") = static_cast<double>(got), Rcpp::Named("size") = static_cast<double>(s.size()),
      Rcpp::Named("first_time") = got > 0 ? na_if_nan(s.first_read_time()) : NA_REAL,
      Rcpp::Named("tail_time") = Rcpp::NumericVector::create(na_if_nan(s.tail_time(0)),
                                                             na_if_nan(s.tail_time(1))),
      Rcpp::Named("head_temp") = head);
}

// gravcal's linear model from R: list(K (3 x 3), offset and, for the
// temperature term, tempoffset and meantemp).
gravcal::ggir_part1::LinearModel linear_model(const Rcpp::List& cal, bool have_temp) {
  gravcal::ggir_part1::LinearModel m;
  const Rcpp::NumericMatrix K = cal["K"];
  const Rcpp::NumericVector off = cal["offset"];
  if (K.nrow() != 3 || K.ncol() != 3 || off.size() != 3) Rcpp::stop("K must be 3 x 3, offset 3 values");
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.K[r][c] = K(r, c);
    m.offset[r] = off[r];
  }
  if (cal.containsElementNamed("tempoffset") && have_temp) {
    const Rcpp::NumericVector to = cal["tempoffset"];
    if (to.size() != 3) Rcpp::stop("tempoffset needs 3 values");
    m.temp = true;
    m.meantemp = Rcpp::as<double>(cal["meantemp"]);
    for (int a = 0; a < 3; ++a) m.tempoffset[a] = to[a];
  }
  return m;
}

// The block store (ggir_block_store.hpp) behind an external pointer.
Store* store(SEXP ptr) {
  Rcpp::XPtr<Store> p(ptr);
  if (p.get() == nullptr) Rcpp::stop("the block store is gone");
  return p.get();
}

// Rows [0, n_use) of the store, checked.
std::size_t rows_used(const Store& s, double n_use) {
  if (!(n_use >= 0) || n_use > static_cast<double>(s.size())) Rcpp::stop("n_use out of range");
  return static_cast<std::size_t>(n_use);
}

}  // namespace

// A store for one of g.getmeta()'s blocks, with a temperature, time,
// light and wear column where asked.
// [[Rcpp::export(rng = false)]]
SEXP gc_meta_store(bool temperature, bool time, bool light, bool wear) {
  return Rcpp::XPtr<Store>(new Store(temperature, time, light, wear), true);
}

// The store's memory given back now (a block and the epochs' work, a few
// hundred MB), not when R's garbage collector finds the pointer; the store
// is gone after this. Once more is nothing.
// [[Rcpp::export(rng = false)]]
void gc_meta_store_release(SEXP ptr) {
  Rcpp::XPtr<Store> p(ptr);
  if (p.get() != nullptr) p.release();
}

// One block from an open decoder (gc_decoder_open()'s ptr) appended to the
// store: `units` units in reads of at most `capacity` samples. Returns
// list(n = rows read, size, first_time = the first row read's time,
// tail_time = the store's last two rows' times (last first), head_temp =
// the first 10 temperatures read), times NA where unknown.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_meta_store_read(SEXP ptr, SEXP decoder, double units, double capacity,
                              bool want_time) {
  Store* s = store(ptr);
  gravcal_glue::OpenFile* f = gravcal_glue::open_file(decoder);
  if (!(capacity >= 1) || capacity > 1e9) Rcpp::stop("capacity must be in [1, 1e9]");
  if (s->beside.ready) {
    // the read was made beside the pump: the same one, taken
    ReadBeside b = s->beside;
    s->beside = ReadBeside();
    if (b.decoder != f || b.units != static_cast<std::int64_t>(units) ||
        b.chunk != static_cast<std::size_t>(capacity) || b.want_time != want_time) {
      Rcpp::stop("the block read beside the calibration is not the one asked for");
    }
    if (b.error) {
      try {
        std::rethrow_exception(b.error);
      } catch (const std::exception& e) {
        Rcpp::stop(e.what());
      }
    }
    return read_info(*s, b.before, b.got);
  }
  const std::size_t before = s->size();
  std::size_t got = 0;
  try {
    got = s->read(*f->decoder, static_cast<std::int64_t>(units), static_cast<std::size_t>(capacity),
                  want_time);
  } catch (const std::exception& e) {
    Rcpp::stop(e.what());
  }
  return read_info(*s, before, got);
}

std::function<void()> gravcal_glue::meta_read_beside(const Rcpp::List& spec) {
  Store* s = store(spec["store"]);
  gravcal_glue::OpenFile* f = gravcal_glue::open_file(spec["decoder"]);
  const double units = Rcpp::as<double>(spec["units"]);
  const double chunk = Rcpp::as<double>(spec["chunk"]);
  const bool want_time = Rcpp::as<bool>(spec["want_time"]);
  if (!(chunk >= 1) || chunk > 1e9) Rcpp::stop("chunk must be in [1, 1e9]");
  if (s->beside.ready) Rcpp::stop("the store holds a read not yet taken");
  ReadBeside b;
  b.decoder = f;
  b.units = static_cast<std::int64_t>(units);
  b.chunk = static_cast<std::size_t>(chunk);
  b.want_time = want_time;
  return [s, f, b]() mutable {
    b.before = s->size();
    try {
      b.got = s->read(*f->decoder, b.units, b.chunk, b.want_time);
    } catch (...) {
      b.error = std::current_exception();
    }
    b.ready = true;
    s->beside = b;
  };
}

// Rows given from R (samples in memory) appended, or (`from` >= 0) put in
// place of the rows from `from` on (R's imputation of the rows read): a
// list of columns x, y, z and, where the store keeps them, temperature,
// time, light, wear (absent: NA). Returns what gc_meta_store_read() returns.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_meta_store_put(SEXP ptr, const Rcpp::List& cols, double from) {
  Store* s = store(ptr);
  const char* names[Store::kCols] = {"x", "y", "z", "temperature", "time", "light", "wear"};
  const R_xlen_t n = Rf_xlength(cols["x"]);
  const double* src[Store::kCols];
  for (int c = 0; c < Store::kCols; ++c) {
    src[c] = nullptr;
    if (!cols.containsElementNamed(names[c])) continue;
    SEXP v = cols[names[c]];
    src[c] = gravcal_glue::column(v, n, c >= Store::kT, names[c]);
  }
  const std::size_t before = from >= 0 ? static_cast<std::size_t>(from) : s->size();
  if (from >= 0) {
    if (from > static_cast<double>(s->size())) Rcpp::stop("from beyond the block");
    s->replace_tail(before, src, static_cast<std::size_t>(n));
  } else {
    s->append(src, static_cast<std::size_t>(n));
  }
  return read_info(*s, before, static_cast<std::size_t>(n));
}

// Rows [from, from + count) of the store as R columns (those it keeps).
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_meta_store_rows(SEXP ptr, double from, double count) {
  const Store* s = store(ptr);
  if (!(from >= 0) || !(count >= 0) || from + count > static_cast<double>(s->size()))
    Rcpp::stop("rows beyond the block");
  const std::size_t a = static_cast<std::size_t>(from), k = static_cast<std::size_t>(count);
  const char* names[Store::kCols] = {"x", "y", "z", "temperature", "time", "light", "wear"};
  Rcpp::List out;
  for (int c = 0; c < Store::kCols; ++c) {
    if (!s->has(c)) continue;
    const double* v = s->col(c);
    if (v != nullptr) {
      out[names[c]] = Rcpp::NumericVector(v + a, v + a + k);
    } else {
      Rcpp::NumericVector r(Rcpp::no_init(static_cast<R_xlen_t>(k)));
      for (std::size_t i = 0; i < k; ++i) r[static_cast<R_xlen_t>(i)] = s->value(c, a + i);
      out[names[c]] = r;
    }
  }
  return out;
}

// The rows the store holds.
// [[Rcpp::export(rng = false)]]
double gc_meta_store_size(SEXP ptr) { return static_cast<double>(store(ptr)->size()); }

// Rows [0, length(x)) of x, y, z replaced (a block calibrated in R).
// [[Rcpp::export(rng = false)]]
void gc_meta_store_set_xyz(SEXP ptr, const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                           const Rcpp::NumericVector& z) {
  Store* s = store(ptr);
  const R_xlen_t n = x.size();
  if (y.size() != n || z.size() != n || static_cast<double>(n) > static_cast<double>(s->size()))
    Rcpp::stop("x, y, z must have equal lengths within the block");
  std::copy(x.begin(), x.end(), s->col(Store::kX));
  std::copy(y.begin(), y.end(), s->col(Store::kY));
  std::copy(z.begin(), z.end(), s->col(Store::kZ));
}

// GGIR's fill of a gap after the carry (its last row, 1-based `last`):
// normalised, repeated `reps` times.
// [[Rcpp::export(rng = false)]]
void gc_meta_store_fill_gap(SEXP ptr, double last, double reps) {
  Store* s = store(ptr);
  if (!(last >= 1) || last > static_cast<double>(s->size()) || !(reps >= 0) || reps > 1e9)
    Rcpp::stop("gap fill out of range");
  gravcal::with_r_acc(gravcal_glue::r_long_double(), [&](auto acc) {
    s->fill_gap<decltype(acc)>(static_cast<std::size_t>(last) - 1, static_cast<std::size_t>(reps));
    return 0;
  });
}

// The store reduced to its rows [from, from + count) (0-based from): the
// start's shift, or the carry after a block.
// [[Rcpp::export(rng = false)]]
double gc_meta_store_keep(SEXP ptr, double from, double count) {
  Store* s = store(ptr);
  if (!(from >= 0) || !(count >= 0) || from + count > static_cast<double>(s->size()))
    Rcpp::stop("rows beyond the block");
  s->keep(static_cast<std::size_t>(from), static_cast<std::size_t>(count));
  return static_cast<double>(s->size());
}

// One block of g.getmeta(): the store's first n_use rows (GGIR's
// data[1:use, ]), calibrated in place, then its epoch signals; use_temp:
// the temperature column is g.getmeta()'s (calibration, long epochs). The
// calibration: `model` (list: K, offset and, for a temperature term,
// tempoffset, meantemp: gravcal's linear model as apply_model() applies
// it), else `cal` as g.getmeta applies it (list: offset, inv_scale, and
// when the temperature term applies meantemp, inv_tempoffset); the rows
// after n_use (the carry) are untouched. sf, windowsizes (ws3, ws2, ws),
// the short-epoch metric names (ggir_epochs.hpp short_metrics()), non-wear
// settings (list: clipthres, sdcriter, racriter, approach "2013"/"2023"),
// the filters (ggir_filter_coefs() or NULL) and whether R's stats::filter()
// fuses; threads: 1, or 2 for the running medians of the angles on a
// second thread (short_metrics()). Returns list(short = named list of
// epoch means, nonwear, clipping, epochs, en, temperature, lightmean,
// lightpeak), unrounded.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_meta_store_epochs(SEXP ptr, const Rcpp::List& cal,
                                Rcpp::Nullable<Rcpp::List> model, bool use_temp, double sf,
                                const Rcpp::NumericVector& windowsizes,
                                const Rcpp::CharacterVector& metrics,
                                const Rcpp::List& nonwear,
                                Rcpp::Nullable<Rcpp::List> filters, bool conv_fused,
                                bool rec_fused, double n_use, int threads) {
  namespace p1 = gravcal::ggir_part1;
  Store* s = store(ptr);
  const std::size_t un = rows_used(*s, n_use);
  if (windowsizes.size() != 3) Rcpp::stop("windowsizes must have 3 values");
  if (!(sf > 0)) Rcpp::stop("sf must be positive");
  if (threads < 1) Rcpp::stop("threads must be at least 1");
  double* cx = s->col(Store::kX);
  double* cy = s->col(Store::kY);
  double* cz = s->col(Store::kZ);
  // the temperature: for GGIR's calibration and its epoch means when used
  // (g.getmeta() drops a temperature over 50 degrees C); gravcal's model
  // takes the column whenever the recording has one
  const gravcal::ggir_part1::RunColumn* tcol = s->runs(Store::kT);
  const gravcal::ggir_part1::RunColumn* t = use_temp ? tcol : nullptr;
  const gravcal::ggir_part1::RunColumn* li = s->runs(Store::kLight);
  // readers of the temperature and light for passes in increasing order
  // (none where the column is absent: never read then)
  gravcal::ggir_part1::RunColumn empty;
  gravcal::ggir_part1::RunColumn::Cursor tcur(tcol ? *tcol : empty);
  auto temp_at = [&tcur](std::size_t i) { return tcur(i); };
  if (model.isNotNull()) {
    const p1::LinearModel m = linear_model(Rcpp::List(model.get()), tcol != nullptr);
    try {
      p1::apply_linear(m, cx, cy, cz, temp_at, un);
    } catch (const std::exception& e) {
      Rcpp::stop(e.what());
    }
  } else {
    p1::Calibration c;
    const Rcpp::NumericVector off = cal["offset"], isc = cal["inv_scale"];
    if (off.size() != 3 || isc.size() != 3) Rcpp::stop("offset and inv_scale need 3 values");
    for (int a = 0; a < 3; ++a) {
      c.offset[a] = off[a];
      c.inv_scale[a] = isc[a];
    }
    if (cal.containsElementNamed("meantemp") && t != nullptr) {
      const Rcpp::NumericVector ito = cal["inv_tempoffset"];
      if (ito.size() != 3) Rcpp::stop("inv_tempoffset needs 3 values");
      c.temp = true;
      c.meantemp = Rcpp::as<double>(cal["meantemp"]);
      for (int a = 0; a < 3; ++a) c.inv_tempoffset[a] = ito[a];
    }
    auto spans = [t](std::size_t n, auto&& f) { t->spans(n, f); };
    p1::apply_calibration(c, cx, cy, cz, spans, t != nullptr, un);
  }
  std::vector<std::string> names(metrics.size());
  for (R_xlen_t k = 0; k < metrics.size(); ++k) names[static_cast<std::size_t>(k)] = Rcpp::as<std::string>(metrics[k]);
  p1::NonwearConfig nw;
  nw.sf = sf;
  nw.ws2 = windowsizes[1];
  nw.ws = windowsizes[2];
  nw.clipthres = Rcpp::as<double>(nonwear["clipthres"]);
  nw.sdcriter = Rcpp::as<double>(nonwear["sdcriter"]);
  nw.racriter = Rcpp::as<double>(nonwear["racriter"]);
  const std::string appr = Rcpp::as<std::string>(nonwear["approach"]);
  if (appr != "2013" && appr != "2023") Rcpp::stop("nonwear approach must be \"2013\" or \"2023\"");
  nw.approach_2023 = appr == "2023";
  const bool ld = gravcal_glue::r_long_double();
  gravcal::GgirFilterCoefs fc;
  std::vector<Rcpp::NumericVector> keep_coefs;
  const bool have_f = filters.isNotNull();
  if (have_f) {
    const Rcpp::List fl(filters.get());
    auto arma = [&](const char* nm) {
      const Rcpp::List co = fl[nm];
      keep_coefs.push_back(Rcpp::NumericVector(co["b"]));
      keep_coefs.push_back(Rcpp::NumericVector(co["a"]));
      const Rcpp::NumericVector& b = keep_coefs[keep_coefs.size() - 2];
      const Rcpp::NumericVector& a = keep_coefs.back();
      return gravcal::ArmaCoefs{b.begin(), static_cast<std::size_t>(b.size()), a.begin(),
                                static_cast<std::size_t>(a.size())};
    };
    keep_coefs.reserve(8);
    fc.band = arma("band");
    fc.low = arma("low");
    fc.high = arma("high");
    fc.zc = arma("zc");
    fc.zc_sb = Rcpp::as<double>(fl["zc_sb"]);
  }
  gravcal::RFilterArith arith;
  arith.conv_fused = conv_fused;
  arith.rec_fused = rec_fused;
  gravcal::ggir_part1::RunColumn::Cursor lcur(li ? *li : empty);
  auto light_at = [&lcur](std::size_t i) { return lcur(i); };
  // an ad hoc csv file's wear flags: GGIR's non-wear from them
  const gravcal::ggir_part1::RunColumn* we = s->runs(Store::kWear);
  const std::function<double(std::size_t)> wear_at = [we](std::size_t i) { return we->at(i); };
  Rcpp::List shorts(metrics.size());
  Rcpp::List out;
  try {
    gravcal::with_r_acc(ld, [&](auto acc) {
      using Acc = decltype(acc);
      // the long epochs' means of the norm, the temperature and the light,
      // in the short metrics' pass
      const double M = windowsizes[1] * sf;
      using Sum = p1::PassSum<Acc>;
      std::vector<Sum> longs;
      longs.reserve(3);
      longs.push_back(Sum{p1::EpochSums<Acc>(un, M, true),
                          [](std::size_t from, std::size_t to, const double* en, double* o) {
                            std::copy(en, en + (to - from), o);
                          },
                          true});
      // a column (the temperature, the light) whose running sums are exact
      // (a .cwa file's) is summed a run at a time (run_sums_exact()), the
      // others in the pass; `at`: its place in `longs` (the norm's first),
      // or -1 - its place in `by_runs`
      std::vector<p1::EpochSums<Acc>> by_runs;
      by_runs.reserve(2);
      auto column = [&](const p1::RunColumn* col) -> std::ptrdiff_t {
        if (p1::run_sums_exact<Acc>([&](auto&& f) { col->spans(un, f); })) {
          by_runs.emplace_back(un, M, true);
          p1::EpochSums<Acc>& e = by_runs.back();
          col->spans(un, [&e](std::size_t from, std::size_t to, double v) { e.add_run_exact(v, to - from); });
          return -1 - static_cast<std::ptrdiff_t>(by_runs.size() - 1);
        }
        longs.push_back(Sum{p1::EpochSums<Acc>(un, M, true),
                            [cur = p1::RunColumn::Cursor(*col)](std::size_t from, std::size_t to, const double*,
                                                                double* o) mutable { cur.fill(from, to, o); },
                            false});
        return static_cast<std::ptrdiff_t>(longs.size() - 1);
      };
      const std::ptrdiff_t t_at = t ? column(t) : 0;
      const std::ptrdiff_t li_at = li ? column(li) : 0;
      std::vector<Sum*> lp;
      for (Sum& l : longs) lp.push_back(&l);
      // non-wear, clipping and the light's peaks beside the metrics (on
      // this thread while a second makes the running medians)
      const double* xyz[3] = {cx, cy, cz};
      p1::NonwearResult r;
      std::vector<double> peaks;
      // the clipping counts and the non-wear's lattice read in the pass of
      // the sums (the rows read once)
      p1::ClipLattice lattice(un, nw);
      const std::function<void(std::size_t, std::size_t)> on_rows =
          [&](std::size_t from, std::size_t to) { lattice.feed(xyz, from, to); };
      const std::function<void()> beside = [&]() {
        r = p1::nonwear_clipping<Acc>(xyz, un, nw, we ? &wear_at : nullptr, &lattice);
        if (li) {
          peaks = p1::light_peaks(light_at, un, M, [li](std::size_t from, std::size_t to, auto&& f) {
            li->values_in(from, to, f);
          });
        }
      };
      const std::vector<std::vector<double>> sm =
          p1::short_metrics<Acc>(cx, cy, cz, un, sf, windowsizes[0], names,
                                 have_f ? &fc : nullptr, arith, lp.data(), lp.size(), threads, beside,
                                 lattice.usable ? on_rows : std::function<void(std::size_t, std::size_t)>());
      for (std::size_t k = 0; k < sm.size(); ++k) shorts[static_cast<R_xlen_t>(k)] = as_r(sm[k]);
      shorts.names() = metrics;
      auto finished = [&](bool have, std::ptrdiff_t at) {
        if (!have) return Rcpp::RObject();
        return Rcpp::RObject(as_r(at >= 0 ? longs[static_cast<std::size_t>(at)].sums.finish()
                                          : by_runs[static_cast<std::size_t>(-1 - at)].finish()));
      };
      const Rcpp::RObject en = as_r(longs[0].sums.finish());
      const Rcpp::RObject temperature = finished(t != nullptr, t_at);
      const Rcpp::RObject lightmean = finished(li != nullptr, li_at);
      out = Rcpp::List::create(
          Rcpp::Named("short") = shorts, Rcpp::Named("nonwear") = as_r(r.nonwear),
          Rcpp::Named("clipping") = as_r(r.clipping),
          Rcpp::Named("epochs") = static_cast<double>(r.epochs),
          Rcpp::Named("en") = en, Rcpp::Named("temperature") = temperature,
          Rcpp::Named("lightmean") = lightmean,
          Rcpp::Named("lightpeak") = li ? Rcpp::RObject(as_r(peaks)) : Rcpp::RObject());
      return 0;
    });
  } catch (const std::exception& e) {
    Rcpp::stop(e.what());
  }
  return out;
}

// The gradient of each short epoch's ENMO with respect to a linear
// calibration's coefficients (ggir_epochs.hpp enmo_gradient()), for the
// store's first n_use rows, raw (before gc_meta_store_epochs() calibrates
// them): sf, the short epoch ws3 (s), and the calibration as a list: K
// (3 x 3), offset, and, for the temperature term (with `temperature`),
// tempoffset and meantemp. Returns a matrix, one row per short epoch, 12
// columns named as coef().
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix gc_meta_store_gradient(SEXP ptr, double n_use, double sf, double ws3,
                                           const Rcpp::List& cal, bool temperature) {
  namespace p1 = gravcal::ggir_part1;
  const Store* s = store(ptr);
  const std::size_t n = rows_used(*s, n_use);
  if (!(sf > 0) || !(ws3 > 0)) Rcpp::stop("sf and ws3 must be positive");
  const p1::RunColumn* t = temperature ? s->runs(Store::kT) : nullptr;
  p1::RunColumn empty;
  p1::RunColumn::Cursor tcur(t ? *t : empty);
  const p1::LinearModel lm = linear_model(cal, t != nullptr);
  p1::LinearCalibration m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.K[r][c] = lm.K[r][c];
    m.offset[r] = lm.offset[r];
    m.tempoffset[r] = lm.tempoffset[r];
  }
  m.temp = lm.temp;
  m.meantemp = lm.meantemp;
  std::vector<double> g;
  try {
    g = p1::enmo_gradient(s->col(Store::kX), s->col(Store::kY), s->col(Store::kZ),
                          [&tcur](std::size_t i) { return tcur(i); }, m.temp, n, sf * ws3, m);
  } catch (const std::exception& e) {
    Rcpp::stop(e.what());
  }
  const std::size_t C = p1::kGradientColumns;
  const std::size_t ne = g.size() / C;
  Rcpp::NumericMatrix out(static_cast<int>(ne), static_cast<int>(C));
  for (std::size_t e = 0; e < ne; ++e) {
    for (std::size_t c = 0; c < C; ++c) out(static_cast<int>(e), static_cast<int>(c)) = g[e * C + c];
  }
  Rcpp::colnames(out) = Rcpp::CharacterVector::create("k_xx", "k_yy", "k_zz", "k_xy", "k_xz", "k_yz",
                                                      "o_x", "o_y", "o_z", "t_x", "t_y", "t_z");
  return out;
}

// GGIR's time stamps of M (strftime(<POSIXlt>, "%Y-%m-%dT%H:%M:%S%z")) from
// a POSIXlt's fields, without R's formatter (a tenth of a second for a
// week's short epochs): the date and time as two-digit fields, the year as
// four, then the offset from UTC as "+hhmm" or "-hhmm", whole minutes of
// `gmtoff` (seconds dropped, as the C library's %z drops them). `gmtoff`
// NULL: an offset of zero (R's "UTC" and "GMT", which carry none). Only
// where that is certainly what R writes: NULL (R formats) if any element
// has a year outside 1000-9999, a field NA or out of its range, seconds
// not whole, an offset NA, or isdst negative (the C library then writes no
// offset at all).
// [[Rcpp::export(rng = false)]]
SEXP gc_iso_stamps(const Rcpp::IntegerVector& year, const Rcpp::IntegerVector& mon,
                   const Rcpp::IntegerVector& mday, const Rcpp::IntegerVector& hour,
                   const Rcpp::IntegerVector& min, const Rcpp::NumericVector& sec,
                   const Rcpp::IntegerVector& isdst, SEXP gmtoff) {
  const R_xlen_t n = year.size();
  if (mon.size() != n || mday.size() != n || hour.size() != n || min.size() != n ||
      sec.size() != n || isdst.size() != n) {
    Rcpp::stop("the fields of the time stamps differ in length");
  }
  const bool zero = Rf_isNull(gmtoff);
  if (!zero && (TYPEOF(gmtoff) != INTSXP || Rf_xlength(gmtoff) != n)) return R_NilValue;
  const int* off = zero ? nullptr : INTEGER(gmtoff);
  auto in = [](int v, int lo, int hi) { return v != NA_INTEGER && v >= lo && v <= hi; };
  for (R_xlen_t i = 0; i < n; ++i) {
    const double s = sec[i];
    if (!in(year[i], 1000 - 1900, 9999 - 1900) || !in(mon[i], 0, 11) || !in(mday[i], 1, 31) ||
        !in(hour[i], 0, 23) || !in(min[i], 0, 59) || !(s >= 0 && s <= 60) || s != std::floor(s) ||
        !in(isdst[i], 0, 1) || (off != nullptr && !in(off[i], -86400, 86400))) {
      return R_NilValue;
    }
  }
  auto two = [](char* p, int v) {
    p[0] = static_cast<char>('0' + v / 10);
    p[1] = static_cast<char>('0' + v % 10);
  };
  Rcpp::CharacterVector out(n);
  char b[24];  // "YYYY-mm-ddTHH:MM:SS+hhmm"
  for (R_xlen_t i = 0; i < n; ++i) {
    const int y = year[i] + 1900;
    two(b, y / 100);
    two(b + 2, y % 100);
    b[4] = '-';
    two(b + 5, mon[i] + 1);
    b[7] = '-';
    two(b + 8, mday[i]);
    b[10] = 'T';
    two(b + 11, hour[i]);
    b[13] = ':';
    two(b + 14, min[i]);
    b[16] = ':';
    two(b + 17, static_cast<int>(sec[i]));
    const int o = off == nullptr ? 0 : off[i];
    const int m = (o < 0 ? -o : o) / 60;  // whole minutes, toward zero
    b[19] = o < 0 ? '-' : '+';
    two(b + 20, m / 60);
    two(b + 22, m % 60);
    SET_STRING_ELT(out, i, Rf_mkCharLenCE(b, 24, CE_NATIVE));
  }
  return out;
}
