#include "grid_oracle.h"

#include <math.h>
#include <stdarg.h>

bool grid_cell_free(const Grid* g, int cx, int cy) {
  if (cx < 0 || cy < 0 || cx >= g->width || cy >= g->height) return false;
  const int v = g->data[(long)cy * g->width + cx];
  return v >= 0 && v < g->free_below;
}

bool grid_cell_of(const Grid* g, double x, double y, int* cx, int* cy) {
  const double fx = floor((x - g->origin_x) / g->resolution);
  const double fy = floor((y - g->origin_y) / g->resolution);
  if (!(fx >= 0 && fy >= 0 && fx < g->width && fy < g->height)) return false;
  *cx = (int)fx;
  *cy = (int)fy;
  return true;
}

bool grid_point_free(const Grid* g, double x, double y) {
  int cx, cy;
  return grid_cell_of(g, x, y, &cx, &cy) && grid_cell_free(g, cx, cy);
}

void grid_cell_centre(const Grid* g, int cx, int cy, double* x, double* y) {
  *x = g->origin_x + (cx + 0.5) * g->resolution;
  *y = g->origin_y + (cy + 0.5) * g->resolution;
}

/* The parameters t in [0, 1] where p + t d lies strictly between lo and hi narrow (a, b). */
static void clip_open(double p, double d, double lo, double hi, double* a, double* b) {
  if (d == 0.0) {
    if (!(p > lo && p < hi)) *b = -INFINITY; /* never strictly inside on this axis */
    return;
  }
  double t0 = (lo - p) / d, t1 = (hi - p) / d;
  if (t0 > t1) {
    const double t = t0;
    t0 = t1;
    t1 = t;
  }
  if (t0 > *a) *a = t0;
  if (t1 < *b) *b = t1;
}

/* Does the closed segment meet the open box (x_lo, x_hi) x (y_lo, y_hi)? The set of t with
 * a < t < b (open in each axis) and 0 <= t <= 1 is non-empty. */
static bool segment_meets_open_box(double x0, double y0, double dx, double dy, double x_lo,
                                   double x_hi, double y_lo, double y_hi) {
  double a = -INFINITY, b = INFINITY;
  clip_open(x0, dx, x_lo, x_hi, &a, &b);
  clip_open(y0, dy, y_lo, y_hi, &a, &b);
  return a < b && a < 1.0 && b > 0.0;
}

bool grid_segment_blocked(const Grid* g, double x0, double y0, double x1, double y1, int* cx,
                          int* cy) {
  const double r = g->resolution;
  const double dx = x1 - x0, dy = y1 - y0;
  /* Outside the map: an end point off the grid (the map is a rectangle, so a segment between
   * two points on it stays on it). */
  int ignored_x, ignored_y;
  if (!grid_cell_of(g, x0, y0, &ignored_x, &ignored_y) ||
      !grid_cell_of(g, x1, y1, &ignored_x, &ignored_y)) {
    if (cx) *cx = -1;
    if (cy) *cy = -1;
    return true;
  }
  const int cx_lo = (int)floor((fmin(x0, x1) - g->origin_x) / r) - 1;
  const int cx_hi = (int)floor((fmax(x0, x1) - g->origin_x) / r) + 1;
  const int cy_lo = (int)floor((fmin(y0, y1) - g->origin_y) / r) - 1;
  const int cy_hi = (int)floor((fmax(y0, y1) - g->origin_y) / r) + 1;
  for (int y = cy_lo; y <= cy_hi; ++y) {
    for (int x = cx_lo; x <= cx_hi; ++x) {
      if (x < 0 || y < 0 || x >= g->width || y >= g->height || grid_cell_free(g, x, y)) continue;
      const double x_lo = g->origin_x + x * r, y_lo = g->origin_y + y * r;
      if (segment_meets_open_box(x0, y0, dx, dy, x_lo, x_lo + r, y_lo, y_lo + r)) {
        if (cx) *cx = x;
        if (cy) *cy = y;
        return true;
      }
    }
  }
  return false;
}

static void report_failure(FILE* report, const char* format, ...) {
  if (report == NULL) return;
  va_list args;
  va_start(args, format);
  vfprintf(report, format, args);
  va_end(args);
}

int grid_check_polyline(const Grid* g, const char* what, const double* xy, int n, double sx,
                        double sy, double gx, double gy, double tolerance, double max_step,
                        FILE* report) {
  int failures = 0;
  if (n < 2) {
    report_failure(report, "FAILED: %s: %d poses, expected at least 2\n", what, n);
    return 1;
  }
  for (int i = 0; i < n; ++i) {
    if (!grid_point_free(g, xy[2 * i], xy[2 * i + 1])) {
      report_failure(report, "FAILED: %s: pose %d (%.4f, %.4f) is not in a free cell\n", what, i,
                     xy[2 * i], xy[2 * i + 1]);
      ++failures;
    }
  }
  for (int i = 0; i + 1 < n; ++i) {
    const double x0 = xy[2 * i], y0 = xy[2 * i + 1], x1 = xy[2 * i + 2], y1 = xy[2 * i + 3];
    int bx, by;
    if (grid_segment_blocked(g, x0, y0, x1, y1, &bx, &by)) {
      report_failure(
          report, "FAILED: %s: segment %d (%.4f, %.4f)-(%.4f, %.4f) enters blocked cell (%d, %d)\n",
          what, i, x0, y0, x1, y1, bx, by);
      ++failures;
    }
    const double step = hypot(x1 - x0, y1 - y0);
    if (max_step > 0 && step > max_step) {
      report_failure(report, "FAILED: %s: poses %d and %d are %.4f m apart, more than %.4f m\n",
                     what, i, i + 1, step, max_step);
      ++failures;
    }
  }
  const double start_off = hypot(xy[0] - sx, xy[1] - sy);
  const double goal_off = hypot(xy[2 * n - 2] - gx, xy[2 * n - 1] - gy);
  if (!(start_off <= tolerance)) {
    report_failure(report,
                   "FAILED: %s: first pose (%.4f, %.4f) is %.2g m from the start (%.4f, %.4f)\n",
                   what, xy[0], xy[1], start_off, sx, sy);
    ++failures;
  }
  if (!(goal_off <= tolerance)) {
    report_failure(report,
                   "FAILED: %s: last pose (%.4f, %.4f) is %.2g m from the goal (%.4f, %.4f)\n",
                   what, xy[2 * n - 2], xy[2 * n - 1], goal_off, gx, gy);
    ++failures;
  }
  return failures;
}
