// libFuzzer harness: the Movisens decoder on arbitrary bytes. The input is
// a mode byte, then unisens.xml (its length in two bytes), temp.bin (its
// length in two bytes) and acc.bin (the rest). Bit 0 of the mode replaces
// the xml by a valid one whose data types, rates, lsbValue and baseline
// come from the next bytes, so that the fuzzer reaches the samples; bit 1
// drops temp.bin; bit 2 picks the interpolation (GGIR's interpolationType
// 2); bits 3-4 the block (GGIR's, or a few samples, so that many blocks and
// their temperature ranges are tried), bit 5 the buffer, bit 6 the units
// a call and bit 7 gravcal's own reading (compat = 0). Checks: no
// crash, no write past the buffer, progress on every call, no more samples
// than acc.bin holds whole frames of, finite acceleration when lsbValue and
// baseline are, report counts consistent with what was given, nothing
// after the end.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/decoders/decode_movisens.hpp"

#define CHECK(cond)                                                              \
  do {                                                                           \
    if (!(cond)) {                                                               \
      std::fprintf(stderr, "invariant failed, line %d: %s\n", __LINE__, #cond); \
      __builtin_trap();                                                          \
    }                                                                            \
  } while (0)

static std::string valid_xml(FuzzInput& in) {
  static const char* rates[] = {"64", "1", "2", "0.5", "32", "100", "0", "-1", "x", "1e308"};
  static const char* lsbs[] = {"0.00048828125", "1", "0.1", "-2", "1e-300", "nan"};
  const std::uint8_t a = in.byte(), b = in.byte(), c = in.byte();
  std::string x = "<?xml version=\"1.0\"?>\n<unisens xmlns=\"http://www.unisens.org/unisens2.0\" "
                  "timestampStart=\"2023-05-11T09:00:00.000\">\n";
  x += std::string("<signalEntry id=\"acc.bin\" dataType=\"") + ((a & 1) ? "int32" : "int16") +
       "\" sampleRate=\"" + rates[(a >> 1) % 10] + "\" lsbValue=\"" + lsbs[(a >> 5) % 6] +
       "\" baseline=\"" + std::to_string(static_cast<int>(b) - 128) +
       "\"><binFileFormat endianess=\"LITTLE\"/><channel name=\"accX\"/><channel name=\"accY\"/>"
       "<channel name=\"accZ\"/></signalEntry>\n";
  x += std::string("<signalEntry id=\"temp.bin\" dataType=\"") + ((c & 1) ? "int32" : "int16") +
       "\" sampleRate=\"" + rates[(c >> 1) % 10] + "\" lsbValue=\"0.1\"><binFileFormat/>" +
       ((c & 32) ? "<channel name=\"other\"/>" : "") + "<channel name=\"temp\"/></signalEntry>\n";
  return x + "</unisens>\n";
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t mode = in.byte();
  std::string xml;
  if (mode & 1) {
    xml = valid_xml(in);
  } else {
    std::size_t k = static_cast<std::size_t>(in.byte()) | (static_cast<std::size_t>(in.byte()) << 8);
    if (k > in.n) k = in.n;
    xml.assign(reinterpret_cast<const char*>(in.p), k);
    in.p += k;
    in.n -= k;
  }
  std::size_t kt = static_cast<std::size_t>(in.byte()) | (static_cast<std::size_t>(in.byte()) << 8);
  if (kt > in.n) kt = in.n;
  const std::vector<unsigned char> temp(in.p, in.p + kt);
  in.p += kt;
  in.n -= kt;
  const std::vector<unsigned char> acc(in.p, in.p + in.n);

  gravcal::MemorySource acc_src(acc.data(), acc.size());
  std::unique_ptr<gravcal::ByteSource> temp_src;
  if (!(mode & 2)) temp_src.reset(new gravcal::MemorySource(temp.data(), temp.size()));
  gravcal::Options opts;
  opts.set("interpolation", (mode & 4) ? 2.0 : 1.0);
  opts.set("compat", (mode & 128) ? 0.0 : 1.0);
  const int blk = (mode >> 3) & 3;
  if (blk) opts.set("block_samples", blk == 1 ? 1.0 : blk == 2 ? 7.0 : 130.0);
  gravcal::MovisensDecoder dec(acc_src, opts, xml, std::move(temp_src));
  if (!dec.open()) {
    CHECK(!dec.error().empty());
    CHECK(dec.done());
    return 0;
  }
  CHECK(dec.info().sf > 0 && std::isfinite(dec.info().sf));
  const std::size_t cap = (mode & 32) ? 5 : 512;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  std::int64_t samples = 0, units = 0;
  while (!dec.done()) {
    gravcal::SampleBuffer out;
    out.x = x.data();
    out.y = y.data();
    out.z = z.data();
    out.t = t.data();
    out.time = tm.data();
    out.capacity = cap;
    const std::int64_t u = dec.read(out, (mode & 64) ? 3 : -1);
    CHECK(out.n <= cap && u >= 0);
    CHECK(u == static_cast<std::int64_t>(out.n));
    CHECK(!(u == 0 && !dec.done()));  // no progress
    samples += static_cast<std::int64_t>(out.n);
    units += u;
  }
  CHECK(samples <= static_cast<std::int64_t>(acc.size() / 6));
  const gravcal::Report& r = dec.report();
  CHECK(r.samples == samples && r.units == units);
  CHECK(r.notes.size() <= gravcal::Report::max_notes);
  gravcal::SampleBuffer out;
  out.x = x.data();
  out.y = y.data();
  out.z = z.data();
  out.capacity = cap;
  CHECK(dec.read(out, -1) == 0 && out.n == 0);
  return 0;
}
