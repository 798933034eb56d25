// gravcal: a byte source read ahead on a second thread.
//
// The inner source's bytes come through a few fixed buffers that a thread
// fills while the reader decodes the bytes before them: for an inner source
// whose reading costs (a .gt3x's log.bin inflated: a third of a week's
// reading), the two overlap. The bytes, their order and the end are the
// inner source's; only read() is passed through (seek() is refused).
//
// The thread starts at the first read() (so the inner source's own setup,
// and any other source on the same file before it, are done by then) and
// has the inner source to itself until the inner source ends (a read gives
// 0 bytes) or this is destroyed (which stops and joins it). At the end,
// failed() is the inner source's, and whatever the inner source reads from
// is the reader's again. Where the C++ library has no threads
// (GRAVCAL_NO_THREADS), read() reads the inner source directly.
// Header-only, standard headers only.
#ifndef GRAVCAL_DECODERS_READ_AHEAD_HPP
#define GRAVCAL_DECODERS_READ_AHEAD_HPP

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <system_error>
#include <utility>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/host/threads.hpp"

#ifndef GRAVCAL_NO_THREADS
#include <condition_variable>
#include <mutex>
#include <thread>
#endif

namespace gravcal {

class ReadAheadSource : public ByteSource {
 public:
  // `inner`: the source read ahead; buffers of `chunk` bytes, `count` of
  // them (at least 2).
  explicit ReadAheadSource(std::unique_ptr<ByteSource> inner, std::size_t chunk = std::size_t(1) << 20,
                           std::size_t count = 4)
      : inner_(std::move(inner)), size_(inner_->size()) {
#ifndef GRAVCAL_NO_THREADS
    slots_.resize(std::max<std::size_t>(count, 2));
    for (Slot& s : slots_) s.bytes.resize(std::max<std::size_t>(chunk, 1));
#else
    (void)chunk;
    (void)count;
#endif
  }
  ~ReadAheadSource() override {
#ifndef GRAVCAL_NO_THREADS
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
#endif
  }
  ReadAheadSource(const ReadAheadSource&) = delete;
  ReadAheadSource& operator=(const ReadAheadSource&) = delete;

  std::size_t read(unsigned char* buf, std::size_t n) override {
#ifdef GRAVCAL_NO_THREADS
    const std::size_t k = inner_->read(buf, n);
    pos_ += static_cast<std::int64_t>(k);
    return k;
#else
    if (!started_) start();
    if (direct_) {  // no thread could be had: the inner source itself
      const std::size_t k = inner_->read(buf, n);
      pos_ += static_cast<std::int64_t>(k);
      return k;
    }
    std::size_t got = 0;
    while (got < n) {
      Slot& s = slots_[take_];
      if (!held_) {
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait(lock, [&s] { return s.full; });
        held_ = true;
      }
      // (the slot is the reader's until it is given back)
      const std::size_t k = std::min(n - got, s.len - s.at);
      std::memcpy(buf + got, s.bytes.data() + s.at, k);
      s.at += k;
      got += k;
      if (s.at < s.len) continue;
      if (s.last) break;  // the inner source ended after this slot
      {
        std::lock_guard<std::mutex> lock(m_);
        s.full = false;
      }
      held_ = false;
      cv_.notify_all();
      take_ = (take_ + 1) % slots_.size();
    }
    pos_ += static_cast<std::int64_t>(got);
    return got;
#endif
  }
  bool failed() const override {
#ifndef GRAVCAL_NO_THREADS
    if (started_ && !direct_) {
      std::lock_guard<std::mutex> lock(m_);
      return ended_ && failed_;
    }
#endif
    return inner_->failed();
  }
  std::int64_t position() const override { return pos_; }
  std::int64_t size() const override { return size_; }

 private:
#ifndef GRAVCAL_NO_THREADS
  struct Slot {
    std::vector<unsigned char> bytes;
    std::size_t len = 0, at = 0;
    bool full = false;  // filled by the thread, not yet given back by the reader
    bool last = false;  // the inner source ended in (or right after) this slot
  };

  void start() {
    started_ = true;
    try {
      thread_ = std::thread([this] { fill(); });
    } catch (const std::system_error&) {
      direct_ = true;
    }
  }

  // The thread: the slots in turn, each filled whole but the last.
  void fill() {
    std::size_t put = 0;
    for (;;) {
      Slot& s = slots_[put];
      {
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait(lock, [&] { return stop_ || !s.full; });
        if (stop_) return;
      }
      std::size_t len = 0;
      bool end = false;
      while (len < s.bytes.size()) {
        const std::size_t k = inner_->read(s.bytes.data() + len, s.bytes.size() - len);
        if (k == 0) {
          end = true;
          break;
        }
        len += k;
      }
      const bool bad = end && inner_->failed();
      {
        std::lock_guard<std::mutex> lock(m_);
        s.len = len;
        s.at = 0;
        s.last = end;
        s.full = true;
        if (end) {
          ended_ = true;
          failed_ = bad;
        }
      }
      cv_.notify_all();
      if (end) return;
      put = (put + 1) % slots_.size();
    }
  }

  std::vector<Slot> slots_;
  std::size_t take_ = 0;
  bool held_ = false;  // the reader holds slot take_ (seen full)
  mutable std::mutex m_;
  std::condition_variable cv_;
  std::thread thread_;
  bool started_ = false, direct_ = false;
  bool stop_ = false, ended_ = false, failed_ = false;  // under m_
#endif
  std::unique_ptr<ByteSource> inner_;
  std::int64_t size_;
  std::int64_t pos_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODERS_READ_AHEAD_HPP
