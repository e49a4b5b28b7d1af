"""The simulated robot's global planner: a path around the floorplan's walls, as Nav2's planner_server gives.

A* over the wall grid the robot already drives in (walls.py: occupied cells grown by its radius),
coarsened to about PLAN_CELL_M so a whole floor is planned in a fraction of a second in pure
Python; a coarse cell is blocked if any image pixel in it is. 8-connected, no corner cutting,
octile distance, with a higher cost next to walls (as Nav2's inflated costmap has). The cell path
is then pulled tight (a corner is dropped when the line past it stays in free coarse cells, clear
of walls where it can), so the robot drives straight legs between a few corners.

Refusals carry Nav2's ComputePathToPose error codes (nav2_msgs/action/ComputePathToPose, Jazzy),
which bt_navigator hands on in NavigateToPose's result. Pure Python, so it is unit-tested.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from .walls import Walls, grow

PLAN_CELL_M = 0.1
NEAR_CELLS = 2  # cells this close to a wall cost more (Nav2's inflation): paths keep to the middle of doors
NEAR_COST = 3.0
# Weighted A*: the octile distance counted twice. Paths at most twice the cheapest (in practice a few
# per cent longer before they are pulled tight), for a fraction of the cells expanded: a plan is a
# stall of the simulator's tick, and the wall cost above makes the plain heuristic a weak guide.
HEURISTIC_WEIGHT = 2.0
SNAP_CELLS = 3  # a start or goal in free space but in a coarse cell that touches a wall: the nearest free one

# nav2_msgs/action/ComputePathToPose result codes (Jazzy)
START_OUTSIDE_MAP = 203
GOAL_OUTSIDE_MAP = 204
START_OCCUPIED = 205
GOAL_OCCUPIED = 206
NO_VALID_PATH = 208

SQRT2 = math.sqrt(2.0)


class PlanError(Exception):
    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def path_length(points: list[tuple[float, float]]) -> float:
    return sum(math.hypot(x1 - x0, y1 - y0) for (x0, y0), (x1, y1) in zip(points, points[1:], strict=False))


class GridPlanner:
    def __init__(self, walls: Walls | None, cell_m: float = PLAN_CELL_M):
        self.walls = walls
        if walls is None:
            return
        g = walls.geometry
        self.factor = max(1, round(cell_m / g.resolution_m))
        self.cell_m = self.factor * g.resolution_m
        h, w = walls.blocked.shape
        rows, cols = -(-h // self.factor), -(-w // self.factor)
        padded = np.zeros((rows * self.factor, cols * self.factor), dtype=bool)
        padded[:h, :w] = walls.blocked
        # Rows from the image's top, as the wall grid: row 0 is the map's far (north) edge.
        self.blocked = padded.reshape(rows, self.factor, cols, self.factor).any(axis=(1, 3))
        self.rows, self.cols = rows, cols
        self.near = grow(self.blocked, NEAR_CELLS) & ~self.blocked

    # --- cells ---

    def _cell(self, x: float, y: float) -> tuple[int, int] | None:
        fine = self.walls.geometry.cell_of(x, y)
        return None if fine is None else (fine[1] // self.factor, fine[0] // self.factor)

    def _centre(self, cell: tuple[int, int]) -> tuple[float, float]:
        row, col = cell
        return self.walls.geometry.pixel_to_world((col + 0.5) * self.factor, (row + 0.5) * self.factor)

    def _free(self, row: int, col: int) -> bool:
        return 0 <= row < self.rows and 0 <= col < self.cols and not self.blocked[row, col]

    def _snap(self, cell: tuple[int, int]) -> tuple[int, int] | None:
        if self._free(*cell):
            return cell
        row, col = cell
        best = None
        for dr in range(-SNAP_CELLS, SNAP_CELLS + 1):
            for dc in range(-SNAP_CELLS, SNAP_CELLS + 1):
                if self._free(row + dr, col + dc) and (best is None or dr * dr + dc * dc < best[0]):
                    best = (dr * dr + dc * dc, (row + dr, col + dc))
        return None if best is None else best[1]

    # --- planning ---

    def plan(self, start: tuple[float, float], goal: tuple[float, float]) -> list[tuple[float, float]]:
        """Points from `start` to `goal` (both included) around the walls; PlanError when there is none."""
        if self.walls is None:
            return [start, goal]  # open ground (a boat, --no-walls): the straight line
        start_cell, goal_cell = self._cell(*start), self._cell(*goal)
        if goal_cell is None:
            raise PlanError(GOAL_OUTSIDE_MAP, f"the goal ({goal[0]:.2f}, {goal[1]:.2f}) is outside the map")
        if start_cell is None:
            raise PlanError(START_OUTSIDE_MAP, f"the robot ({start[0]:.2f}, {start[1]:.2f}) is outside the map")
        if self.walls.is_blocked(*goal):
            raise PlanError(GOAL_OCCUPIED, f"the goal ({goal[0]:.2f}, {goal[1]:.2f}) is in a wall "
                                           "or too close to one for the robot")
        snapped_goal = self._snap(goal_cell)
        if snapped_goal is None:
            raise PlanError(GOAL_OCCUPIED, f"the goal ({goal[0]:.2f}, {goal[1]:.2f}) has no room around it")
        snapped_start = self._snap(start_cell)
        if snapped_start is None:
            raise PlanError(START_OCCUPIED, f"the robot ({start[0]:.2f}, {start[1]:.2f}) is stuck in a wall")
        cells = self._astar(snapped_start, snapped_goal)
        if cells is None:
            raise PlanError(NO_VALID_PATH, f"no path from ({start[0]:.2f}, {start[1]:.2f}) to "
                                           f"({goal[0]:.2f}, {goal[1]:.2f}) around the walls")
        corners = self._pull_tight(cells)
        return [start, *[self._centre(c) for c in corners[1:-1]], goal]

    def _astar(self, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]] | None:
        if start == goal:
            return [start]
        gr, gc = goal

        def h(row: int, col: int) -> float:
            dr, dc = abs(row - gr), abs(col - gc)
            return HEURISTIC_WEIGHT * ((dr + dc) + (SQRT2 - 2) * min(dr, dc))

        cost = {start: 0.0}
        came: dict[tuple[int, int], tuple[int, int]] = {}
        frontier = [(h(*start), 0.0, start)]
        closed = set()
        while frontier:
            _, g, cell = heapq.heappop(frontier)
            if cell in closed:
                continue
            if cell == goal:
                path = [cell]
                while cell in came:
                    cell = came[cell]
                    path.append(cell)
                return path[::-1]
            closed.add(cell)
            row, col = cell
            for dr, dc, step in ((-1, 0, 1.0), (1, 0, 1.0), (0, -1, 1.0), (0, 1, 1.0),
                                 (-1, -1, SQRT2), (-1, 1, SQRT2), (1, -1, SQRT2), (1, 1, SQRT2)):
                nr, nc = row + dr, col + dc
                if not self._free(nr, nc) or (dr and dc and not (self._free(row, nc) and self._free(nr, col))):
                    continue
                ng = g + step * (1.0 + NEAR_COST * self.near[nr, nc])
                if ng < cost.get((nr, nc), math.inf):
                    cost[(nr, nc)] = ng
                    came[(nr, nc)] = cell
                    heapq.heappush(frontier, (ng + h(nr, nc), ng, (nr, nc)))
        return None

    def _line_free(self, a: tuple[int, int], b: tuple[int, int], clear: bool) -> bool:
        """Does the straight line between two cell centres stay in free cells (sampled at a quarter cell)?"""
        (r0, c0), (r1, c1) = a, b
        steps = max(1, math.ceil(4 * math.hypot(r1 - r0, c1 - c0)))
        for i in range(steps + 1):
            t = i / steps
            r, c = r0 + 0.5 + (r1 - r0) * t, c0 + 0.5 + (c1 - c0) * t
            # the cells on both sides of a line that runs along a cell border
            for rr in {math.floor(r - 0.01), math.floor(r + 0.01)}:
                for cc in {math.floor(c - 0.01), math.floor(c + 0.01)}:
                    if not self._free(rr, cc) or (clear and self.near[rr, cc]):
                        return False
        return True

    def _pull_tight(self, cells: list[tuple[int, int]]) -> list[tuple[int, int]]:
        out = [cells[0]]
        i = 0
        while i < len(cells) - 1:
            # Lines that keep away from walls first; if none goes past the next cell (the robot
            # is beside a wall already), any line through free cells.
            for clear in (True, False):
                j = i + 1  # the next cell is always reachable: A* stepped there
                while j + 1 < len(cells) and self._line_free(cells[i], cells[j + 1], clear):
                    j += 1
                if j > i + 1:
                    break
            out.append(cells[j])
            i = j
        return out
