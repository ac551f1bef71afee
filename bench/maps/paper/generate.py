#!/usr/bin/env python3
"""Draws the paper's benchmark maps (Li, Li, Dai, Sensors 2024, section 4 and Figure 3).

Writes, next to this script, one Moving AI map (`<name>.map`) and one scenario file
(`<name>.map.scen`, version 1) per map. The scenario's optimal length is computed here by an
independent octile Dijkstra without corner cutting (the Moving AI convention), so the files can
be checked against the C++ A*.

The maps are drawn from the paper's text; its figures are not reproduced cell for cell. Each
drawing function says which sentence it follows. The random map (Figure 3d) comes from
random.Random(RANDOM_SEED): the committed text is what this script writes, and rerunning it
reproduces the same bytes.

Coordinates in this script: grid[y][x], y = 0 is the bottom row (as in the world and in the C++
core); the files store the top row first, and the scenario's y counts from the top line.
"""
import heapq
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
RANDOM_SEED = 20241029  # the paper's publication date
RANDOM_DENSITY = 0.20


def empty(w, h):
    return [[0] * w for _ in range(h)]


def block(g, x0, y0, x1, y1):
    """Blocks the inclusive rectangle [x0, x1] x [y0, y1] (clipped to the map)."""
    h, w = len(g), len(g[0])
    for y in range(max(0, y0), min(h - 1, y1) + 1):
        for x in range(max(0, x0), min(w - 1, x1) + 1):
            g[y][x] = 1


def clear(g, x0, y0, x1, y1):
    h, w = len(g), len(g[0])
    for y in range(max(0, y0), min(h - 1, y1) + 1):
        for x in range(max(0, x0), min(w - 1, x1) + 1):
            g[y][x] = 0


def staircase(g, x0, y0, steps, dx, dy, thickness=2):
    """A diagonal wall of `steps` cells going (dx, dy) per step, `thickness` cells thick."""
    for i in range(steps):
        x, y = x0 + i * dx, y0 + i * dy
        block(g, x, y, x + thickness - 1, y + thickness - 1)


# --- Maps A-D (section 4, Figures 8-11) -------------------------------------------------------

def map_a():
    """A, 20 x 20: "a simple 20 x 20 map": a few separate blocks, some across the diagonal."""
    g = empty(20, 20)
    block(g, 3, 4, 6, 7)
    block(g, 9, 8, 11, 12)
    block(g, 14, 12, 17, 14)
    block(g, 4, 13, 6, 16)
    block(g, 13, 3, 16, 5)
    return g


def map_b():
    """B, 40 x 40: "zigzag-shaped obstacles" and "branching paths in the middle of the map", where
    unidirectional A* "entered the wrong branch at the center": zigzag walls near start and goal,
    and in the middle a cup open towards the start whose inside is the tempting (dead-end) branch,
    with the two real branches around it."""
    g = empty(40, 40)
    # Zigzag wall near the start: up-right, down-right, up-right (a W), gaps at its ends.
    staircase(g, 2, 14, 6, 1, -1)
    staircase(g, 8, 9, 5, 1, 1)
    staircase(g, 13, 13, 5, 1, -1)
    # Zigzag wall near the goal (the same shape rotated by 180 degrees).
    staircase(g, 36, 24, 6, -1, 1)
    staircase(g, 30, 29, 5, -1, -1)
    staircase(g, 25, 25, 5, -1, 1)
    # The middle: a cup (walls on its top and right, open to the lower left), on the diagonal.
    block(g, 15, 25, 26, 26)   # top wall of the cup
    block(g, 25, 14, 26, 26)   # right wall of the cup
    block(g, 19, 19, 21, 21)   # a pillar inside, so the wrong branch forks again
    # Branch walls that split each way around the cup into two corridors.
    block(g, 8, 28, 12, 29)
    block(g, 28, 8, 29, 12)
    return g


