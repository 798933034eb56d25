// gravcal: Movisens recordings (a unisens 2.0 folder), as GGIR 3.3 reads
// them through unisensR.
//
// The folder holds unisens.xml and one binary file per <signalEntry>: here
// acc.bin (three interleaved channels) and temp.bin (a channel named
// "temp"). Each entry gives dataType (int16 or int32, little-endian),
// sampleRate, lsbValue (default 1) and baseline (default 0); a stored value
// v is (v - baseline) * lsbValue, computed only when baseline is not 0 or
// lsbValue not 1, as unisensR::readUnisensSignalEntry does. A file's
// sample count is its size in whole frames (getUnisensSignalSampleCount):
// the xml's counts and durations are not used, so the file size bounds
// everything and a partial last frame is left out (and reported).
//
// Temperature, as GGIR's g.readtemp_movisens gives it, per GGIR block of
// `block_samples` acceleration samples (GGIR: sf * 60 * 1440 / 2 with sf =
// 64, as g.inspectfile sets it for every Movisens recording, whatever
// chunksize): for the block's samples from..to (1-based) it reads the
// temperature samples ceiling(from / sf * r)..ceiling(to / sf * r), first with
// r = 1 and then, when temp.bin's rate differs, with its rate (either range
// out of the file: no temperature for the block), and interpolates them
// onto the block's n samples as GGIRread::resample does, at the points R's
// seq(1, m, length.out = n) gives: linear, or nearest neighbour with
// interpolation = 2 (GGIR's interpolationType), fused where GGIRread's
// compiler fused it (option resample_fused). GGIR takes the temperature
// only when the first block has it; a later block without it makes GGIR
// fail: in GGIR's mode (option compat = 1) the decoder refuses such a
// recording when it opens it, in gravcal's own (compat = 0) it gives NaN
// there and counts the block ("temperature_blocks_unreadable").
//
// The decoder reads acc.bin from its ByteSource, the xml as text and
// temp.bin from a second ByteSource that it owns (null: none), so that it
// runs on bytes in memory too (tests, the fuzzer). Its unit is one sample;
// memory is two fixed buffers, never sized by the file.
#ifndef GRAVCAL_DECODE_MOVISENS_HPP
#define GRAVCAL_DECODE_MOVISENS_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {

// One <signalEntry> of unisens.xml, as far as the decoder needs it.
struct UnisensEntry {
  std::string id;
  std::string data_type;
  std::string sample_rate, lsb_value, baseline;  // as written; "" when absent
  bool has_rate = false, has_lsb = false, has_baseline = false;
  bool bin = false, csv = false;
  std::vector<std::string> channels;
};

// A small reader of unisens.xml: the root's name and timestampStart, and
// the signal entries. Namespace prefixes are dropped; comments, processing
// instructions and declarations are skipped. False, with `why`, when the
// text is not well-formed enough to tell these.
class UnisensXml {
 public:
  std::string root;
  std::string timestamp_start;
  std::vector<UnisensEntry> entries;
  std::string why;

