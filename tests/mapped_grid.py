"""A robot's map with a whole building mapped, for tests that ask what the navigator makes of what it has seen."""

from __future__ import annotations

import numpy as np

from sim.mapping.occupancy import OccupancyGrid, OccupancyParams


def mapped(world) -> OccupancyGrid:  # type: ignore[no-untyped-def]
    """A grid over ``world`` with every cell mapped as its floor plan has it."""
    x0, x1, y0, y1 = world.floorplan.extent
    grid = OccupancyGrid(OccupancyParams(resolution_m=0.1, bounds=(x0, x1, y0, y1)))
    xy = grid.cell_to_world(np.argwhere(np.ones(grid.shape, dtype=bool)))
    plan = world.floorplan
    col = ((xy[:, 0] - plan.origin[0]) / plan.resolution).astype(int)
    row = plan.shape[0] - 1 - ((xy[:, 1] - plan.origin[1]) / plan.resolution).astype(int)
    inside = (row >= 0) & (row < plan.shape[0]) & (col >= 0) & (col < plan.shape[1])
    occupied = np.zeros(len(xy), dtype=bool)
    occupied[inside] = plan.occupied[row[inside], col[inside]]
    cells = grid.world_to_cell(xy)
    grid.log_odds[cells[:, 0], cells[:, 1]] = np.where(occupied, 3.0, -2.0)
    return grid
