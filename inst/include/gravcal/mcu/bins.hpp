// gravcal: calibration point selection in 3 x 3 orientation bins
// (Farago, Maczak & Gingl 2024, Sec. II-B-1, Eq. 10 and Fig. 6).
//
// Each axis is split into three intervals, negative [-1.25, -0.75],
// zero [-0.25, 0.25] and positive [0.75, 1.25] g, giving nine subsets C_ij
// (bin index 3 * axis + j, axis x = 0, y = 1, z = 2; j n = 0, zero = 1, p = 2).
// A rest mean is offered to the selector; it is kept when
//   1. it lies in at least one subset that is not full (count < max_per_bin),
//   2. its Euclidean distance to every point kept so far is at least
//      min_distance (the paper's "differs sufficiently", whose value is not
//      printed; gravcal's default is 0.3 g, about 17 degrees of tilt, which
//      spreads the points and so speeds up the descent).
// A point can lie in up to three subsets at once (one per axis). A kept point
// counts for exactly one: its negative or positive subset when that is open
// (these caps cover 1/8 of the sphere each, the zero bands 1/4, so points that
// can fill them should); otherwise the open zero subset whose axis coordinate
// is nearest to 0, ties going to the lower bin index. So a point lying flat
// on +z counts for C_zp; once C_zp is full, it may count for C_x0 or C_y0.
//
// Header-only, fixed capacity, no heap.
#ifndef GRAVCAL_BINS_HPP
#define GRAVCAL_BINS_HPP

#include "gravcal/mcu/model.hpp"

namespace gravcal {

struct BinConfig {
  int min_per_bin = 2;        // paper: 2
  int max_per_bin = 2;        // paper: 2
  double min_distance = 0.3;  // g; the paper's novelty threshold (unpublished)
  double outer_lo = 0.75;     // |coordinate| in [outer_lo, outer_hi]: n or p
  double outer_hi = 1.25;
  double inner = 0.25;        // |coordinate| <= inner: zero subset
};

enum BinResult { BIN_OUTSIDE = -1, BIN_FULL = -2, BIN_TOO_CLOSE = -3 };

template <typename T, int Capacity = 90>
class BinSelector {
 public:
  static const int kCapacity = Capacity;

  explicit BinSelector(const BinConfig& cfg) : cfg_(cfg) { reset(); }

  void reset() {
    n_ = 0;
    for (int b = 0; b < 9; ++b) count_[b] = 0;
  }

  // Is the configuration usable with this capacity?
  bool valid() const {
    return cfg_.min_per_bin >= 1 && cfg_.max_per_bin >= cfg_.min_per_bin &&
           9 * cfg_.max_per_bin <= Capacity;
  }

  // Which of the three subsets of `axis` holds coordinate c (0, 1, 2), or -1.
  int subset_of(T c) const {
    const T lo = T(cfg_.outer_lo), hi = T(cfg_.outer_hi), in = T(cfg_.inner);
    if (c >= -hi && c <= -lo) return 0;
    if (c >= -in && c <= in) return 1;
    if (c >= lo && c <= hi) return 2;
    return -1;
  }

  // Offer a rest mean. Returns the bin it was counted for (0..8), or a
  // negative BinResult saying why it was not kept.
  int offer(const Vec3<T>& v) {
    const T c[3] = {v.x, v.y, v.z};
    bool member = false;
    // pass 0: the negative / positive bins; pass 1: the zero bins
    int best = -1;
    for (int pass = 0; pass < 2 && best < 0; ++pass) {
      T best_dist = T(0);
      for (int axis = 0; axis < 3; ++axis) {
        const int j = subset_of(c[axis]);
        if (j < 0) continue;
        member = true;
        if ((j == 1) != (pass == 1)) continue;
        const int b = 3 * axis + j;
        if (count_[b] >= cfg_.max_per_bin) continue;
        T d = c[axis] - T(j - 1);
        if (d < T(0)) d = -d;
        if (best < 0 || d < best_dist) {
          best = b;
          best_dist = d;
        }
      }
    }
    if (!member) return BIN_OUTSIDE;
    if (best < 0) return BIN_FULL;
    const T md = T(cfg_.min_distance);
    const T md2 = md * md;
    for (int i = 0; i < n_; ++i) {
      const Vec3<T> d{v.x - pts_[i].x, v.y - pts_[i].y, v.z - pts_[i].z};
      if (norm2(d) < md2) return BIN_TOO_CLOSE;
    }
    if (n_ >= Capacity) return BIN_FULL;
    pts_[n_] = v;
    bin_[n_] = best;
    ++n_;
    ++count_[best];
    return best;
  }

  // Every subset holds at least min_per_bin points: fitting may start.
  bool complete() const {
    for (int b = 0; b < 9; ++b)
      if (count_[b] < cfg_.min_per_bin) return false;
    return true;
  }

  // Every subset is full: no further point can be kept.
  bool full() const {
    for (int b = 0; b < 9; ++b)
      if (count_[b] < cfg_.max_per_bin) return false;
    return true;
  }

  int size() const { return n_; }
  int count(int b) const { return count_[b]; }
  const Vec3<T>& point(int i) const { return pts_[i]; }
  int bin(int i) const { return bin_[i]; }

 private:
  BinConfig cfg_;
  int n_;
  int count_[9];
  Vec3<T> pts_[Capacity];
  int bin_[Capacity];
};

}  // namespace gravcal

#endif  // GRAVCAL_BINS_HPP