  bool parse(const std::string& s) {
    std::size_t i = 0;
    const std::size_t n = s.size();
    bool in_entry = false;
    int depth = 0;
    while (true) {
      i = s.find('<', i);
      if (i == std::string::npos) break;
      if (s.compare(i, 4, "<!--") == 0) {
        const std::size_t e = s.find("-->", i + 4);
        if (e == std::string::npos) return bad("a comment is not closed");
        i = e + 3;
        continue;
      }
      if (i + 1 < n && (s[i + 1] == '?' || s[i + 1] == '!')) {
        const std::size_t e = s.find('>', i + 2);
        if (e == std::string::npos) return bad("a declaration is not closed");
        i = e + 1;
        continue;
      }
      bool closing = false;
      std::size_t p = i + 1;
      if (p < n && s[p] == '/') {
        closing = true;
        ++p;
      }
      const std::size_t name0 = p;
      while (p < n && !is_space(s[p]) && s[p] != '>' && s[p] != '/') ++p;
      if (p >= n) return bad("a tag is not closed");
      std::string name = s.substr(name0, p - name0);
      if (name.empty()) return bad("a tag has no name");
      const std::size_t colon = name.rfind(':');
      if (colon != std::string::npos) name = name.substr(colon + 1);
      std::vector<std::pair<std::string, std::string>> attrs;
      bool self_closing = false;
      while (true) {
        while (p < n && is_space(s[p])) ++p;
        if (p >= n) return bad("a tag is not closed");
        if (s[p] == '>') {
          ++p;
          break;
        }
        if (s[p] == '/') {
          if (p + 1 < n && s[p + 1] == '>') {
            self_closing = true;
            p += 2;
            break;
          }
          return bad("a stray '/' in a tag");
        }
        if (closing) return bad("attributes in a closing tag");
        const std::size_t a0 = p;
        while (p < n && !is_space(s[p]) && s[p] != '=' && s[p] != '>' && s[p] != '/') ++p;
        std::string an = s.substr(a0, p - a0);
        while (p < n && is_space(s[p])) ++p;
        if (an.empty() || p >= n || s[p] != '=') return bad("an attribute without a value");
        ++p;
        while (p < n && is_space(s[p])) ++p;
        if (p >= n || (s[p] != '"' && s[p] != '\'')) return bad("an attribute value without quotes");
        const char q = s[p++];
        const std::size_t v0 = p;
        while (p < n && s[p] != q) ++p;
        if (p >= n) return bad("an attribute value is not closed");
        std::string av;
        if (!unescape(s.substr(v0, p - v0), av)) return bad("an unknown entity in an attribute");
        ++p;
        const std::size_t ac = an.rfind(':');
        if (ac != std::string::npos) an = an.substr(ac + 1);
        attrs.emplace_back(an, av);
      }
      i = p;
      if (closing) {
        if (depth <= 0) return bad("a closing tag without its opening tag");
        --depth;
        if (name == "signalEntry") in_entry = false;
        continue;
      }
      if (depth == 0) {
        if (!root.empty()) return bad("more than one root element");
        root = name;
        for (const auto& a : attrs) {
          if (a.first == "timestampStart") timestamp_start = a.second;
        }
      }
      if (!self_closing) ++depth;
      if (name == "signalEntry" && depth <= 3) {
        UnisensEntry e;
        for (const auto& a : attrs) {
          if (a.first == "id") e.id = a.second;
          if (a.first == "dataType") e.data_type = a.second;
          if (a.first == "sampleRate") e.sample_rate = a.second, e.has_rate = true;
          if (a.first == "lsbValue") e.lsb_value = a.second, e.has_lsb = true;
          if (a.first == "baseline") e.baseline = a.second, e.has_baseline = true;
        }
        entries.push_back(e);
        in_entry = !self_closing;
      } else if (in_entry && !entries.empty()) {
        UnisensEntry& e = entries.back();
        if (name == "binFileFormat") e.bin = true;
        if (name == "csvFileFormat") e.csv = true;
        if (name == "channel") {
          std::string cn;
          for (const auto& a : attrs) {
            if (a.first == "name") cn = a.second;
          }
          e.channels.push_back(cn);
        }
      }
    }
    if (root.empty()) return bad("no element at all");
    if (depth != 0) return bad("the root element is not closed");
    return true;
  }

  const UnisensEntry* find(const std::string& id) const {
    for (const UnisensEntry& e : entries) {
      if (e.id == id) return &e;
    }
    return nullptr;
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  bool bad(const char* what) {
    why = what;
    return false;
  }
  static bool unescape(const std::string& in, std::string& out) {
    for (std::size_t k = 0; k < in.size(); ++k) {
      if (in[k] != '&') {
        out += in[k];
        continue;
      }
      const std::size_t e = in.find(';', k);
      if (e == std::string::npos) return false;
      const std::string ent = in.substr(k + 1, e - k - 1);
      if (ent == "amp") out += '&';
      else if (ent == "lt") out += '<';
      else if (ent == "gt") out += '>';
      else if (ent == "quot") out += '"';
      else if (ent == "apos") out += '\'';
      else return false;
      k = e;
    }
    return true;
  }
};

// An attribute's text without the blanks around it.
inline std::string unisens_trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\n' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\n' || s[b - 1] == '\r')) --b;
  return s.substr(a, b - a);
}