def map_c():
    """C, 60 x 60: "indoor scenarios such as home and office": rooms off a central corridor,
    where "the line between the forward and backward paths is parallel to the x-axis with fewer
    obstacles". Walls 1 cell thick, doors 3 cells wide, furniture blocks in the rooms."""
    g = empty(60, 60)
    corridor_low, corridor_high = 27, 32  # free rows of the corridor
    # Corridor walls, with doors into each room.
    block(g, 0, corridor_low - 1, 59, corridor_low - 1)
    block(g, 0, corridor_high + 1, 59, corridor_high + 1)
    # Rooms below the corridor: partitions at x = 14, 30, 44; rooms above: x = 18, 36, 48.
    for x in (14, 30, 44):
        block(g, x, 0, x, corridor_low - 1)
    for x in (18, 36, 48):
        block(g, x, corridor_high + 1, x, 59)
    # A second row of small offices above the corridor's top-left rooms (a horizontal wall).
    block(g, 0, 46, 18, 46)
    clear(g, 8, 46, 10, 46)
    # Doors from the rooms to the corridor (3 cells wide); the bottom-left room's door is at its
    # far end, so the path must cross the room.
    for x0 in (10, 20, 36, 50):
        clear(g, x0, corridor_low - 1, x0 + 2, corridor_low - 1)
    for x0 in (6, 25, 40, 52):
        clear(g, x0, corridor_high + 1, x0 + 2, corridor_high + 1)
    # Doors between neighbouring rooms (a home's connecting doors).
    clear(g, 30, 8, 30, 10)
    clear(g, 48, 50, 48, 52)
    # Furniture: beds, tables, shelves, desks.
    block(g, 3, 5, 8, 9)
    block(g, 2, 16, 5, 22)
    block(g, 18, 4, 26, 6)
    block(g, 20, 14, 24, 18)
    block(g, 34, 3, 40, 4)
    block(g, 35, 12, 37, 20)
    block(g, 48, 6, 55, 9)
    block(g, 50, 16, 53, 21)
    block(g, 4, 37, 10, 40)
    block(g, 3, 52, 8, 55)
    block(g, 24, 40, 30, 42)
    block(g, 22, 50, 32, 52)
    block(g, 40, 38, 43, 47)
    block(g, 39, 53, 45, 55)
    block(g, 52, 40, 56, 45)
    block(g, 51, 49, 53, 50)
    # Pillars in the corridor.
    block(g, 28, 29, 29, 30)
    block(g, 46, 29, 47, 30)
    return g


def map_d():
    """D, 80 x 80: "ports and warehouses, where obstacles represent goods placed in the scene":
    racks of goods in rows (2 cells deep, 10-14 long) with aisles between them, cross aisles,
    container stacks and loose pallets."""
    g = empty(80, 80)
    # Rack rows in three bays separated by cross aisles; rows alternate their offsets so the
    # aisles do not all line up.
    bays = [(4, 24), (30, 50), (56, 76)]  # x ranges of the bays
    for bay_index, (bx0, bx1) in enumerate(bays):
        y = 4 + bay_index  # each bay starts a row higher
        row = 0
        while y + 1 < 62:
            shift = 2 if row % 2 else 0
            block(g, bx0 + shift, y, bx1 - 2 + shift, y + 1)
            y += 5
            row += 1
    # Container stacks on the quay (top band).
    for x0 in (2, 14, 30, 46, 60):
        block(g, x0, 66, x0 + 8, 69)
    for x0 in (8, 24, 40, 54, 68):
        block(g, x0, 73, x0 + 6, 75)
    # Loose pallets in the cross aisles.
    rng = random.Random(7)
    for _ in range(18):
        x, y = rng.randrange(2, 78), rng.randrange(2, 64)
        block(g, x, y, x + 1, y + 1)
    # Keep start and goal areas clear.
    clear(g, 0, 0, 2, 2)
    clear(g, 77, 77, 79, 79)
    return g


# --- The four maps of Figure 3 (the omega/eta sweep) -------------------------------------------

