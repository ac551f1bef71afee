/* The interop client's own oracle for paths: its map and an exact line walk over it, written
 * independently of the node's planner (plain C, no DDS). A path passes when every pose lies in a
 * free cell and no straight segment between consecutive poses enters the interior of a blocked
 * cell (touching a blocked cell's edge or corner is not entering it).
 *
 * Cells: row-major, row 0 at the origin, cell (cx, cy) covers [ox + cx r, ox + (cx + 1) r) x
 * [oy + cy r, oy + (cy + 1) r). Values as in nav_msgs/OccupancyGrid: 0..100, -1 unknown; a cell is
 * free when its value is in 0..free_below-1 (the client sends 0 and 100 only). */
#ifndef VNSBA_INTEROP_GRID_ORACLE_H
#define VNSBA_INTEROP_GRID_ORACLE_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

typedef struct {
  int width, height;
  double resolution;
  double origin_x, origin_y;
  int free_below; /* a value v with 0 <= v < free_below is free; anything else is blocked */
  const int8_t* data;
} Grid;

bool grid_cell_free(const Grid* g, int cx, int cy);
/* The cell containing (x, y); false outside the map. */
bool grid_cell_of(const Grid* g, double x, double y, int* cx, int* cy);
bool grid_point_free(const Grid* g, double x, double y);
void grid_cell_centre(const Grid* g, int cx, int cy, double* x, double* y);

/* True when the segment (x0, y0)-(x1, y1) has a point in the open interior of a blocked cell or
 * outside the map; *cx, *cy (may be NULL) receive one such cell. Exact: every cell of the
 * segment's bounding box is clipped against the segment, no sampling. */
bool grid_segment_blocked(const Grid* g, double x0, double y0, double x1, double y1, int* cx,
                          int* cy);

/* Checks a polyline of n points (xy[2i], xy[2i+1]): n >= 2, every point in a free cell, every
 * segment clear (grid_segment_blocked), consecutive points at most max_step apart (<= 0: no
 * bound), the first within tolerance of (sx, sy) and the last within tolerance of (gx, gy).
 * Returns the number of failures, each described on `report` (NULL: none) after `what`. */
int grid_check_polyline(const Grid* g, const char* what, const double* xy, int n, double sx,
                        double sy, double gx, double gy, double tolerance, double max_step,
                        FILE* report);

#endif /* VNSBA_INTEROP_GRID_ORACLE_H */
