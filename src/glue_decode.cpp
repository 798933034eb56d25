// Rcpp glue for the device-file decoders (decode*.hpp): opens a file with
// the format's decoder, hands blocks of samples to R, and reports what was
// skipped. Converts and calls, nothing more.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <sys/stat.h>

#include <memory>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "decoders.h"
#include "r_services.h"
#include "sources_glue.h"

namespace {

gravcal::Options to_options(const Rcpp::List& opts) {
  gravcal::Options o;
  // R's accumulator, for the decoders that replay R's sums (.cwa)
  o.set("r_long_double", gravcal_glue::r_long_double() ? 1.0 : 0.0);
  if (opts.size() == 0) return o;
  const Rcpp::CharacterVector nm = opts.names();
  for (R_xlen_t i = 0; i < opts.size(); ++i) {
    const std::string name = Rcpp::as<std::string>(nm[i]);
    SEXP v = opts[i];
    if (TYPEOF(v) == STRSXP && Rf_length(v) == 1) {
      o.set(name, Rcpp::as<std::string>(v));
    } else if ((TYPEOF(v) == REALSXP || TYPEOF(v) == INTSXP || TYPEOF(v) == LGLSXP) &&
               Rf_length(v) == 1) {
      o.set(name, Rcpp::as<double>(v));
    } else {
      Rcpp::stop("decoder option '%s' must be a single number or string", name);
    }
  }
  return o;
}

using gravcal_glue::OpenFile;

}  // namespace

// What `path` is, without opening it (opening a named pipe blocks until a
// writer comes): "file", "directory", "fifo", "device", "other", or
// "unknown" when the system cannot say (stat() fails, e.g. a path Windows'
// narrow stat() cannot spell; the caller's file.exists() judges then).
// [[Rcpp::export(rng = false)]]
std::string gc_file_kind(std::string path) {
#ifdef _WIN32
  struct _stat64 st;
  if (_stat64(path.c_str(), &st) != 0) return "unknown";
  const unsigned mode = st.st_mode;
  if ((mode & _S_IFMT) == _S_IFREG) return "file";
  if ((mode & _S_IFMT) == _S_IFDIR) return "directory";
  if ((mode & _S_IFMT) == _S_IFCHR) return "device";
  return "other";
#else
  struct stat st;
  if (stat(path.c_str(), &st) != 0) return "unknown";
  if (S_ISREG(st.st_mode)) return "file";
  if (S_ISDIR(st.st_mode)) return "directory";
  if (S_ISFIFO(st.st_mode)) return "fifo";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "device";
  return "other";
#endif
}

namespace {

OpenFile* get(SEXP ptr) { return gravcal_glue::open_file(ptr); }

// A fixed buffer of `chunk` samples (x, y, z and, when asked, temperature)
// that the decoder fills and the core reads, over and over.
struct ChunkBuffer {
  static constexpr std::size_t chunk = 1u << 16;
  explicit ChunkBuffer(bool temperature)
      : buf((temperature ? 4u : 3u) * chunk),
        out(gravcal::SampleBuffer::columns(buf.data(), chunk, temperature, false)) {}
  std::vector<double> buf;
  gravcal::SampleBuffer out;
};

Rcpp::List info_list(const gravcal::DeviceInfo& d) {
  return Rcpp::List::create(
      Rcpp::Named("format") = d.format, Rcpp::Named("device") = d.device,
      Rcpp::Named("serial") = d.serial, Rcpp::Named("sf") = d.sf,
      Rcpp::Named("start_time") = d.start_time,
      Rcpp::Named("temperature") = d.has_temperature,
      Rcpp::Named("time") = d.has_time, Rcpp::Named("light") = d.has_light,
      Rcpp::Named("wear") = d.has_wear, Rcpp::Named("range_g") = d.range_g, Rcpp::Named("header_text") = d.header_text);
}

}  // namespace