// A number attribute (surrounding blanks allowed), correctly rounded by
// strtod; NaN when it is not one. unisensR reads these with R's
// as.numeric(), whose digits accumulate in R's long double (in double where
// R has none), so a long number can differ in its last bits: the caller
// gives R's values where it has them (option "r_number:" + text).
inline double unisens_number(const std::string& s) {
  const std::string t = unisens_trim(s);
  if (t.empty()) return std::numeric_limits<double>::quiet_NaN();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size()) return std::numeric_limits<double>::quiet_NaN();
  return v;
}

// One binary signal file read frame by frame through a fixed buffer.
class UnisensSignal {
 public:
  static constexpr std::size_t kBufFrames = 4096;

  // `chan`: the channel to give (value()), or -1 for all (frame()).
  bool setup(ByteSource* src, int size, int nch, double lsb, double baseline) {
    src_ = src;
    size_ = size;
    nch_ = nch;
    frame_ = static_cast<std::size_t>(size) * static_cast<std::size_t>(nch);
    scale_ = baseline != 0 || lsb != 1;
    lsb_ = lsb;
    baseline_ = baseline;
    const std::int64_t bytes = src ? src->size() : -1;
    if (bytes < 0) return false;
    count_ = bytes / static_cast<std::int64_t>(frame_);
    tail_ = bytes % static_cast<std::int64_t>(frame_);
    // the channel count comes from unisens.xml: the buffer never holds more
    // frames than the file has (nor more than kBufFrames)
    const std::int64_t frames = std::max<std::int64_t>(1, std::min<std::int64_t>(count_, kBufFrames));
    buf_.assign(static_cast<std::size_t>(frames) * frame_, 0);
    buf_frames_ = static_cast<std::size_t>(frames);
    return true;
  }
  std::int64_t count() const { return count_; }
  std::int64_t tail_bytes() const { return tail_; }
  bool failed() const { return failed_; }

  // Channel c of frame k (0-based, k < count()), scaled; NaN when it could
  // not be read.
  double value(std::int64_t k, int c) {
    std::int64_t n = 0;
    const unsigned char* f = frames(k, &n);
    return f != nullptr ? decode(f, c) : std::numeric_limits<double>::quiet_NaN();
  }
  // Frame k's bytes, and in *n how many frames from k on the buffer holds
  // (read in when it does not hold k); nullptr when k cannot be read.
  const unsigned char* frames(std::int64_t k, std::int64_t* n) {
    if (k < first_ || k >= first_ + have_) {
      if (!fill(k)) return nullptr;
    }
    *n = first_ + have_ - k;
    return buf_.data() + static_cast<std::size_t>(k - first_) * frame_;
  }
  std::size_t frame_bytes() const { return frame_; }
  // Channel c of a frame, as value() gives it.
  double decode(const unsigned char* frame, int c) const {
    const unsigned char* p = frame + static_cast<std::size_t>(c) * static_cast<std::size_t>(size_);
    const double v = size_ == 2 ? static_cast<double>(static_cast<std::int16_t>(le16(p)))
                                : static_cast<double>(static_cast<std::int32_t>(le32(p)));
    return scale_ ? (v - baseline_) * lsb_ : v;
  }
  // Channels 0, 1, 2 of m consecutive frames of 3 channels from f, as
  // decode() gives them, into x, y, z.
  void decode3(const unsigned char* f, std::size_t m, double* x, double* y, double* z) const {
    if (size_ == 2) decode3_as<2>(f, m, x, y, z);
    else decode3_as<4>(f, m, x, y, z);
  }

 private:
  template <int S>
  static double raw(const unsigned char* p) {
    if (S == 2) return static_cast<double>(static_cast<std::int16_t>(le16(p)));
    return static_cast<double>(static_cast<std::int32_t>(le32(p)));
  }
  template <int S>
  void decode3_as(const unsigned char* f, std::size_t m, double* x, double* y, double* z) const {
    const double b = baseline_, l = lsb_;
    if (scale_) {
      for (std::size_t i = 0; i < m; ++i, f += 3 * S) {
        x[i] = (raw<S>(f) - b) * l;
        y[i] = (raw<S>(f + S) - b) * l;
        z[i] = (raw<S>(f + 2 * S) - b) * l;
      }
    } else {
      for (std::size_t i = 0; i < m; ++i, f += 3 * S) {
        x[i] = raw<S>(f);
        y[i] = raw<S>(f + S);
        z[i] = raw<S>(f + 2 * S);
      }
    }
  }

