// gravcal: the window table of GGIR's auto-calibration procedure
// (ggir_procedure.hpp), GGIR 3.3's g.calibrate's `features`: one row per
// 10 s window of the recording read so far.
//
// The procedure's stages [3] and [4] (first part) live here:
//   [3] a block's windows, held while the block is read (with the rest
//       rule's flag), go into the table once the block's temperature check
//       has decided whether its temperature is used: mean norm, means, sds
//       and, when the recording has a temperature, the temperature (or
//       GGIR's fill when it is not used); own mode's guards mark the rest
//       windows they leave out;
//   [4] the filters before a fit: missing values, GGIR's fill value,
//       duplicate windows; then the rest windows to fit, the first window
//       left out.
// The procedure decides when to fit, whether there is enough data, and
// fits; this class only keeps and filters the rows.
#ifndef GRAVCAL_GGIR_WINDOW_TABLE_HPP
#define GRAVCAL_GGIR_WINDOW_TABLE_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gravcal/ggir/ggir_blocks.hpp"
#include "gravcal/ggir/ggir_config.hpp"
#include "gravcal/mcu/window_stats.hpp"

namespace gravcal {

// Why own mode's guards leave a rest window out (none: kept).
enum GgirWhy : unsigned char { why_none = 0, why_norm = 1, why_clipped = 2, why_identical = 3 };

class GgirWindowTable {
 public:
  explicit GgirWindowTable(const GgirConfig& cfg) : cfg_(cfg) {
    rule_.max_sd = cfg_.max_sd;
    rule_.max_abs_mean = cfg_.max_abs_mean;
  }

  // [1] a new block: its windows are held until add_block()
  void start_block() { block_.clear(); }

  // [1] one window of the block being read, with the rest rule's flag
  void hold(const WindowStats& w) { block_.push_back(Row{w, is_rest(w, rule_)}); }

  // [3] the held windows into the table: the temperature column only when
  // the recording has one (temp_available), GGIR's fill in it when the
  // temperature is not used
  void add_block(bool temp_available, bool use_temp) {
    for (const Row& r : block_) {
      const WindowStats& w = r.w;
      col_[0].push_back(w.mean_norm);
      for (int a = 0; a < 3; ++a) col_[1 + a].push_back(w.mean[a]);
      for (int a = 0; a < 3; ++a) col_[4 + a].push_back(w.sd[a]);
      if (temp_available) col_[7].push_back(use_temp ? w.temperature : cfg_.temp_missing);
      rest_.push_back(r.rest);
      why_.push_back(static_cast<unsigned char>(cfg_.compat || !r.rest ? why_none : guard(w)));
    }
  }

  // windows in the table
  std::size_t size() const { return col_[0].size(); }

  // the rows `rows` (0-based) of the first nc columns (0: mean norm, 1-3:
  // means, 4-6: sds, 7: temperature) into out, column-major
  void copy(const std::vector<std::size_t>& rows, int nc, std::vector<double>& out) const {
    const std::size_t n = rows.size();
    out.assign(static_cast<std::size_t>(nc) * n, 0.0);
    for (int c = 0; c < nc; ++c) {
      for (std::size_t i = 0; i < n; ++i) out[static_cast<std::size_t>(c) * n + i] = col_[c][rows[i]];
    }
  }

  // [4] the rows (0-based) a fit may look at: without missing values,
  // without GGIR's fill value (compatible mode), duplicates removed.
  // excluded[k]: own mode's rest windows among them that its guards leave
  // out, by reason (GgirWhy - 1), counted before the duplicate filter
  // (which also drops all but the last window of a run of equal windows,
  // as a stuck sensor's).
  std::vector<std::size_t> usable(std::int64_t excluded[3]) const {
    const std::size_t N = col_[0].size();
    std::vector<std::size_t> idx;
    idx.reserve(N);
    for (std::size_t r = 0; r < N; ++r) {
      if (std::isnan(col_[3][r]) || std::isnan(col_[0][r])) continue;
      // GGIR also drops a window whose mean norm equals its table's fill
      if (cfg_.compat && col_[0][r] == cfg_.fill) continue;
      idx.push_back(r);
    }
    for (int k = 0; k < 3; ++k) excluded[k] = 0;
    for (const std::size_t r : idx) {
      if (rest_[r] && why_[r] != why_none) ++excluded[why_[r] - 1];
    }
    if (idx.size() > 1) {
      // consecutive windows equal in 3 (GGIR) or all 6 of means and sds
      const double* cols[7];
      for (int c = 0; c < 7; ++c) cols[c] = col_[c].data();
      const std::vector<std::size_t> cut =
          duplicate_cuts(cols, idx.data(), idx.size(), cfg_.compat ? 3 : 6);
      remove_positions(idx, cut);
    }
    return idx;
  }

  // [4] of usable()'s rows, those to fit: the first is left out, then the
  // windows at rest, then (own mode) those its guards leave out
  std::vector<std::size_t> rest(const std::vector<std::size_t>& idx) const {
    std::vector<std::size_t> keep;
    for (std::size_t j = 1; j < idx.size(); ++j) {
      if (rest_[idx[j]] && why_[idx[j]] == why_none) keep.push_back(idx[j]);
    }
    return keep;
  }

 private:
  struct Row {
    WindowStats w;
    bool rest;
  };

  // own mode's guards on a rest window (GgirConfig): identical samples
  // first, then clipping, then the norm (one reason per window)
  GgirWhy guard(const WindowStats& w) const {
    const double valid = static_cast<double>(w.n) - static_cast<double>(w.n_invalid);
    if (valid > 1 && static_cast<double>(w.n_repeat) > cfg_.guard_repeat * (valid - 1)) {
      return why_identical;
    }
    if (cfg_.guard_clip > 0) {
      for (int a = 0; a < 3; ++a) {
        if (std::fabs(w.mean[a]) + (w.max[a] - w.min[a]) >= cfg_.guard_clip) return why_clipped;
      }
    }
    const double nm = std::sqrt(w.mean[0] * w.mean[0] + w.mean[1] * w.mean[1] +
                                w.mean[2] * w.mean[2]);
    if (std::fabs(nm - 1.0) > cfg_.guard_norm) return why_norm;
    return why_none;
  }

  // v without the elements at positions `pos` (ascending)
  static void remove_positions(std::vector<std::size_t>& v, const std::vector<std::size_t>& pos) {
    std::size_t w = 0, p = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (p < pos.size() && pos[p] == i) {
        ++p;
        continue;
      }
      v[w++] = v[i];
    }
    v.resize(w);
  }

  GgirConfig cfg_;
  SdRestRule rule_;
  std::vector<Row> block_;          // the block being read
  std::vector<double> col_[8];      // the table, by column
  std::vector<bool> rest_;          // the rest rule's flag of each row
  std::vector<unsigned char> why_;  // own mode's guard on each rest row (GgirWhy)
};

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_WINDOW_TABLE_HPP
