// The one pump (pipeline.hpp) and GGIR's procedure (ggir_procedure.hpp)
// without R: the same windows whether a source lends its samples or writes
// them where the stage asks, in blocks of any size; the procedure recovers
// a known miscalibration, and stops when its host says so. The Movisens
// decoder's samples and temperatures against a sample-by-sample replay of
// unisensR and GGIR's g.readtemp_movisens, in runs of any length.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_movisens.hpp"
#include "gravcal/ggir/ggir_procedure.hpp"
#include "gravcal/ggir/pipeline.hpp"

static int failures = 0;
#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      std::printf("FAILED %s:%d: %s\n", __FILE__, __LINE__, #cond);   \
      ++failures;                                                     \
    }                                                                 \
  } while (0)

// Columns that must be read into the stage's buffer (a decoder's path).
class WrittenColumns : public gravcal::ColumnsSource {
 public:
  using ColumnsSource::ColumnsSource;
  bool borrow(gravcal::Chunk&, std::int64_t, std::int64_t&) override { return false; }
};

struct Recording {
  std::vector<double> x, y, z, t;
};

// `hours` at `sf` Hz: rest in a new orientation every half hour, a minute of
// movement between, measured by a sensor with scale s and offset o:
// v = a / s - o (GGIR's model: a = (v + o) s).
static Recording simulate(double hours, double sf, const double* s, const double* o) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003), tilt(0.0, 0.3);
  const std::size_t n = static_cast<std::size_t>(hours * 3600 * sf);
  const std::size_t period = static_cast<std::size_t>(1800 * sf);
  Recording r;
  double g[3] = {0, 0, 1};
  for (std::size_t i = 0; i < n; ++i) {
    if (i % period == 0) {
      double v[3] = {tilt(rng), tilt(rng), tilt(rng)};
      v[(i / period) % 3] += ((i / period) % 2) ? 1.0 : -1.0;
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int k = 0; k < 3; ++k) g[k] = v[k] / len;
    }
    const bool moving = i % period < static_cast<std::size_t>(60 * sf);
    double a[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = g[k] + noise(rng) + (moving ? 0.3 * std::sin(0.7 * static_cast<double>(i) + k) : 0.0);
    }
    r.x.push_back(a[0] / s[0] - o[0]);
    r.y.push_back(a[1] / s[1] - o[1]);
    r.z.push_back(a[2] / s[2] - o[2]);
    r.t.push_back(25.0 + 2.0 * std::sin(static_cast<double>(i) / (3600 * sf)));
  }
  return r;
}

static bool same(const gravcal::WindowStats& a, const gravcal::WindowStats& b) {
  bool ok = a.first == b.first && a.n == b.n && a.mean_norm == b.mean_norm;
  for (int k = 0; k < 3; ++k) ok = ok && a.mean[k] == b.mean[k] && a.sd[k] == b.sd[k];
  return ok;
}

// The segmenter through the pump, lent or written, in blocks of `units`.
static std::vector<gravcal::WindowStats> windows(const Recording& r, bool lend,
                                                 std::int64_t units) {
  gravcal::Segmenter seg(100.0, true);
  gravcal::SegmenterStage stage(seg, true);
  gravcal::ColumnsSource lent(r.x.data(), r.y.data(), r.z.data(), r.t.data(), r.x.size());
  WrittenColumns written(r.x.data(), r.y.data(), r.z.data(), r.t.data(), r.x.size());
  gravcal::Source& src = lend ? static_cast<gravcal::Source&>(lent) : written;
  std::vector<gravcal::WindowStats> out;
  auto sink = [&](const gravcal::WindowStats& w) { out.push_back(w); };
  for (;;) {
    const gravcal::PumpResult p = gravcal::pump(src, stage, units, sink, [] { return false; });
    if (p.done || p.units == 0) break;
  }
  return out;
}

static void test_pump() {
  const double s[3] = {1, 1, 1}, o[3] = {0, 0, 0};
  const Recording r = simulate(3, 10, s, o);
  const std::vector<gravcal::WindowStats> ref = windows(r, true, -1);
  CHECK(ref.size() == r.x.size() / 100);
  for (std::int64_t units : {1, 7, 99, 100, 101, 65537, 1 << 20}) {
    for (bool lend : {true, false}) {
      const std::vector<gravcal::WindowStats> w = windows(r, lend, units);
      bool ok = w.size() == ref.size();
      for (std::size_t i = 0; ok && i < w.size(); ++i) ok = same(w[i], ref[i]);
      CHECK(ok);
    }
  }
}