  bool fill(std::int64_t k) {
    std::int64_t want = count_ - k;
    if (want > static_cast<std::int64_t>(buf_frames_)) want = static_cast<std::int64_t>(buf_frames_);
    have_ = 0;
    first_ = k;
    if (want <= 0 || failed_) return false;
    if (src_->position() != k * static_cast<std::int64_t>(frame_) &&
        !src_->seek(k * static_cast<std::int64_t>(frame_))) {
      failed_ = true;
      return false;
    }
    const std::size_t bytes = static_cast<std::size_t>(want) * frame_;
    const std::size_t got = read_full(*src_, buf_.data(), bytes);
    have_ = static_cast<std::int64_t>(got / frame_);
    if (got < bytes) failed_ = true;
    return have_ > 0;
  }

  ByteSource* src_ = nullptr;
  int size_ = 2, nch_ = 1;
  std::size_t frame_ = 2;
  std::size_t buf_frames_ = 0;  // frames buf_ holds
  bool scale_ = false;
  double lsb_ = 1, baseline_ = 0;
  std::int64_t count_ = 0, tail_ = 0;
  std::vector<unsigned char> buf_;
  std::int64_t first_ = 0, have_ = 0;
  bool failed_ = false;
};

class MovisensDecoder : public Decoder {
 public:
  MovisensDecoder(ByteSource& acc, const Options& opts, std::string xml,
                  std::unique_ptr<ByteSource> temp)
      : acc_src_(acc),
        temp_src_(std::move(temp)),
        xml_(std::move(xml)),
        rules_(ReadRules::of(opts)),
        block_opt_(opts.num("block_samples", 0)),
        opts_(opts) {}

