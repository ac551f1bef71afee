/* CHECK(condition, printf format, ...): when the condition is false, prints "FAILED: ..." with
 * the file and line on stderr and counts it in the including file's `static int failures`. The
 * interop client and its oracle's test report every failed check this way and exit 1 at the end
 * when any failed. */
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
