// A stand-in for libFuzzer's main in builds without it (GCC, the normal build): runs a fuzz
// target's LLVMFuzzerTestOneInput on every corpus file, then on random mutations of them (bit
// flips, byte edits, inserts, deletes, copies, splices, interesting integers and tokens) until
// the time is up. No coverage feedback: it is the suite's few-second smoke run and a check
// that the corpus still passes, not a replacement for scripts/fuzz.
//
//   fuzz_<target> [--seconds S] [--max-len N] [--seed K] [--timeout T] CORPUS_DIR_OR_FILE...
//
// A finding aborts the process (the targets call abort; sanitizers do the same); a signal
// handler first writes the input being run to ./fuzz-crash-<pid> and names it on stderr, so
// that `fuzz_<target> ./fuzz-crash-<pid>` reproduces it. An input that took more than T
// seconds (default 10) is a finding too, written to ./fuzz-slow-<pid> (exit 1). Exit 0 after
// the time is up, 64 for a bad command line or an unreadable path.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::vector<std::uint8_t>;

// The input being run, for the crash handler; written before each run.
const Bytes* g_current = nullptr;
char g_crash_path[64];

void WriteCrashInput(int signal_number) {
  if (g_current != nullptr) {
    const int fd = ::open(g_crash_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      const ssize_t ignored = ::write(fd, g_current->data(), g_current->size());
      (void)ignored;
      ::close(fd);
      static const char kMessage[] = "fuzz driver: the input that failed is in ";
      const ssize_t a = ::write(2, kMessage, sizeof kMessage - 1);
      const ssize_t b = ::write(2, g_crash_path, std::strlen(g_crash_path));
      const ssize_t c = ::write(2, "\n", 1);
      (void)a, (void)b, (void)c;
    }
  }
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

bool ReadFile(const std::filesystem::path& path, Bytes* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

// Values that sit on the edges parsers get wrong, as bytes (little-endian) and as text.
const std::uint64_t kInterestingIntegers[] = {0,
                                              1,
                                              2,
                                              0x7f,
                                              0x80,
                                              0xff,
                                              0x7fff,
                                              0x8000,
                                              0xffff,
                                              0x7fffffff,
                                              0x80000000u,
                                              0xffffffffu,
                                              0x7fffffffffffffffull,
                                              0x8000000000000000ull,
                                              0xffffffffffffffffull};
const char* const kInterestingTokens[] = {"-1",
                                          "0",
                                          "1e308",
                                          "-1e308",
                                          "nan",
                                          "inf",
                                          "-inf",
                                          "4294967296",
                                          "1e-320",
                                          "2147483648",
                                          "999999999999",
                                          " ",
                                          "\n",
                                          "#",
                                          ",",
                                          "{",
                                          "}",
                                          "[",
                                          "]",
                                          "\"",
                                          "-0",
                                          "0x10",
                                          "1.7976931348623157e308"};

class Mutator {
 public:
  Mutator(const std::vector<Bytes>& corpus, std::uint64_t seed, std::size_t max_len)
      : corpus_(corpus), rng_(seed), max_len_(max_len) {}

  Bytes Next() {
    Bytes data = corpus_[Below(corpus_.size())];
    const int edits = 1 + static_cast<int>(Below(4));
    for (int i = 0; i < edits; ++i) Edit(&data);
    if (data.size() > max_len_) data.resize(max_len_);
    return data;
  }

 private:
  std::size_t Below(std::size_t n) { return n == 0 ? 0 : rng_() % n; }

  void Insert(Bytes* data, const Bytes& piece) {
    const std::size_t at = Below(data->size() + 1);
    data->insert(data->begin() + static_cast<std::ptrdiff_t>(at), piece.begin(), piece.end());
  }

  void Edit(Bytes* data) {
    switch (Below(8)) {
      case 0:  // flip a bit
        if (!data->empty()) (*data)[Below(data->size())] ^= std::uint8_t(1u << Below(8));
        break;
      case 1:  // set a byte
        if (!data->empty()) (*data)[Below(data->size())] = std::uint8_t(rng_());
        break;
      case 2: {  // insert random bytes
        Bytes piece(1 + Below(8));
        for (std::uint8_t& b : piece) b = std::uint8_t(rng_());
        Insert(data, piece);
        break;
      }
      case 3: {  // delete a range
        if (data->empty()) break;
        const std::size_t at = Below(data->size());
        const std::size_t n = 1 + Below(std::min<std::size_t>(16, data->size() - at));
        data->erase(data->begin() + static_cast<std::ptrdiff_t>(at),
                    data->begin() + static_cast<std::ptrdiff_t>(at + n));
        break;
      }
      case 4: {  // copy a range of itself elsewhere
        if (data->empty()) break;
        const std::size_t at = Below(data->size());
        const std::size_t n = 1 + Below(std::min<std::size_t>(64, data->size() - at));
        Insert(data, Bytes(data->begin() + static_cast<std::ptrdiff_t>(at),
                           data->begin() + static_cast<std::ptrdiff_t>(at + n)));
        break;
      }
      case 5: {  // splice: a piece of another corpus input
        const Bytes& other = corpus_[Below(corpus_.size())];
        if (other.empty()) break;
        const std::size_t at = Below(other.size());
        const std::size_t n = 1 + Below(other.size() - at);
        Insert(data, Bytes(other.begin() + static_cast<std::ptrdiff_t>(at),
                           other.begin() + static_cast<std::ptrdiff_t>(at + n)));
        break;
      }
      case 6: {  // overwrite 1, 2, 4 or 8 bytes with an interesting integer
        const std::size_t width = std::size_t{1} << Below(4);
        if (data->size() < width) break;
        const std::uint64_t value = kInterestingIntegers[Below(std::size(kInterestingIntegers))];
        std::memcpy(data->data() + Below(data->size() - width + 1), &value, width);
        break;
      }
      default: {  // insert an interesting token
        const char* token = kInterestingTokens[Below(std::size(kInterestingTokens))];
        Insert(data, Bytes(token, token + std::strlen(token)));
        break;
      }
    }
  }

  const std::vector<Bytes>& corpus_;
  std::mt19937_64 rng_;
  std::size_t max_len_;
};

int Usage(const char* why) {
  std::fprintf(stderr,
               "fuzz driver: %s\nusage: fuzz_<target> [--seconds S] [--max-len N] [--seed K] "
               "[--timeout T] CORPUS_DIR_OR_FILE...\n",
               why);
  return 64;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 0.0;
  std::uint64_t max_len = 4096;
  std::uint64_t seed = 1;
  double timeout = 10.0;
  std::vector<std::filesystem::path> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--seconds" && has_value) {
      if (!absl::SimpleAtod(argv[++i], &seconds) || !(seconds >= 0.0)) {
        return Usage("--seconds takes a number >= 0");
      }
    } else if (arg == "--max-len" && has_value) {
      if (!absl::SimpleAtoi(argv[++i], &max_len) || max_len == 0) {
        return Usage("--max-len takes a positive integer");
      }
    } else if (arg == "--timeout" && has_value) {
      if (!absl::SimpleAtod(argv[++i], &timeout) || !(timeout > 0.0)) {
        return Usage("--timeout takes a number > 0");
      }
    } else if (arg == "--seed" && has_value) {
      if (!absl::SimpleAtoi(argv[++i], &seed)) return Usage("--seed takes an integer");
    } else if (arg.rfind("--", 0) == 0) {
      return Usage(("unknown option " + arg).c_str());
    } else {
      paths.emplace_back(arg);
    }
  }
  if (paths.empty()) return Usage("no corpus given");

  std::vector<std::filesystem::path> files;
  for (const std::filesystem::path& path : paths) {
    std::error_code error;
    if (std::filesystem::is_directory(path, error)) {
      for (const auto& entry : std::filesystem::recursive_directory_iterator(path)) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
    } else if (std::filesystem::is_regular_file(path, error)) {
      files.push_back(path);
    } else {
      return Usage(("no such file or directory: " + path.string()).c_str());
    }
  }
  std::sort(files.begin(), files.end());  // a fixed order, so runs repeat

  std::snprintf(g_crash_path, sizeof g_crash_path, "fuzz-crash-%ld", static_cast<long>(::getpid()));
  for (int signal_number : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL}) {
    ::signal(signal_number, WriteCrashInput);
  }

  // Runs one input; false (after saving it) when it took longer than `timeout`.
  auto run = [timeout](const Bytes& data) {
    g_current = &data;
    const auto begin = std::chrono::steady_clock::now();
    LLVMFuzzerTestOneInput(data.data(), data.size());
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    g_current = nullptr;
    if (took <= timeout) return true;
    const std::string path = "fuzz-slow-" + std::to_string(::getpid());
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(data.data()),
               static_cast<std::streamsize>(data.size()));
    std::fprintf(stderr,
                 "fuzz driver: an input took %.1f s (more than --timeout %.1f); it is in %s\n",
                 took, timeout, path.c_str());
    return false;
  };

  const auto start = std::chrono::steady_clock::now();
  std::vector<Bytes> corpus;
  std::int64_t runs = 0;
  for (const std::filesystem::path& file : files) {
    Bytes data;
    if (!ReadFile(file, &data)) return Usage(("cannot read " + file.string()).c_str());
    if (!run(data)) return 1;
    ++runs;
    corpus.push_back(std::move(data));
  }
  if (corpus.empty()) corpus.emplace_back();

  Mutator mutator(corpus, seed, max_len);
  const auto deadline = start + std::chrono::duration<double>(seconds);
  std::int64_t mutations = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (!run(mutator.Next())) return 1;
    ++mutations;
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("fuzz driver: %lld corpus files and %lld mutations run in %.1f s, no findings\n",
              static_cast<long long>(runs), static_cast<long long>(mutations), elapsed);
  std::fflush(stdout);
  // Targets may hold servers and threads that are never stopped (fuzz_requests): leave
  // without running static destructors under them.
  std::_Exit(0);
}