  bool open() override {
    if (xml_.empty()) return fail("unisens.xml is missing, empty or unreadable");
    if (xml_ == "<toolong") return fail("unisens.xml is over 16 MB");
    UnisensXml doc;
    if (!doc.parse(xml_)) return fail("unisens.xml is malformed: " + doc.why);
    xml_.clear();
    xml_.shrink_to_fit();
    if (doc.root != "unisens") return fail("unisens.xml's root element is not <unisens>");
    const UnisensEntry* acc = doc.find("acc.bin");
    if (acc == nullptr) return fail("unisens.xml has no signalEntry for acc.bin");
    int size = 0;
    double lsb = 1, base = 0;
    if (!entry_format(*acc, "acc.bin", size, lsb, base)) return false;
    if (acc->channels.size() != 3) {
      return fail("acc.bin has " + std::to_string(acc->channels.size()) +
                  " channels in unisens.xml, not 3 (x, y, z)");
    }
    sf_ = acc->has_rate ? number(acc->sample_rate) : std::nan("");
    if (!(sf_ > 0) || !std::isfinite(sf_) || sf_ > 1e6) {
      return fail("acc.bin's sampleRate in unisens.xml is not a positive number");
    }
    if (!acc_.setup(&acc_src_, size, 3, lsb, base)) {
      return fail("the size of acc.bin is unknown");
    }
    n_ = acc_.count();
    if (acc_.tail_bytes() != 0) {
      report_.truncated = true;
      report_.count("partial_frame_bytes", acc_.tail_bytes());
      report_.note("acc.bin ends in a partial sample of " + std::to_string(acc_.tail_bytes()) +
                   " bytes (after " + std::to_string(n_) + " samples): left out");
    }
    // GGIR's block: sf * 60 * 1440 / 2 with its sf, 64 Hz for every Movisens
    const double b = block_opt_ > 0 ? std::floor(block_opt_) : 64.0 * 60 * 1440 / 2;
    block_ = b >= 1 && b < 9e15 ? static_cast<std::int64_t>(b) : 1;
    open_temperature(doc);
    info_.format = "movisens";
    info_.device = "Movisens";
    info_.sf = sf_;
    info_.start_time = parse_time(doc.timestamp_start);
    info_.has_temperature = temp_ok_ && block_temperature_ok(1, n_ < block_ ? n_ : block_);
    if (temp_ok_ && !info_.has_temperature && n_ > 0) {
      report_.note("temp.bin does not cover the first block: no temperature");
    }
    // GGIR fails on a recording whose first block has a temperature and a
    // later one none: in its mode, so does the decoder (at once)
    if (rules_.compat && info_.has_temperature) {
      for (std::int64_t from = block_; from < n_; from += block_) {
        const std::int64_t to = n_ - from < block_ ? n_ : from + block_;
        if (!block_temperature_ok(from + 1, to)) {
          return fail("temp.bin does not cover samples " + std::to_string(from + 1) + " to " +
                      std::to_string(to) +
                      " (a later GGIR block than the first), on which GGIR's g.calibrate "
                      "fails; gravcal's own methods read it (compat = 0)");
        }
      }
    }
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    std::int64_t units = 0;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    while (next_ < n_ && !out.full() && (max_units < 0 || units < max_units)) {
      if (next_ == block_end_) start_block();
      // the samples the buffer holds, in this block, that fit
      std::int64_t m = 0;
      const unsigned char* f = acc_.frames(next_, &m);
      if (f == nullptr) {
        report_.read_error = true;
        report_.note("acc.bin could not be read past sample " + std::to_string(next_));
        n_ = next_;
        break;
      }
      if (m > block_end_ - next_) m = block_end_ - next_;
      if (m > static_cast<std::int64_t>(out.room())) m = static_cast<std::int64_t>(out.room());
      if (max_units >= 0 && m > max_units - units) m = max_units - units;
      // a run of m samples, column by column (acc.bin has 3 channels)
      const std::size_t k = out.n, mm = static_cast<std::size_t>(m);
      acc_.decode3(f, mm, out.x + k, out.y + k, out.z + k);
      if (out.t != nullptr) {
        if (info_.has_temperature) temperatures(next_ - block_from_, m, out.t + k);
        else std::fill(out.t + k, out.t + k + mm, nan);
      }
      if (out.time != nullptr) std::fill(out.time + k, out.time + k + mm, nan);
      out.n += mm;
      next_ += m;
      units += m;
      report_.samples += m;
    }
    report_.units += units;
    return units;
  }

  bool done() const override { return next_ >= n_; }
  std::size_t max_samples_per_unit() const override { return 1; }

 private:
  bool fail(const std::string& why) {
    error_ = why;
    n_ = 0;
    return false;
  }

  // A number attribute as R reads it where the caller gave R's value for
  // this text, else strtod's.
  double number(const std::string& s) const {
    const std::string key = "r_number:" + unisens_trim(s);
    if (opts_.has_num(key.c_str())) return opts_.num(key.c_str(), 0);
    return unisens_number(s);
  }

  // dataType, lsbValue and baseline of a binary entry; false (error set for
  // acc.bin) when they cannot be read as unisensR would.
  bool entry_format(const UnisensEntry& e, const std::string& id, int& size, double& lsb,
                    double& base) {
    if (!e.bin) {
      return fail(id + " is not a binary entry (binFileFormat) in unisens.xml" +
                  (e.csv ? ": csv entries are not read" : ""));
    }
    if (e.data_type == "int16") size = 2;
    else if (e.data_type == "int32") size = 4;
    else return fail(id + "'s dataType \"" + e.data_type + "\" is not int16 or int32");
    lsb = e.has_lsb ? number(e.lsb_value) : 1.0;
    base = e.has_baseline ? number(e.baseline) : 0.0;
    if (!std::isfinite(lsb)) return fail(id + "'s lsbValue in unisens.xml is not a number");
    if (!std::isfinite(base)) return fail(id + "'s baseline in unisens.xml is not a number");
    return true;
  }

