// libFuzzer harness: arbitrary bytes through MemorySource to the csv decoder
// (its three formats, both compat modes, blocks of varying size). Checks: no
// crash, n <= capacity, every block's units within its limit, the report's
// counts consistent (samples given = samples counted, samples + skipped <=
// units, no sample without a unit). And the lines parsed in place give
// what the general line parser gives: a second decoder with option fast = 0
// reads the same bytes in the same blocks, and every block, value (bit for
// bit), counter and note must be the same. Last, the number at the start
// of the input (every number rule): scan_plain_number() and plain_value() agree with
// parse_number() whenever they take it.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "gravcal/decoders/decode_csv.hpp"

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_report(const gravcal::Report& a, const gravcal::Report& b) {
  return a.units == b.units && a.samples == b.samples && a.skipped == b.skipped &&
         a.gaps == b.gaps && same_bits(a.gap_seconds, b.gap_seconds) &&
         a.truncated == b.truncated && a.read_error == b.read_error &&
         a.counters == b.counters && a.notes == b.notes && a.notes_total == b.notes_total;
}

// The fast number parser against the exact one on the first field-like run
// of the input (up to a separator or 40 bytes), for both modes.
void check_number(const std::uint8_t* data, std::size_t size, char dec) {
  std::size_t n = 0;
  while (n < size && n < 40 && data[n] != ',' && data[n] != '\n') ++n;
  std::string field(reinterpret_cast<const char*>(data), n);
  std::string text = field + '\n' + std::string(8, '\0');
  gravcal::csv_text::PlainNumber pn;
  const char* b = text.data();
  const char* e = gravcal::csv_text::scan_plain_number(b, dec, pn);
  if (e == nullptr || e != b + n) return;  // not taken, or not the whole field
  for (int rule = 0; rule <= 2; ++rule) {
    double fast = 0, exact = 0;
    const bool ok_fast = gravcal::csv_text::plain_value(pn, b, e, dec, rule, fast);
    const bool ok_exact = gravcal::csv_text::parse_number(b, e, dec, rule, exact);
    if (ok_fast != ok_exact || (ok_fast && !same_bits(fast, exact))) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  check_number(data + 1, size - 1, (mode & 1) ? '.' : ',');
  gravcal::MemorySource src(data + 1, size - 1), src_ref(data + 1, size - 1);
  gravcal::Options o;
  o.set("compat", (mode & 1) ? 1.0 : 0.0);
  if (mode & 2) o.set("sf", 30.0);
  o.set("buffer", 64.0 + 61.0 * (mode >> 3));  // small buffers: lines cross refills
  gravcal::Options o_ref = o;
  o_ref.set("fast", 0.0);
  std::string format = (mode & 4) ? "actigraph_csv" : "csv";
  // GGIR's ad hoc csv (sf given, bits 1, 2 and 7 set): its layout and
  // units from the other bits (lines skipped, mg, bits, time and
  // temperature columns)
  if ((mode & 0x86) == 0x86) {
    format = "adhoc_csv";
    o.set("skip", static_cast<double>((mode >> 3) & 1));
    if (mode & 0x10) o.set("acc_div", 1000.0);
    if (mode & 0x20) {
      o.set("bit", 1.0);
      o.set("bit_pow", 4096.0);
      o.set("bit_range", 8.0);
      o.set("temp_unit", 2.0);
    }
    if (mode & 0x40) {
      o.set("col_time", 1.0);
      o.set("time_div", 1000.0);
      o.set("col_x", 2.0);
      o.set("col_y", 3.0);
      o.set("col_z", 4.0);
      o.set("col_temp", 5.0);
    }
    o_ref = o;
    o_ref.set("fast", 0.0);
  }
  gravcal::CsvDecoder dec(src, o, format), ref(src_ref, o_ref, format);
  const bool opened = dec.open();
  if (opened != ref.open() || dec.error() != ref.error()) __builtin_trap();
  if (!opened) {
    if (dec.error().empty()) __builtin_trap();
    return 0;
  }
  const std::size_t cap = 1 + (mode >> 3);  // 1 .. 32
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  std::vector<double> rx(cap), ry(cap), rz(cap), rt(cap), rtm(cap);
  std::int64_t given = 0, units = 0;
  for (int calls = 0; calls < 100000 && !dec.done(); ++calls) {
    gravcal::SampleBuffer b, r;
    b.x = x.data(); b.y = y.data(); b.z = z.data(); b.t = t.data(); b.time = tm.data();
    r.x = rx.data(); r.y = ry.data(); r.z = rz.data(); r.t = rt.data(); r.time = rtm.data();
    b.capacity = r.capacity = cap;
    const std::int64_t max_units = (calls % 3 == 0) ? -1 : 1 + calls % 7;
    const std::int64_t u = dec.read(b, max_units);
    if (b.n > cap) __builtin_trap();
    if (u < 0 || (max_units >= 0 && u > max_units)) __builtin_trap();
    if (static_cast<std::int64_t>(b.n) > u) __builtin_trap();  // one sample per line at most
    given += static_cast<std::int64_t>(b.n);
    units += u;
    if (u == 0 && b.n == 0 && !dec.done()) __builtin_trap();  // no progress
    // the general parser, block for block
    if (ref.read(r, max_units) != u || r.n != b.n || ref.done() != dec.done()) __builtin_trap();
    for (std::size_t i = 0; i < b.n; ++i) {
      if (!same_bits(x[i], rx[i]) || !same_bits(y[i], ry[i]) || !same_bits(z[i], rz[i]) ||
          !same_bits(t[i], rt[i]) || !same_bits(tm[i], rtm[i])) {
        __builtin_trap();
      }
    }
  }
  const gravcal::Report& r = dec.report();
  if (r.samples != given || r.units != units) __builtin_trap();
  if (r.samples + r.skipped > r.units) __builtin_trap();
  if (r.gaps < 0 || !(r.gap_seconds >= 0)) __builtin_trap();
  if (r.notes.size() > gravcal::Report::max_notes) __builtin_trap();
  if (!same_report(r, ref.report())) __builtin_trap();
  return 0;
}
