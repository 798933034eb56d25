// libFuzzer harness: arbitrary bytes through MemorySource to the csv decoder
// (both formats, both compat modes, blocks of varying size). Checks: no
// crash, n <= capacity, every block's units within its limit, the report's
// counts consistent (samples given = samples counted, samples + skipped <=
// units, no sample without a unit).
#include <cstdint>
#include <vector>

#include "gravcal/decode_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  gravcal::MemorySource src(data + 1, size - 1);
  gravcal::Options o;
  o.set("compat", (mode & 1) ? 1.0 : 0.0);
  if (mode & 2) o.set("sf", 30.0);
  o.set("buffer", 64.0 + 61.0 * (mode >> 3));  // small buffers: lines cross refills
  gravcal::CsvDecoder dec(src, o, (mode & 4) ? "actigraph_csv" : "csv");
  if (!dec.open()) {
    if (dec.error().empty()) __builtin_trap();
    return 0;
  }
  const std::size_t cap = 1 + (mode >> 3);  // 1 .. 32
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  std::int64_t given = 0, units = 0;
  for (int calls = 0; calls < 100000 && !dec.done(); ++calls) {
    gravcal::SampleBuffer b;
    b.x = x.data(); b.y = y.data(); b.z = z.data(); b.t = t.data(); b.time = tm.data();
    b.capacity = cap;
    const std::int64_t max_units = (calls % 3 == 0) ? -1 : 1 + calls % 7;
    const std::int64_t u = dec.read(b, max_units);
    if (b.n > cap) __builtin_trap();
    if (u < 0 || (max_units >= 0 && u > max_units)) __builtin_trap();
    if (static_cast<std::int64_t>(b.n) > u) __builtin_trap();  // one sample per line at most
    given += static_cast<std::int64_t>(b.n);
    units += u;
    if (u == 0 && b.n == 0 && !dec.done()) __builtin_trap();  // no progress
  }
  const gravcal::Report& r = dec.report();
  if (r.samples != given || r.units != units) __builtin_trap();
  if (r.samples + r.skipped > r.units) __builtin_trap();
  if (r.gaps < 0 || !(r.gap_seconds >= 0)) __builtin_trap();
  if (r.notes.size() > gravcal::Report::max_notes) __builtin_trap();
  return 0;
}
