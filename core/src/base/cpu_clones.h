// INSCRIBE_CLONES_X86_64_V2: put before a hot function to compile it twice, for x86-64-v2
// (popcnt, SSE4.1) and for the baseline, one chosen when the library loads (GCC's
// target_clones, an ifunc resolver). GCC only, and not under ThreadSanitizer, whose runtime is
// not set up yet when the resolver runs (the program crashes at start, GCC 12). Clang 14 (the
// fuzz build) refuses the attribute on a function already called in the file ("cannot become
// a multiversioned function after first usage") and, where a header carries it, makes calls
// from other files jump to the resolver itself instead of the clone it returns. There only
// the baseline is built.
#pragma once

#if defined(__SANITIZE_THREAD__) || defined(__clang__)
#define INSCRIBE_CLONES_X86_64_V2
#else
#define INSCRIBE_CLONES_X86_64_V2 __attribute__((target_clones("arch=x86-64-v2", "default")))
#endif
