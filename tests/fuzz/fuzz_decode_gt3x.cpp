// libFuzzer harness: arbitrary bytes as a .gt3x (zip) through MemorySource,
// read to the end in blocks of arbitrary size with arbitrary options. Checks
// no crash, n <= capacity, units <= max_units, finite samples with times,
// and report counts that add up. The first byte chooses options and block
// sizes; the rest is the file. Deflated entries go through zlib as in R.
#include <cmath>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/decoders/decode_gt3x.hpp"
#include "../../src/zip_inflate.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t mode = in.byte();
  const std::uint8_t block = in.byte();
  gravcal::MemorySource src(in.p, in.n);
  gravcal::Options opts;
  opts.set("compat", (mode & 1) ? 1.0 : 0.0);
  opts.set("impute_zeroes", (mode & 2) ? 1.0 : 0.0);
  gravcal_glue::ZlibInflater inflater;
  gravcal::Gt3xDecoder dec(src, opts, &inflater);
  if (!dec.open()) {
    if (dec.error().empty()) __builtin_trap();
    return 0;
  }
  const std::size_t cap = 1 + block % 97 + ((mode & 4) ? 300 : 0);
  const std::int64_t max_units = (mode & 8) ? -1 : 1 + (block >> 4);
  std::vector<double> x(cap), y(cap), z(cap), t(cap);
  std::int64_t total = 0, units = 0;
  // bounded: a file may ask for up to 2^31 imputed zeros, given in chunks
  for (int call = 0; call < 2000 && !dec.done(); ++call) {
    gravcal::SampleBuffer out;
    out.x = x.data();
    out.y = y.data();
    out.z = z.data();
    out.time = t.data();
    out.capacity = cap;
    const std::int64_t u = dec.read(out, max_units);
    if (out.n > cap || u < 0) __builtin_trap();
    if (max_units >= 0 && u > max_units) __builtin_trap();
    for (std::size_t i = 0; i < out.n; ++i) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i])) __builtin_trap();
      if (std::isnan(t[i])) __builtin_trap();
    }
    total += static_cast<std::int64_t>(out.n);
    units += u;
    if (out.n == 0 && u == 0 && !dec.done()) __builtin_trap();  // no progress
  }
  const gravcal::Report& r = dec.report();
  if (r.samples != total || r.units != units) __builtin_trap();
  if (r.skipped < 0 || r.gaps < 0 || !(r.gap_seconds >= 0)) __builtin_trap();
  if (r.notes.size() > gravcal::Report::max_notes) __builtin_trap();
  return 0;
}