// Opens `path` with the decoder for `format`. Returns list(ptr, info), or
// list(ptr = NULL, error = why) when the file cannot be read as that format.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_decoder_open(const std::string& path, const std::string& format,
                           const Rcpp::List& options) {
  std::unique_ptr<OpenFile> f(new OpenFile());
  gravcal::Options opts = to_options(options);
  // where the file is, for a format whose recording is a folder (Movisens)
  opts.set("file_path", path);
  std::string why;
  f->bytes = gravcal_glue::open_bytes(path, format, opts, why);
  if (!f->bytes) {
    return Rcpp::List::create(Rcpp::Named("ptr") = R_NilValue,
                              Rcpp::Named("error") = why);
  }
  f->decoder = gravcal_glue::make_decoder(format, *f->bytes, opts);
  if (!f->decoder) {
    return Rcpp::List::create(Rcpp::Named("ptr") = R_NilValue,
                              Rcpp::Named("error") = "no native decoder for format " + format,
                              Rcpp::Named("unsupported") = true);
  }
  if (!f->decoder->open()) {
    return Rcpp::List::create(Rcpp::Named("ptr") = R_NilValue,
                              Rcpp::Named("error") = f->decoder->error());
  }
  Rcpp::List info = info_list(f->decoder->info());
  Rcpp::XPtr<OpenFile> ptr(f.release(), true);
  return Rcpp::List::create(Rcpp::Named("ptr") = ptr, Rcpp::Named("info") = info);
}

// The next block: at most `max_units` format units (negative: no limit) and
// at most `capacity` samples. Returns list(x, y, z, temperature, time,
// light, n, units, done); the vectors have length `capacity` and hold n
// samples (temperature, time and light are NULL unless asked for and given
// by the file).
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_decoder_read(SEXP ptr, double max_units, double capacity,
                           bool want_temperature, bool want_time, bool want_light) {
  OpenFile* f = get(ptr);
  if (!(capacity >= 1) || capacity > 1e9) Rcpp::stop("capacity must be in [1, 1e9]");
  const R_xlen_t cap = static_cast<R_xlen_t>(capacity);
  const gravcal::DeviceInfo& d = f->decoder->info();
  Rcpp::NumericVector x(Rcpp::no_init(cap)), y(Rcpp::no_init(cap)), z(Rcpp::no_init(cap));
  Rcpp::NumericVector t, tm, li;
  gravcal::SampleBuffer out;
  out.x = x.begin();
  out.y = y.begin();
  out.z = z.begin();
  if (want_temperature && d.has_temperature) {
    t = Rcpp::NumericVector(Rcpp::no_init(cap));
    out.t = t.begin();
  }
  if (want_time && d.has_time) {
    tm = Rcpp::NumericVector(Rcpp::no_init(cap));
    out.time = tm.begin();
  }
  if (want_light && d.has_light) {
    li = Rcpp::NumericVector(Rcpp::no_init(cap));
    out.light = li.begin();
  }
  out.capacity = static_cast<std::size_t>(cap);
  const std::int64_t units = f->decoder->read(
      out, max_units < 0 ? -1 : static_cast<std::int64_t>(max_units));
  return Rcpp::List::create(
      Rcpp::Named("x") = x, Rcpp::Named("y") = y, Rcpp::Named("z") = z,
      Rcpp::Named("temperature") = out.t ? Rcpp::RObject(t) : Rcpp::RObject(R_NilValue),
      Rcpp::Named("time") = out.time ? Rcpp::RObject(tm) : Rcpp::RObject(R_NilValue),
      Rcpp::Named("light") = out.light ? Rcpp::RObject(li) : Rcpp::RObject(R_NilValue),
      Rcpp::Named("n") = static_cast<double>(out.n),
      Rcpp::Named("units") = static_cast<double>(units),
      Rcpp::Named("done") = f->decoder->done());
}