// A host without R: Eigen's least squares, rounding by powers of ten.
class PlainHost : public gravcal::GgirHost {
 public:
  double round_digits(double x, int digits) override {
    const double p = std::pow(10.0, digits);
    return std::round(x * p) / p;
  }
  void least_squares(double* X, const double* y, std::size_t n, int p, double* coef,
                     double* rsd) override {
    gravcal::EigenLeastSquares()(X, y, n, p, coef, rsd);
  }
  bool interrupted() override { return ++calls > stop_after; }
  std::int64_t calls = 0;
  std::int64_t stop_after = std::int64_t(1) << 40;  // (long: 32 bits on Windows)
};

static gravcal::GgirOutcome procedure(const Recording& r, bool compat, bool lend,
                                      PlainHost& host) {
  gravcal::GgirConfig c;
  c.compat = compat;
  c.sf = 10;
  c.block_units = 12 * 3600 * 10;
  c.minloadcrit = 24;
  gravcal::GgirProcedure proc(c, host);
  gravcal::ColumnsSource lent(r.x.data(), r.y.data(), r.z.data(), r.t.data(), r.x.size());
  WrittenColumns written(r.x.data(), r.y.data(), r.z.data(), r.t.data(), r.x.size());
  return proc.run(lend ? static_cast<gravcal::Source&>(lent) : written);
}

static void test_procedure() {
  const double s[3] = {1.02, 0.98, 1.01}, o[3] = {0.03, -0.02, 0.01};
  const Recording r = simulate(30, 10, s, o);
  for (bool compat : {true, false}) {
    PlainHost h1, h2;
    const gravcal::GgirOutcome a = procedure(r, compat, true, h1);
    const gravcal::GgirOutcome b = procedure(r, compat, false, h2);
    CHECK(a.qc == gravcal::GgirQc::done);
    CHECK(a.use_temp && a.temp_available && a.has_icp && a.icp.finite);
    for (int k = 0; k < 3; ++k) {
      CHECK(std::fabs(a.scale[k] - s[k]) < 2e-3);
      CHECK(std::fabs(a.offset[k] - o[k]) < 2e-3);
      CHECK(a.scale[k] == b.scale[k] && a.offset[k] == b.offset[k]);
    }
    CHECK(a.error_end < a.error_start && a.error_end < 0.01);
    CHECK(a.samples == static_cast<std::int64_t>(r.x.size()));
    // the reading stops after the block that reaches minloadcrit hours
    CHECK(a.blocks == 3 && a.nhoursused > 24);
  }
  // too short for GGIR's procedure (2 whole hours, 720 windows, not more
  // than minloadcrit - 21): every window back, no fit
  Recording short_r = r;
  for (auto* v : {&short_r.x, &short_r.y, &short_r.z, &short_r.t}) v->resize(9000 * 10);
  PlainHost h;
  gravcal::GgirConfig c;
  c.sf = 10;
  c.block_units = 12 * 3600 * 10;
  c.minloadcrit = 1000;
  gravcal::GgirProcedure proc(c, h);
  gravcal::ColumnsSource src(short_r.x.data(), short_r.y.data(), short_r.z.data(),
                             short_r.t.data(), short_r.x.size());
  const gravcal::GgirOutcome q = proc.run(src);
  CHECK(q.qc == gravcal::GgirQc::no_data && !q.has_icp && q.has_table);
  CHECK(q.table_rows.size() == 720 && q.table_columns == 8);
  // the host's interrupt ends the run, marked
  PlainHost stop;
  stop.stop_after = 1;
  const gravcal::GgirOutcome z = procedure(r, true, false, stop);
  CHECK(z.stopped);
}

