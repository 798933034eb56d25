// The one pump (pipeline.hpp) and GGIR's procedure (ggir_procedure.hpp)
// without R: the same windows whether a source lends its samples or writes
// them where the stage asks, in blocks of any size; the procedure recovers
// a known miscalibration, and stops when its host says so.
#include "gravcal/fp_contract.hpp"  // first: see there

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "gravcal/decode.hpp"
#include "gravcal/ggir_procedure.hpp"
#include "gravcal/pipeline.hpp"

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

int main() {
  test_zone();
  test_pump();
  test_procedure();
  std::printf("pipeline: %s\n", failures ? "FAILED" : "all checks passed");
  return failures ? 1 : 0;
}
