// fit_points for a Cortex-M4: the same cases (check-r.R writes them), the
// same fits, run on the target's instruction set, so that R's results can be
// compared with the device's to the bit (make -C tests/cpp check-m4).
// Built like firmware.cpp (-mcpu=cortex-m4 -mthumb -Os, soft floating point,
// no heap) and linked for the MPS2 AN386 board (mps2-an386.ld), which
// qemu-system-arm emulates. Input and output go through ARM semihosting: it
// reads m4-cases.txt (format of fit_points.cpp) and writes one line per
// case to m4-out.txt, the nine parameters as printf's %a would print them.
// Exits through semihosting with status 0, or 1 on bad input.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "gravcal/mcu.hpp"

namespace {

// ---- semihosting (ARM DUI 0471: bkpt 0xAB, operation in r0, block in r1)
int semihost(int op, const void* arg) {
  register int r0 __asm__("r0") = op;
  register const void* r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}
enum { SYS_OPEN = 0x01, SYS_CLOSE = 0x02, SYS_WRITE = 0x05, SYS_READ = 0x06,
       SYS_EXIT = 0x18 };

int open_file(const char* name, int mode) {  // mode 0 "r", 4 "w"
  const std::uint32_t a[3] = {reinterpret_cast<std::uint32_t>(name),
                              static_cast<std::uint32_t>(mode),
                              static_cast<std::uint32_t>(std::strlen(name))};
  return semihost(SYS_OPEN, a);
}

[[noreturn]] void exit_with(int status) {
  // ADP_Stopped_ApplicationExit (0 status) or ADP_Stopped_RunTimeErrorUnknown
  semihost(SYS_EXIT, reinterpret_cast<const void*>(status == 0 ? 0x20026 : 0x20023));
  for (;;) {
  }
}

// ---- input: a buffered reader of whitespace-separated tokens
int in_handle = -1;
char in_buf[4096];
int in_len = 0, in_pos = 0;

int next_char() {
  if (in_pos == in_len) {
    const std::uint32_t a[3] = {static_cast<std::uint32_t>(in_handle),
                                reinterpret_cast<std::uint32_t>(in_buf), sizeof in_buf};
    in_len = static_cast<int>(sizeof in_buf) - semihost(SYS_READ, a);  // bytes read
    in_pos = 0;
    if (in_len <= 0) return -1;
  }
  return static_cast<unsigned char>(in_buf[in_pos++]);
}

bool token(char* out, int size) {
  int c = next_char();
  while (c == ' ' || c == '\n' || c == '\r' || c == '\t') c = next_char();
  if (c < 0) return false;
  int k = 0;
  while (c > ' ' && k < size - 1) {
    out[k++] = static_cast<char>(c);
    c = next_char();
  }
  out[k] = 0;
  return true;
}

int hex_digit(char c) {
  return c >= '0' && c <= '9' ? c - '0' : (c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1);
}

// "%a" as glibc prints a double (-0x1.8p+1, 0x0p+0), exactly.
double parse_hex(const char* s) {
  bool neg = false;
  if (*s == '-') neg = true, ++s;
  if (s[0] != '0' || s[1] != 'x') exit_with(1);
  s += 2;
  std::uint64_t m = static_cast<std::uint64_t>(hex_digit(*s++));
  int shift = 0;
  if (*s == '.') {
    for (++s; hex_digit(*s) >= 0; ++s) {
      m = m * 16 + static_cast<std::uint64_t>(hex_digit(*s));
      shift += 4;
    }
  }
  if (*s++ != 'p') exit_with(1);
  bool eneg = false;
  if (*s == '+' || *s == '-') eneg = *s++ == '-';
  int e = 0;
  for (; *s >= '0' && *s <= '9'; ++s) e = e * 10 + (*s - '0');
  const double v = std::ldexp(static_cast<double>(m), (eneg ? -e : e) - shift);
  return neg ? -v : v;
}

int parse_int(const char* s) {
  int v = 0;
  for (; *s >= '0' && *s <= '9'; ++s) v = v * 10 + (*s - '0');
  return v;
}

// ---- output: %a of a double as glibc prints it (normal numbers and zero)
int out_handle = -1;
char out_buf[512];
int out_len = 0;

void put(const char* s) {
  while (*s) out_buf[out_len++] = *s++;
}

void put_hex(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  if (b >> 63) put("-");
  const int be = static_cast<int>((b >> 52) & 0x7ff);
  std::uint64_t frac = b & ((std::uint64_t(1) << 52) - 1);
  if (be == 0 && frac == 0) {
    put("0x0p+0");
    return;
  }
  if (be == 0 || be == 0x7ff) exit_with(1);  // subnormal, inf, NaN: not expected
  char s[40];
  int k = 0;
  s[k++] = '0', s[k++] = 'x', s[k++] = '1';
  if (frac != 0) {
    s[k++] = '.';
    int digits = 13;
    while ((frac & 0xf) == 0) frac >>= 4, --digits;
    for (int i = digits - 1; i >= 0; --i) s[k++] = "0123456789abcdef"[(frac >> (4 * i)) & 0xf];
  }
  int e = be - 1023;
  s[k++] = 'p';
  s[k++] = e < 0 ? '-' : '+';
  if (e < 0) e = -e;
  char t[8];
  int n = 0;
  do t[n++] = static_cast<char>('0' + e % 10), e /= 10;
  while (e);
  while (n) s[k++] = t[--n];
  s[k] = 0;
  put(s);
}

void flush_line() {
  put("\n");
  const std::uint32_t a[3] = {static_cast<std::uint32_t>(out_handle),
                              reinterpret_cast<std::uint32_t>(out_buf),
                              static_cast<std::uint32_t>(out_len)};
  if (semihost(SYS_WRITE, a) != 0) exit_with(1);
  out_len = 0;
}

// ---- the fits, as in fit_points.cpp (points rounded to T, identity start)
constexpr int kMaxPoints = 64;
double xd[kMaxPoints], yd[kMaxPoints], zd[kMaxPoints];

template <typename T>
void fit_case(int n, int max_iter, double h, gravcal::GradientMode mode, bool use_sqrt) {
  static T x[kMaxPoints], y[kMaxPoints], z[kMaxPoints];
  for (int i = 0; i < n; ++i) x[i] = T(xd[i]), y[i] = T(yd[i]), z[i] = T(zd[i]);
  gravcal::GradientConfig<T> cfg;
  cfg.max_iter = max_iter;
  cfg.h = T(h);
  cfg.gradient = mode;
  cfg.use_sqrt = use_sqrt;
  T p[gravcal::NPARAM];
  gravcal::identity_params(p);
  gravcal::fit_gradient(p, x, y, z, n, cfg);
  for (int i = 0; i < gravcal::NPARAM; ++i) {
    if (i) put(" ");
    put_hex(static_cast<double>(p[i]));
  }
  flush_line();
}

void run() {
  in_handle = open_file("m4-cases.txt", 0);
  out_handle = open_file("m4-out.txt", 4);
  if (in_handle < 0 || out_handle < 0) exit_with(1);
  char arith[16], diff[16], it[16], hs[40], ns[16], sq[8], a[40], b[40], c[40];
  while (token(arith, sizeof arith)) {
    if (!token(diff, sizeof diff) || !token(it, sizeof it) || !token(hs, sizeof hs) ||
        !token(ns, sizeof ns) || !token(sq, sizeof sq))
      exit_with(1);
    const int n = parse_int(ns);
    if (n > kMaxPoints) exit_with(1);
    for (int i = 0; i < n; ++i) {
      if (!token(a, sizeof a) || !token(b, sizeof b) || !token(c, sizeof c)) exit_with(1);
      xd[i] = parse_hex(a), yd[i] = parse_hex(b), zd[i] = parse_hex(c);
    }
    const gravcal::GradientMode mode =
        std::strcmp(diff, "central") == 0    ? gravcal::GRADIENT_CENTRAL
        : std::strcmp(diff, "analytic") == 0 ? gravcal::GRADIENT_ANALYTIC
                                             : gravcal::GRADIENT_FORWARD;
    const int max_iter = parse_int(it);
    const double h = parse_hex(hs);
    const bool use_sqrt = sq[0] == '1';
    if (std::strcmp(arith, "double") == 0) fit_case<double>(n, max_iter, h, mode, use_sqrt);
    else if (std::strcmp(arith, "float") == 0) fit_case<float>(n, max_iter, h, mode, use_sqrt);
    else if (std::strcmp(arith, "fixed32") == 0)
      fit_case<gravcal::fixed32>(n, max_iter, h, mode, use_sqrt);
    else if (std::strcmp(arith, "fixed16") == 0)
      fit_case<gravcal::fixed16>(n, max_iter, h, mode, use_sqrt);
    else exit_with(1);
  }
  const std::uint32_t cl[1] = {static_cast<std::uint32_t>(out_handle)};
  semihost(SYS_CLOSE, cl);
  exit_with(0);
}

}  // namespace

// Start-up: copy .data, clear .bss, run.
extern "C" {
extern std::uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
void Reset_Handler() {
  for (std::uint32_t *s = &_sidata, *d = &_sdata; d < &_edata;) *d++ = *s++;
  for (std::uint32_t* d = &_sbss; d < &_ebss;) *d++ = 0;
  run();
}
__attribute__((section(".isr_vector"), used)) void (*const vectors[2])() = {
    reinterpret_cast<void (*)()>(&_estack), Reset_Handler};
}
