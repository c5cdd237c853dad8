// INSCRIBE_CLONES_X86_64_V2: put before a hot function to compile it twice, for x86-64-v2
// (popcnt, SSE4.1) and for the baseline, one chosen when the library loads (GCC's
// target_clones, an ifunc resolver). Under ThreadSanitizer that resolver runs before TSan's
// runtime is set up and the program crashes at start (GCC 12), so there only the baseline is
// built.
#pragma once

#if defined(__SANITIZE_THREAD__)
#define INSCRIBE_CLONES_X86_64_V2
#else
#define INSCRIBE_CLONES_X86_64_V2 __attribute__((target_clones("arch=x86-64-v2", "default")))
#endif
