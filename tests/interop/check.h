/* CHECK(condition, printf format, ...): when the condition is false, prints "FAILED: ..." with
 * the file and line on stderr and counts it in `failures`: the clients' shared counter
 * (client_common.h), or the including file's own `static int failures` (the oracle's test). Each
 * reports every failed check this way and exits 1 at the end when any failed. */
#ifndef VNSBA_INTEROP_CHECK_H
#define VNSBA_INTEROP_CHECK_H

#include <stdio.h>

#define CHECK(cond, ...)                                 \
  do {                                                   \
    if (!(cond)) {                                       \
      fprintf(stderr, "FAILED: " __VA_ARGS__);           \
      fprintf(stderr, " [%s:%d]\n", __FILE__, __LINE__); \
      ++failures;                                        \
    }                                                    \
  } while (0)

#endif /* VNSBA_INTEROP_CHECK_H */
