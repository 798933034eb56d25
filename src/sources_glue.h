// The sample sources the glue hands to the core's pump (pipeline.hpp): an
// open device file, columns of R vectors, or blocks that an R function
// reads (GGIR's own readers). Each box keeps alive what its source reads.
#ifndef GRAVCAL_GLUE_SOURCES_H
#define GRAVCAL_GLUE_SOURCES_H

#include <Rcpp.h>

#include <memory>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/ggir/pipeline.hpp"

namespace gravcal_glue {

// An open device file: the byte source and the decoder on it.
struct OpenFile {
  std::unique_ptr<gravcal::ByteSource> bytes;
  std::unique_ptr<gravcal::Decoder> decoder;
};

inline OpenFile* open_file(SEXP ptr) {
  Rcpp::XPtr<OpenFile> p(ptr);
  if (p.get() == nullptr) Rcpp::stop("the file is closed");
  return p.get();
}

// Numeric column `v` (NULL allowed when `optional`) of length n.
inline const double* column(SEXP v, R_xlen_t n, bool optional, const char* what) {
  if (Rf_isNull(v) && optional) return nullptr;
  if (TYPEOF(v) != REALSXP) Rcpp::stop("%s must be a double vector", what);
  if (Rf_xlength(v) != n) Rcpp::stop("%s has the wrong length", what);
  return REAL(v);
}

// Blocks of samples from an R function: fetch() returns NULL at the end or
// list(x, y, z, temperature (or NULL), last); one block is one unit. The
// first block is given when the source is made (so that whether it has a
// temperature is known).
class RBlockSource : public gravcal::Source {
 public:
  RBlockSource(Rcpp::List first, Rcpp::Function fetch) : fetch_(fetch) { take(first); }
  bool borrow(gravcal::Chunk& c, std::int64_t max_units, std::int64_t& units) override {
    units = 0;
    c = gravcal::Chunk();
    if (max_units == 0 || done_) return true;
    if (!fresh_) {
      SEXP b = fetch_();
      if (Rf_isNull(b)) {
        done_ = true;
        return true;
      }
      take(Rcpp::List(b));
    }
    fresh_ = false;
    cols_.borrow(c, -1, units);
    units = 1;
    if (last_) done_ = true;
    return true;
  }
  std::int64_t read(gravcal::SampleBuffer&, std::int64_t) override {
    Rcpp::stop("blocks from R are lent, not read");
  }
  bool done() const override { return done_; }
  bool has_temperature() const override { return temp_; }

 private:
  void take(Rcpp::List b) {
    block_ = b;
    const SEXP x = b["x"];
    const R_xlen_t n = Rf_xlength(x);
    const double* t = column(b["temperature"], n, true, "temperature");
    cols_.reset(column(x, n, false, "x"), column(b["y"], n, false, "y"),
                column(b["z"], n, false, "z"), t, static_cast<std::size_t>(n));
    temp_ = temp_ || t != nullptr;
    last_ = Rcpp::as<bool>(b["last"]);
    fresh_ = true;
  }
  Rcpp::Function fetch_;
  Rcpp::List block_;
  gravcal::ColumnsSource cols_;
  bool temp_ = false, last_ = false, fresh_ = false, done_ = false;
};

// A source for the pump, with what it reads kept alive.
struct SourceBox {
  std::unique_ptr<gravcal::Source> src;
  Rcpp::RObject keep;
};

}  // namespace gravcal_glue

#endif