// A zone's offsets by calendar time (decode.hpp's ZoneTable, as R/zone.R
// hands them to the .cwa and csv decoders): the step at or before a time,
// the first step's offset before it, the marked spans; a table that does
// not hold together is no table.
static void test_zone() {
  gravcal::Options o;
  o.set("tz_n", 3);
  o.set("tz_at_0", 0);
  o.set("tz_off_0", 0);
  o.set("tz_at_1", 100);
  o.set("tz_off_1", 3600);
  o.set("tz_at_2", 200);
  o.set("tz_off_2", 0);
  o.set("tz_amb_n", 1);
  o.set("tz_amb_lo_0", 150);
  o.set("tz_amb_hi_0", 160);
  const gravcal::ZoneTable z(o);
  CHECK(!z.empty());
  CHECK(z.offset(-5) == 0);
  CHECK(z.offset(99.5) == 0);
  CHECK(z.offset(100) == 3600);
  CHECK(z.offset(199.5) == 3600);
  CHECK(z.offset(200) == 0);
  CHECK(z.offset(1e9) == 0);
  CHECK(!z.ambiguous(149.5));
  CHECK(z.ambiguous(150));
  CHECK(z.ambiguous(159.9));
  CHECK(!z.ambiguous(160));
  gravcal::Options none;
  CHECK(gravcal::ZoneTable(none).empty());
  CHECK(gravcal::ZoneTable(none).offset(12345) == 0);
  gravcal::Options big;
  big.set("tz_n", 5000);  // more than it holds: none
  CHECK(gravcal::ZoneTable(big).empty());
}

// The Movisens decoder, read in runs of `cap` samples, against a replay of
// what GGIR gets sample by sample (from the format's description: unisensR's
// (v - baseline) * lsbValue; g.readtemp_movisens' range of temperature
// samples per block, R's seq(1, m, length.out = n) and GGIRread::resample's
// interpolation, found afresh for each sample). Temperature rates below,
// at and above the acceleration's (several temperature samples per
// acceleration sample), blocks of a few samples to many, linear and
// nearest, rounded twice and fused.
static void le_put(std::vector<unsigned char>& b, long v, int size) {
  for (int k = 0; k < size; ++k) b.push_back(static_cast<unsigned char>((v >> (8 * k)) & 0xff));
}

