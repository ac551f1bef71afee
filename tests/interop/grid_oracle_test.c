/* The interop client's oracle checked on its own (no DDS): hand-made segments whose answer is
 * known exactly (through a cell, along its edge, through its corner, a hair inside), and random
 * segments against dense sampling: a sample strictly inside a blocked cell must make the line
 * walk report the segment blocked. */
#include "grid_oracle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"

static int failures = 0;

/* 6 x 6 cells of 0.5 m at (-1, 2); blocked: (2, 2) and (3, 3), which share one corner. */
enum { kW = 6, kH = 6 };
static int8_t cells[kW * kH];
static const Grid g = {kW, kH, 0.5, -1.0, 2.0, 65, cells};

/* x of column boundary i, y of row boundary j. */
static double bx(double i) {
  return g.origin_x + i * g.resolution;
}
static double by(double j) {
  return g.origin_y + j * g.resolution;
}

static void hand_made(void) {
  cells[2 * kW + 2] = 100;
  cells[3 * kW + 3] = 100;
  int cx = -2, cy = -2;
  /* Through the middle of (2, 2). */
  CHECK(
      grid_segment_blocked(&g, bx(1.5), by(2.5), bx(3.5), by(2.5), &cx, &cy) && cx == 2 && cy == 2,
      "a segment through cell (2, 2) is blocked there (got %d, %d)", cx, cy);
  /* Along the left edge of (2, 2) and the bottom edge of (3, 3): not inside either. */
  CHECK(!grid_segment_blocked(&g, bx(2), by(1.5), bx(2), by(3.5), NULL, NULL),
        "a segment along a blocked cell's edge enters no blocked cell");
  CHECK(!grid_segment_blocked(&g, bx(2.5), by(3), bx(4.5), by(3), NULL, NULL),
        "a segment along the edge shared by (2, 3) and (3, 3) enters no blocked cell");
  /* Through the corner (3, 3) shared by the two blocked cells, from (2, 3) to (3, 2). */
  CHECK(!grid_segment_blocked(&g, bx(2.5), by(3.5), bx(3.5), by(2.5), NULL, NULL),
        "a segment through the corner between two blocked cells enters neither");
  /* The same, a hair toward (2, 2): it enters (2, 2). */
  const double e = 1e-9;
  CHECK(grid_segment_blocked(&g, bx(2.5) - e, by(3.5) - e, bx(3.5) - e, by(2.5) - e, &cx, &cy) &&
            cx == 2 && cy == 2,
        "a segment a hair past the corner enters (2, 2) (got %d, %d)", cx, cy);
  /* Ending on a blocked cell's edge from outside: not inside; one hair further: inside. */
  CHECK(!grid_segment_blocked(&g, bx(0.5), by(2.5), bx(2), by(2.5), NULL, NULL),
        "a segment ending on a blocked cell's edge enters nothing");
  CHECK(grid_segment_blocked(&g, bx(0.5), by(2.5), bx(2) + e, by(2.5), NULL, NULL),
        "a segment ending a hair inside a blocked cell enters it");
  /* A point. */
  CHECK(grid_segment_blocked(&g, bx(2.5), by(2.5), bx(2.5), by(2.5), NULL, NULL),
        "a point inside a blocked cell is blocked");
  CHECK(!grid_segment_blocked(&g, bx(0.5), by(0.5), bx(0.5), by(0.5), NULL, NULL),
        "a point inside a free cell is free");
  /* Off the map. */
  CHECK(grid_segment_blocked(&g, bx(0.5), by(0.5), bx(-0.5), by(0.5), &cx, &cy) && cx == -1,
        "a segment leaving the map is blocked");
  CHECK(grid_point_free(&g, bx(0.5), by(0.5)) && !grid_point_free(&g, bx(2.5), by(2.5)) &&
            !grid_point_free(&g, bx(6.5), by(0.5)),
        "grid_point_free: free cell, blocked cell, off the map");

  /* Polylines: a good one around the blocked cells, then each rule broken once. */
  const double good[] = {bx(0.5), by(0.5), bx(1.5), by(1.5), bx(1.5), by(4.5), bx(4.5), by(4.5)};
  CHECK(grid_check_polyline(&g, "good", good, 4, bx(0.5), by(0.5), bx(4.5), by(4.5), 1e-9, 0,
                            NULL) == 0,
        "a clear polyline passes");
  CHECK(grid_check_polyline(&g, "step", good, 4, bx(0.5), by(0.5), bx(4.5), by(4.5), 1e-9, 1.0,
                            NULL) == 2,
        "two steps of 1.5 m fail a bound of 1 m");
  CHECK(grid_check_polyline(&g, "ends", good, 4, bx(1.5), by(0.5), bx(4.5), by(4.5), 1e-9, 0,
                            NULL) == 1,
        "a polyline not at the start fails");
  const double through[] = {bx(0.5), by(2.5), bx(4.5), by(2.5)};
  CHECK(grid_check_polyline(&g, "through", through, 2, bx(0.5), by(2.5), bx(4.5), by(2.5), 1e-9, 0,
                            NULL) == 1,
        "a polyline through a blocked cell fails");
}

/* Random segments on a random grid: whenever a sample strictly inside a cell lands in a blocked
 * cell, the line walk must say blocked. Also counts the opposite (blocked without a sample in a
 * blocked cell: a short overlap the samples step over), which must stay rare. */
static void against_sampling(void) {
  srand(17);
  for (int i = 0; i < kW * kH; ++i) cells[i] = rand() % 5 == 0 ? 100 : 0;
  int blocked = 0, sampled_blocked = 0, only_walk = 0;
  const int kSegments = 20000, kSamples = 4000;
  const double w = kW * g.resolution, h = kH * g.resolution;
  for (int s = 0; s < kSegments; ++s) {
    const double x0 = g.origin_x + w * rand() / ((double)RAND_MAX + 1);
    const double y0 = g.origin_y + h * rand() / ((double)RAND_MAX + 1);
    /* Mostly short segments (path steps), some across the map (pruned paths). */
    const double reach = s % 4 == 0 ? w : 2 * g.resolution;
    const double x1 =
        fmin(fmax(x0 + reach * (2.0 * rand() / RAND_MAX - 1), g.origin_x), g.origin_x + w - 1e-9);
    const double y1 =
        fmin(fmax(y0 + reach * (2.0 * rand() / RAND_MAX - 1), g.origin_y), g.origin_y + h - 1e-9);
    const bool walk = grid_segment_blocked(&g, x0, y0, x1, y1, NULL, NULL);
    bool sample = false;
    for (int k = 0; k <= kSamples && !sample; ++k) {
      const double t = (double)k / kSamples;
      sample = !grid_point_free(&g, x0 + t * (x1 - x0), y0 + t * (y1 - y0));
    }
    blocked += walk;
    sampled_blocked += sample;
    only_walk += walk && !sample;
    CHECK(!sample || walk,
          "segment (%.6f, %.6f)-(%.6f, %.6f): a sample lies in a blocked cell, the walk says "
          "clear",
          x0, y0, x1, y1);
    if (failures > 10) return;
  }
  printf("random segments: %d, blocked by the walk %d, by sampling %d, by the walk only %d\n",
         kSegments, blocked, sampled_blocked, only_walk);
  CHECK(blocked > kSegments / 10 && blocked < kSegments, "the random grid tests both outcomes");
  CHECK(only_walk * 100 <= blocked, "the walk alone finds %d of %d blocked segments", only_walk,
        blocked);
}

int main(void) {
  hand_made();
  against_sampling();
  if (failures > 0) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("grid oracle: all checks passed\n");
  return 0;
}