// What was read and skipped so far.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_decoder_report(SEXP ptr) {
  const gravcal::Report& r = get(ptr)->decoder->report();
  Rcpp::NumericVector counters(r.counters.size());
  Rcpp::CharacterVector names(r.counters.size());
  for (std::size_t i = 0; i < r.counters.size(); ++i) {
    counters[static_cast<R_xlen_t>(i)] = static_cast<double>(r.counters[i].second);
    names[static_cast<R_xlen_t>(i)] = r.counters[i].first;
  }
  counters.attr("names") = names;
  return Rcpp::List::create(
      Rcpp::Named("units") = static_cast<double>(r.units),
      Rcpp::Named("samples") = static_cast<double>(r.samples),
      Rcpp::Named("skipped") = static_cast<double>(r.skipped),
      Rcpp::Named("gaps") = static_cast<double>(r.gaps),
      Rcpp::Named("gap_seconds") = r.gap_seconds,
      Rcpp::Named("truncated") = r.truncated,
      Rcpp::Named("read_error") = r.read_error,
      Rcpp::Named("counters") = counters,
      Rcpp::Named("notes") = Rcpp::wrap(r.notes),
      Rcpp::Named("notes_total") = static_cast<double>(r.notes_total));
}

// The time gaps imputed at epoch level since the last call (g.getmeta();
// Decoder::take_epoch_gaps()): list(row, remaining), rows 0-based over
// every sample the decoder has given.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_decoder_epoch_gaps(SEXP ptr) {
  const std::vector<gravcal::Decoder::EpochGap> g = get(ptr)->decoder->take_epoch_gaps();
  Rcpp::NumericVector row(g.size()), remaining(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) {
    row[static_cast<R_xlen_t>(i)] = static_cast<double>(g[i].row);
    remaining[static_cast<R_xlen_t>(i)] = g[i].remaining;
  }
  return Rcpp::List::create(Rcpp::Named("row") = row, Rcpp::Named("remaining") = remaining);
}

// The file's units as the decoder logs them (Decoder::unit_log(); a
// Parmay Matrix file's packets): a named list of numeric columns, empty for
// a decoder that keeps no log.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_decoder_unit_log(SEXP ptr) {
  const gravcal::Decoder::UnitLog log = get(ptr)->decoder->unit_log();
  Rcpp::List out(log.columns.size());
  for (std::size_t i = 0; i < log.columns.size(); ++i) {
    out[static_cast<R_xlen_t>(i)] = Rcpp::wrap(log.columns[i]);
  }
  out.attr("names") = Rcpp::wrap(log.names);
  return out;
}

// Closes the file now (the finalizer would, later).
// [[Rcpp::export(rng = false)]]
void gc_decoder_close(SEXP ptr) {
  Rcpp::XPtr<OpenFile> p(ptr);
  p.release();
}

// Decodes the rest of the file into a fixed buffer and drops the samples:
// the cost of reading and decoding alone (the benchmarks' floor). Returns
// the samples decoded.
// [[Rcpp::export(rng = false)]]
double gc_decoder_drain(SEXP ptr) {
  OpenFile* f = get(ptr);
  ChunkBuffer cb(f->decoder->info().has_temperature);
  gravcal::SampleBuffer& out = cb.out;
  double samples = 0;
  int rounds = 0;
  while (!f->decoder->done()) {
    out.n = 0;
    const std::int64_t u = f->decoder->read(out, -1);
    samples += static_cast<double>(out.n);
    if (out.n == 0 && u == 0) break;
    if ((++rounds & 31) == 0) Rcpp::checkUserInterrupt();
  }
  return samples;
}

// The CRC-32 of raw bytes (decode_parmay.hpp's), for the test writer of
// Parmay Matrix files (R/write-parmay.R).
// [[Rcpp::export(rng = false)]]
double gc_crc32(Rcpp::RawVector bytes) {
  return static_cast<double>(
      gravcal::Crc32::update(0, bytes.begin(), static_cast<std::size_t>(bytes.size())));
}
