// MBOPT_CHECK: a broken invariant is a bug in mbopt, not bad input. It aborts
// with the condition, the place and a message, so the bug is found, not hidden.
#pragma once

#include <cstdio>
#include <cstdlib>

#define MBOPT_CHECK(cond, msg)                                              \
  do {                                                                      \
    if (!(cond)) {                                                          \
      std::fprintf(stderr, "%s:%d: check failed: %s: %s\n", __FILE__,       \
                   __LINE__, #cond, (msg));                                 \
      std::abort();                                                         \
    }                                                                       \
  } while (0)