static void test_movisens() {
  const double sf = 64;
  const std::int64_t n = 64 * 90 + 37;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> acc_v(-4000, 4000), temp_v(200, 380);
  std::vector<unsigned char> acc;
  std::vector<long> raw;
  for (std::int64_t i = 0; i < 3 * n; ++i) {
    raw.push_back(acc_v(rng));
    le_put(acc, raw.back(), 2);
  }
  const char* rates[] = {"1", "0.7", "3.3", "64", "100", "250"};
  const double rate_v[] = {1, 0.7, 3.3, 64, 100, 250};
  const double blocks[] = {7, 130, 1000, 64.0 * 60 * 1440 / 2};
  const std::size_t caps[] = {1, 17, 4096};
  int compared = 0;
  for (int ri = 0; ri < 6; ++ri) {
    const double r = rate_v[ri];
    // enough temperature samples for the whole recording at rate r
    const std::int64_t nt = static_cast<std::int64_t>(std::ceil(n / sf * std::max(r, 1.0))) + 2;
    std::vector<unsigned char> temp;
    std::vector<long> traw;
    for (std::int64_t i = 0; i < nt; ++i) {
      traw.push_back(temp_v(rng));
      le_put(temp, traw.back(), 2);
    }
    const std::string xml =
        std::string("<unisens timestampStart=\"2024-01-01T00:00:00.000\">"
                    "<signalEntry id=\"acc.bin\" dataType=\"int16\" sampleRate=\"64\" "
                    "lsbValue=\"0.00048828125\" baseline=\"3\"><binFileFormat/>"
                    "<channel name=\"x\"/><channel name=\"y\"/><channel name=\"z\"/></signalEntry>"
                    "<signalEntry id=\"temp.bin\" dataType=\"int16\" sampleRate=\"") +
        rates[ri] + "\" lsbValue=\"0.1\"><binFileFormat/><channel name=\"temp\"/></signalEntry></unisens>";
    for (double blk : blocks) {
      for (int interp = 1; interp <= 2; ++interp) {
        for (int fused = 0; fused <= 1; ++fused) {
          // the replay
          std::vector<double> want_t(static_cast<std::size_t>(n));
          for (std::int64_t from = 0; from < n; from += static_cast<std::int64_t>(blk)) {
            const std::int64_t to = std::min(n, from + static_cast<std::int64_t>(blk));
            const std::int64_t bn = to - from;
            auto first_last = [&](double rr, std::int64_t& a, std::int64_t& b) {
              a = static_cast<std::int64_t>(std::ceil(static_cast<double>(from + 1) / sf * rr));
              b = static_cast<std::int64_t>(std::ceil(static_cast<double>(to) / sf * rr));
            };
            std::int64_t a = 0, b = 0;
            first_last(1.0, a, b);
            if (r != 1.0) first_last(r, a, b);
            const std::int64_t m = b - a + 1;
            for (std::int64_t q = 0; q < bn; ++q) {
              double v;
              if (m == 1) {
                v = traw[a - 1] * 0.1;
              } else {
                const double g = q == 0 ? 1.0 : q == bn - 1 ? static_cast<double>(m)
                               : 1 + q * ((static_cast<double>(m) - 1) / static_cast<double>(bn - 1));
                std::int64_t j = 1;  // the interval (j, j + 1] of positions 1..m
                while (j < m - 1 && static_cast<double>(j + 1) < g) ++j;
                double u = (g - static_cast<double>(j)) /
                           (static_cast<double>(j + 1) - static_cast<double>(j));
                const double v0 = traw[a - 1 + j - 1] * 0.1, v1 = traw[a - 1 + j] * 0.1;
                if (interp == 2) {
                  // u is then -0, 0 or 1, so u (v1 - v0) is exact and
                  // fused or not is the same number (written unfused here:
                  // mingw-w64's std::fma is not correctly rounded, e.g.
                  // fma(1, 0.19999999999999998, 0.1) = 0.29999999999999993)
                  u = (u < 0 || u > 1) ? 0 : std::ceil(u - 0.5);
                  v = u * (v1 - v0) + v0;
                } else {
                  v = fused ? std::fma(u, v1 - v0, v0) : u * (v1 - v0) + v0;
                }
              }
              want_t[static_cast<std::size_t>(from + q)] = v;
            }
          }
          for (std::size_t cap : caps) {
            gravcal::MemorySource as(acc.data(), acc.size());
            std::unique_ptr<gravcal::ByteSource> ts(new gravcal::MemorySource(temp.data(), temp.size()));
            gravcal::Options o;
            o.set("compat", 1.0);
            o.set("interpolation", static_cast<double>(interp));
            o.set("resample_fused", static_cast<double>(fused));
            o.set("block_samples", blk);
            gravcal::MovisensDecoder dec(as, o, xml, std::move(ts));
            CHECK(dec.open());
            CHECK(dec.info().has_temperature);
            std::vector<double> x(cap), y(cap), z(cap), t(cap);
            std::int64_t k = 0;
            bool ok = true;
            while (!dec.done()) {
              gravcal::SampleBuffer buf;
              buf.x = x.data();
              buf.y = y.data();
              buf.z = z.data();
              buf.t = t.data();
              buf.capacity = cap;
              // units per call: all that fit, or a few
              const std::int64_t got = dec.read(buf, (k % 3 == 1) ? 5 : -1);
              if (got <= 0) break;
              for (std::size_t i = 0; i < buf.n; ++i, ++k) {
                const double* col[3] = {x.data(), y.data(), z.data()};
                for (int c = 0; c < 3; ++c) {
                  ok = ok && col[c][i] == (static_cast<double>(raw[3 * k + c]) - 3) * 0.00048828125;
                }
                ok = ok && std::memcmp(&t[i], &want_t[static_cast<std::size_t>(k)], sizeof(double)) == 0;
              }
            }
            CHECK(k == n);
            CHECK(ok);
            if (!ok) {
              std::printf("  movisens: rate %s, block %g, interpolation %d, fused %d, run %zu\n",
                          rates[ri], blk, interp, fused, cap);
            }
            ++compared;
          }
        }
      }
    }
  }
  CHECK(compared == 6 * 4 * 2 * 2 * 3);
}

int main() {
  test_movisens();
  test_zone();
  test_pump();
  test_procedure();
  std::printf("pipeline: %s\n", failures ? "FAILED" : "all checks passed");
  return failures ? 1 : 0;
}
