// gravcal: the part of a decorating decoder that forwards to the decoder
// it wraps.
//
// GGIR's resampling (decode_ggir_resample.hpp) and its time-gap filling
// (decode_ggir_timegaps.hpp) each sit over another decoder, read it in
// calls of GGIR's blocks and give on what it gives, changed. What they
// forward the same way is here, once: the inner decoder's opening (its
// info, error and report become theirs), its report after each read with
// their own counts added, the reading of its units (how many a call has
// left and has read), and the bound on samples per unit (twice the inner
// decoder's: a decorator at most doubles what a unit gives).
#ifndef GRAVCAL_DECODE_FORWARDING_HPP
#define GRAVCAL_DECODE_FORWARDING_HPP

#include <cstddef>
#include <cstdint>
#include <memory>

#include "gravcal/decoders/decode.hpp"

namespace gravcal {

// Self: the decorator (its add_own(Report&) const adds its own counts to
// the report; called without a virtual call, as it was when each decorator
// wrote this itself).
template <class Inner, class Self>
class ForwardingDecoder : public Decoder {
 public:
  std::size_t max_samples_per_unit() const override {
    return 2 * inner_->max_samples_per_unit();
  }

 protected:
  explicit ForwardingDecoder(std::unique_ptr<Inner> inner) : inner_(std::move(inner)) {}

  // Opens the inner decoder and takes its info, error and report; false
  // when it did not open.
  bool open_inner() {
    const bool ok = inner_->open();
    info_ = inner_->info();
    error_ = inner_->error();
    report_ = inner_->report();
    return ok;
  }

  // The report after a read: the inner decoder's, the decorator's own
  // counts, and the samples the decorator gave.
  void forward_report() {
    report_ = inner_->report();
    static_cast<const Self&>(*this).add_own(report_);
    report_.samples = given_;
  }

  // One read of the inner decoder into b within the call's units left
  // (negative: no limit); its units count to the call's.
  std::int64_t read_inner(SampleBuffer& b) {
    const std::int64_t u = inner_->read(b, left_);
    call_units_ += u;
    if (left_ > 0) left_ -= u;
    return u;
  }

  // What read() returns: nothing while the call is under way (`busy`), its
  // units once all its samples are given, so that a caller reading a block
  // of units gets the whole block.
  std::int64_t call_units(bool busy) {
    if (busy) return 0;
    const std::int64_t u = call_units_;
    call_units_ = 0;
    return u;
  }

  std::unique_ptr<Inner> inner_;
  std::int64_t left_ = -1;        // the call's units left to read (negative: no limit)
  std::int64_t call_units_ = 0;   // units the call has read
  std::int64_t given_ = 0;        // samples given on
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_FORWARDING_HPP