def sweep_simple():
    """Figure 3a, "simple map": a few separate blocks."""
    g = empty(40, 40)
    block(g, 8, 6, 13, 11)
    block(g, 24, 14, 29, 19)
    block(g, 12, 24, 17, 29)
    block(g, 28, 30, 33, 34)
    return g


def sweep_middle():
    """Figure 3b, "obstacles placed in the middle": one large block across the diagonal."""
    g = empty(40, 40)
    block(g, 12, 12, 27, 27)
    return g


def sweep_bars():
    """Figure 3c, "bar-shaped obstructions": long thin bars, alternating from the left and the
    right edge, so the path weaves between them."""
    g = empty(40, 40)
    for i, y in enumerate(range(5, 36, 6)):
        if i % 2 == 0:
            block(g, 0, y, 29, y + 1)
        else:
            block(g, 10, y, 39, y + 1)
    return g


def connected(g, s, t):
    return dijkstra(g, s, t) is not None


def sweep_random():
    """Figure 3d, "random map with 20 % obstacle density": each cell blocked with probability
    0.2 from random.Random(RANDOM_SEED); start and goal cleared; the next seed is tried until
    start and goal are connected (the seed actually used is printed)."""
    seed = RANDOM_SEED
    while True:
        rng = random.Random(seed)
        g = [[1 if rng.random() < RANDOM_DENSITY else 0 for _ in range(40)] for _ in range(40)]
        g[0][0] = 0
        g[39][39] = 0
        if connected(g, (0, 0), (39, 39)):
            print(f"sweep_random: seed {seed}, density "
                  f"{sum(map(sum, g)) / 1600:.3f}")
            return g
        seed += 1


# --- Octile Dijkstra (independent of the C++ code) --------------------------------------------

def dijkstra(g, s, t):
    h, w = len(g), len(g[0])
    dist = {s: 0.0}
    heap = [(0.0, s)]
    while heap:
        d, (x, y) = heapq.heappop(heap)
        if (x, y) == t:
            return d
        if d > dist[(x, y)]:
            continue
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                if dx == 0 and dy == 0:
                    continue
                nx, ny = x + dx, y + dy
                if not (0 <= nx < w and 0 <= ny < h) or g[ny][nx]:
                    continue
                if dx and dy and (g[y][nx] or g[ny][x]):
                    continue  # no corner cutting
                nd = d + (math.sqrt(2) if dx and dy else 1.0)
                if nd < dist.get((nx, ny), math.inf):
                    dist[(nx, ny)] = nd
                    heapq.heappush(heap, (nd, (nx, ny)))
    return None


def write(name, g):
    h, w = len(g), len(g[0])
    start, goal = (0, 0), (w - 1, h - 1)  # opposite corners: bottom-left to top-right
    assert not g[start[1]][start[0]] and not g[goal[1]][goal[0]], name
    optimal = dijkstra(g, start, goal)
    assert optimal is not None, f"{name}: start and goal are not connected"
    with open(os.path.join(HERE, name + ".map"), "w", newline="\n") as f:
        f.write(f"type octile\nheight {h}\nwidth {w}\nmap\n")
        for y in range(h - 1, -1, -1):
            f.write("".join("@" if c else "." for c in g[y]) + "\n")
    with open(os.path.join(HERE, name + ".map.scen"), "w", newline="\n") as f:
        f.write("version 1\n")
        f.write(f"0\t{name}.map\t{w}\t{h}\t{start[0]}\t{h - 1 - start[1]}\t"
                f"{goal[0]}\t{h - 1 - goal[1]}\t{optimal:.8f}\n")
    density = sum(map(sum, g)) / (w * h)
    print(f"{name}: {w} x {h}, density {density:.3f}, optimal {optimal:.4f}")


if __name__ == "__main__":
    for name, draw in [("A", map_a), ("B", map_b), ("C", map_c), ("D", map_d),
                       ("sweep_simple", sweep_simple), ("sweep_middle", sweep_middle),
                       ("sweep_bars", sweep_bars), ("sweep_random", sweep_random)]:
        write(name, draw())