  void open_temperature(const UnisensXml& doc) {
    const UnisensEntry* e = doc.find("temp.bin");
    std::string why;
    if (e == nullptr) why = "unisens.xml has no signalEntry for temp.bin";
    else if (!temp_src_) why = "temp.bin is missing";
    if (why.empty()) {
      int size = 0;
      double lsb = 1, base = 0;
      const std::string keep = error_;
      if (!entry_format(*e, "temp.bin", size, lsb, base)) {
        why = error_;
        error_ = keep;
        n_ = acc_.count();
      } else {
        temp_chan_ = -1;
        for (std::size_t c = 0; c < e->channels.size(); ++c) {
          if (e->channels[c] == "temp") {
            temp_chan_ = static_cast<int>(c);
            break;
          }
        }
        temp_rate_ = e->has_rate ? number(e->sample_rate) : std::nan("");
        if (temp_chan_ < 0) why = "temp.bin has no channel named \"temp\"";
        else if (!std::isfinite(temp_rate_)) why = "temp.bin's sampleRate is not a number";
        else if (!temp_.setup(temp_src_.get(), size, static_cast<int>(e->channels.size()), lsb,
                              base)) {
          why = "the size of temp.bin is unknown";
        }
      }
    }
    if (!why.empty()) {
      report_.count("no_temperature");
      report_.note(why + ": no temperature");
      return;
    }
    if (temp_.tail_bytes() != 0) {
      report_.count("temperature_partial_frame_bytes", temp_.tail_bytes());
      report_.note("temp.bin ends in a partial sample: left out");
    }
    temp_ok_ = true;
  }

  // GGIR's indices of the temperature samples for acceleration samples
  // from..to at rate r; false when unisensR would refuse them.
  bool temp_range(std::int64_t from, std::int64_t to, double r, std::int64_t& a,
                  std::int64_t& b) const {
    const double fa = std::ceil(static_cast<double>(from) / sf_ * r);
    const double fb = std::ceil(static_cast<double>(to) / sf_ * r);
    const double cnt = static_cast<double>(temp_.count());
    if (!(fa >= 1) || fa > cnt || !(fb <= cnt) || fb < fa) return false;
    a = static_cast<std::int64_t>(fa);
    b = static_cast<std::int64_t>(fb);
    return true;
  }

  bool block_temperature_ok(std::int64_t from, std::int64_t to) {
    if (!temp_ok_ || to < from) return false;
    std::int64_t a = 0, b = 0;
    if (!temp_range(from, to, 1.0, a, b)) return false;
    if (temp_rate_ != 1.0 && !temp_range(from, to, temp_rate_, a, b)) return false;
    tfrom_ = a;
    tm_ = b - a + 1;
    return true;
  }

  // The block starting at sample next_ (0-based): its length and its
  // temperature's interpolation.
  void start_block() {
    block_from_ = next_;
    block_end_ = next_ + block_ < n_ ? next_ + block_ : n_;
    bn_ = block_end_ - block_from_;
    block_temp_ = info_.has_temperature && block_temperature_ok(block_from_ + 1, block_end_);
    if (info_.has_temperature && !block_temp_) {
      report_.count("temperature_blocks_unreadable");
      report_.note("no temperature in temp.bin for samples " + std::to_string(block_from_ + 1) +
                   " to " + std::to_string(block_end_) + ": NaN");
    }
    pos_ = 1;
  }

  // The temperatures of the block's samples p..p + m - 1 (0-based), into
  // out: for sample q, R's seq(1, tm, length.out = n)[q + 1] (1 + q * by, by
  // = (tm - 1) / (n - 1), its ends exact), then GGIRread::resample's
  // interpolation between the temperature samples around it. Its weight
  // (g - r0) / (r1 - r0) is g - r0: r1 - r0 is exactly 1 (positions below
  // 2^53) and a division by 1 is exact.
  void temperatures(std::int64_t p, std::int64_t m, double* out) {
    if (!block_temp_) {
      std::fill(out, out + m, std::numeric_limits<double>::quiet_NaN());
      return;
    }
    if (tm_ == 1) {
      for (std::int64_t i = 0; i < m; ++i) out[i] = temp_.value(tfrom_ - 1, temp_chan_);
      return;
    }
    if (rules_.nearest()) temperatures_as<true, false>(p, m, out);
    else if (rules_.fused) temperatures_as<false, true>(p, m, out);
    else temperatures_as<false, false>(p, m, out);
  }

