// Rcpp glue: gzip of bytes from R on two threads, for g.part1()'s meta
// files (R's save() compresses on one). Converts and calls, nothing more.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>
#include <zlib.h>

#include <algorithm>
#include <cstddef>
#include <exception>
#include <string>
#include <system_error>
#include <vector>

#include "gravcal/host/threads.hpp"

namespace {

// n bytes as one whole gzip member (RFC 1952) at zlib's `level`; "" and
// the error's text in `err` where zlib fails.
std::vector<unsigned char> gzip_member(const unsigned char* p, std::size_t n, int level,
                                       std::string* err) {
  std::vector<unsigned char> out;
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    *err = "zlib could not start a gzip stream";
    return out;
  }
  const std::size_t piece = std::size_t{1} << 30;  // (zlib counts in 32 bits)
  std::size_t at = 0;
  unsigned char buf[1 << 16];
  for (;;) {
    const std::size_t take = n - at < piece ? n - at : piece;
    z.next_in = const_cast<unsigned char*>(p + at);
    z.avail_in = static_cast<uInt>(take);
    at += take;
    const int flush = at == n ? Z_FINISH : Z_NO_FLUSH;
    int rc = Z_OK;
    do {
      z.next_out = buf;
      z.avail_out = sizeof buf;
      rc = deflate(&z, flush);
      if (rc == Z_STREAM_ERROR) break;
      out.insert(out.end(), buf, buf + (sizeof buf - z.avail_out));
    } while (z.avail_out == 0);
    if (rc == Z_STREAM_ERROR) {
      *err = "zlib failed while compressing";
      break;
    }
    if (flush == Z_FINISH) break;
  }
  deflateEnd(&z);
  if (!err->empty()) out.clear();
  return out;
}

}  // namespace

// `bytes` gzipped at zlib's `level` (R's save(): 6): cut in `threads` (1 or
// 2) parts of about equal size (one where they are under 1 MB), each a
// whole gzip member made on a thread of its own, the members one after the
// other: one gzip file (RFC 1952's members in a row), which R's gzfile()
// and load() read as the bytes whole, as gzip itself does.
// [[Rcpp::export(rng = false)]]
Rcpp::RawVector gc_gzip(const Rcpp::RawVector& bytes, int level, int threads) {
  if (level < 1 || level > 9) Rcpp::stop("level must be 1 to 9");
  if (threads < 1) Rcpp::stop("threads must be at least 1");
  const unsigned char* p = RAW(bytes);
  const std::size_t n = static_cast<std::size_t>(Rf_xlength(bytes));
  const std::size_t parts = threads >= 2 && n >= (std::size_t{1} << 20) ? 2 : 1;
  const std::size_t cut = parts == 2 ? n / 2 : n;
  std::vector<unsigned char> z[2];
  std::string err[2];
  bool second_on_thread = false;
#ifndef GRAVCAL_NO_THREADS
  std::thread side;
  {
    const gravcal::JoinGuard join{side};
    if (parts == 2) {
      try {
        side = std::thread([&]() {
          try {
            z[1] = gzip_member(p + cut, n - cut, level, &err[1]);
          } catch (const std::exception& e) {
            err[1] = e.what();  // (memory: nothing leaves a thread)
          }
        });
        second_on_thread = true;
      } catch (const std::system_error&) {
        // no thread: both parts on this one
      }
    }
    z[0] = gzip_member(p, cut, level, &err[0]);
  }
#else
  z[0] = gzip_member(p, cut, level, &err[0]);
#endif
  if (parts == 2 && !second_on_thread) z[1] = gzip_member(p + cut, n - cut, level, &err[1]);
  for (const std::string& e : err) {
    if (!e.empty()) Rcpp::stop(e);
  }
  Rcpp::RawVector out(static_cast<R_xlen_t>(z[0].size() + z[1].size()));
  unsigned char* o = RAW(out);
  for (const std::vector<unsigned char>& m : z) {
    if (!m.empty()) std::copy(m.begin(), m.end(), o);
    o += m.size();
  }
  return out;
}
