// g.getmeta()'s first block read beside the pump (R/meta-ahead.R).
#ifndef GRAVCAL_GLUE_META_AHEAD_H
#define GRAVCAL_GLUE_META_AHEAD_H

#include <Rcpp.h>

#include <functional>

namespace gravcal_glue {

// The read of gc_pump()'s `beside` (list(store, decoder, units, chunk,
// want_time): gc_meta_store_read()'s arguments), checked and set up on R's
// thread, to run on another: it touches nothing of R's, and leaves its
// result (the rows read, or its error) in the store, where the next
// gc_meta_store_read() with the same arguments takes it. The store and the
// decoder must outlive the run (R holds them; the pump joins the thread
// before it returns).
std::function<void()> meta_read_beside(const Rcpp::List& spec);

}  // namespace gravcal_glue

#endif  // GRAVCAL_GLUE_META_AHEAD_H