  template <bool Nearest, bool Fused>
  void temperatures_as(std::int64_t p, std::int64_t m, double* out) {
    const std::int64_t t0 = tfrom_ - 1;  // 0-based first temperature sample
    const double tm = static_cast<double>(tm_);
    // the grid walk (kernels/ggir_grid.hpp) over positions: R's seq(1, tm,
    // length.out = n), weights g - r0
    const kernels::GridWalk<kernels::PositionGrid, kernels::UnitWeight,
                            kernels::InterpAs<Nearest, Fused>>
        walk{{tm, (tm - 1) / static_cast<double>(bn_ - 1), bn_ - 1}, {}};
    // the end of the interval (pos, pos + 1]; the last one has none (a
    // position beyond tm, never given, would take it)
    const double inf = std::numeric_limits<double>::infinity();
    auto end_of = [&](std::int64_t pos) {
      return pos < tm_ - 1 ? static_cast<double>(pos + 1) : inf;
    };
    std::int64_t pos = pos_;
    std::int64_t i = 0;
    while (i < m) {
      // the interval that holds sample i's position
      const double gi = walk.grid.at(p + i);
      while (!(gi <= end_of(pos))) ++pos;
      // the temperature samples at its ends, read once for the samples in
      // it (after a read error, every time: value() then gives NaN past it)
      if (t0 + pos != tv_at_ || temp_.failed()) {
        tv_at_ = t0 + pos;
        tv_[0] = temp_.value(tv_at_ - 1, temp_chan_);
        tv_[1] = temp_.value(tv_at_, temp_chan_);
      }
      const double v0 = tv_[0], v1 = tv_[1];
      const double r0 = static_cast<double>(pos), r1 = end_of(pos);
      // sample i and those after it in the same interval
      std::int64_t q = p + i;
      walk.through(
          q, r1, [&](std::int64_t k) { return k < p + m; },
          [&](std::int64_t k, double g) GRAVCAL_GRID_POINT {
            out[k - p] = walk.value(walk.weight(g, r0, r1), v0, v1);
            return true;
          });
      i = q - p;
    }
    pos_ = pos;
  }

  // "YYYY-MM-DDTHH:MM:SS[.fff]" as seconds since 1970 UTC; NaN otherwise.
  static double parse_time(const std::string& s) {
    int Y = 0, M = 0, D = 0, h = 0, mi = 0;
    double sec = 0;
    char T = 0;
    if (std::sscanf(s.c_str(), "%4d-%2d-%2d%c%2d:%2d:%lf", &Y, &M, &D, &T, &h, &mi, &sec) != 7 ||
        M < 1 || M > 12 || D < 1 || D > 31 || h > 23 || mi > 59 || !(sec >= 0 && sec < 61)) {
      return std::numeric_limits<double>::quiet_NaN();
    }
    return static_cast<double>(days_from_civil(Y, static_cast<unsigned>(M),
                                               static_cast<unsigned>(D))) * 86400.0 +
           h * 3600.0 + mi * 60.0 + sec;
  }

  ByteSource& acc_src_;
  std::unique_ptr<ByteSource> temp_src_;
  std::string xml_;
  // the reading rules (compat, interpolation, resample_fused), read once
  const ReadRules rules_;
  double block_opt_ = 0;
  Options opts_;
  double sf_ = 0;
  UnisensSignal acc_, temp_;
  bool temp_ok_ = false;
  int temp_chan_ = 0;
  double temp_rate_ = 1;
  std::int64_t n_ = 0, next_ = 0, block_ = 1;
  std::int64_t block_from_ = 0, block_end_ = 0, bn_ = 0;
  bool block_temp_ = false;
  std::int64_t tfrom_ = 1, tm_ = 0, pos_ = 1;
  std::int64_t tv_at_ = -1;  // temperature(): the sample index tv_ holds, from tv_at_ - 1
  double tv_[2] = {0, 0};
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_MOVISENS_HPP
