// Assertion macros for programmer errors (never for bad input: that is ConfigError).
// SR_ASSERT is always on; SR_DASSERT only in builds without STOKESRODS_FAST_KERNELS.
#pragma once

#include <cstdio>
#include <cstdlib>

#define SR_ASSERT(cond, msg)                                                             \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      std::fprintf(stderr, "%s:%d: assertion failed: %s (%s)\n", __FILE__, __LINE__,   \
                   #cond, msg);                                                          \
      std::abort();                                                                      \
    }                                                                                    \
  } while (false)

#ifdef NDEBUG
#define SR_DASSERT(cond, msg) ((void)0)
#else
#define SR_DASSERT(cond, msg) SR_ASSERT(cond, msg)
#endif
