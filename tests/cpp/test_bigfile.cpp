// A file over 2 GiB (and over 4 GiB) through FileSource (decode.hpp): its
// size, and seeks and reads past 2^31 and 2^32 bytes. std::ftell and
// std::fseek take a long, 32 bits on Windows and on 32-bit Linux, where
// such a file would lose its size and could not be seeked; `make` runs this
// built for the host and for 32-bit x86 (-m32, with 64-bit off_t), whose
// long is 32 bits as Windows' is; make cross-check builds it for Windows
// (mingw-w64) and runs it under wine. The file is sparse (written only at its
// start and at the two marks), so it takes a few kB of disk.
//   make -C tests/cpp test_bigfile && ./test_bigfile [directory]
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "gravcal/decoders/decode.hpp"

// Windows' long is 32 bits (LLP64): the build for Windows proves it here,
// so its run (under wine, make cross-check) is a run with a 32-bit long
#if defined(_WIN32)
static_assert(sizeof(long) == 4, "Windows' long is 32 bits");
#endif

static int failures = 0;
#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      std::printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);     \
      ++failures;                                                     \
    }                                                                 \
  } while (0)

static const std::int64_t kMarks[3] = {0, (std::int64_t(1) << 31) + 5, (std::int64_t(1) << 32) + 7};

static void mark_bytes(int k, unsigned char* m) {
  for (int i = 0; i < 16; ++i) m[i] = static_cast<unsigned char>(0x30 + 16 * k + i);
}

int main(int argc, char** argv) {
  const char* dir = argc > 1 ? argv[1] : std::getenv("TMPDIR");
  const std::string path = std::string(dir && *dir ? dir : "/tmp") + "/gravcal-bigfile-" +
                           std::to_string(static_cast<long long>(sizeof(long))) + ".bin";
  // the sparse file, written through the same 64-bit helper
  std::FILE* f = std::fopen(path.c_str(), "wb");
  CHECK(f != nullptr);
  if (f == nullptr) return 1;
  bool wrote = true;
  for (int k = 0; k < 3; ++k) {
    unsigned char m[16];
    mark_bytes(k, m);
    wrote = wrote && gravcal::file_seek64(f, kMarks[k], SEEK_SET) &&
            std::fwrite(m, 1, sizeof m, f) == sizeof m &&
            gravcal::file_tell64(f) == kMarks[k] + 16;
  }
  CHECK(wrote);
  CHECK(std::fclose(f) == 0);
  const std::int64_t size = kMarks[2] + 16;
  {
    gravcal::FileSource src(path.c_str());
    CHECK(src.is_open());
    CHECK(src.size() == size);
    // from the last mark back to the first, then forward again
    for (int k : {2, 1, 0, 2}) {
      unsigned char want[16], got[16] = {0};
      mark_bytes(k, want);
      CHECK(src.seek(kMarks[k]));
      CHECK(src.position() == kMarks[k]);
      CHECK(gravcal::read_full(src, got, sizeof got) == sizeof got);
      CHECK(std::memcmp(got, want, sizeof got) == 0);
    }
    // the end of the file is the end of the input
    unsigned char one = 0;
    CHECK(src.read(&one, 1) == 0 && !src.failed());
    CHECK(src.position() == size);
    // between the marks: zeros (a hole reads as zeros)
    CHECK(src.seek(kMarks[1] - 8));
    unsigned char z[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    CHECK(gravcal::read_full(src, z, sizeof z) == sizeof z);
    CHECK(z[0] == 0 && z[7] == 0);
  }
  std::remove(path.c_str());
  std::printf("file of %lld bytes (sizeof(long) = %d): size, seeks and reads past 2^31 and 2^32 %s\n",
              static_cast<long long>(size), static_cast<int>(sizeof(long)),
              failures ? "FAILED" : "correct");
  return failures ? 1 : 0;
}
