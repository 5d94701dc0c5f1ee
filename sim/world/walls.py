"""Walls from a floor plan: pure geometry, no simulator.

The occupancy grid is max-pooled (so thin walls survive), covered with
rectangles (the wall tops), and its outlines traced and simplified into
segments, which become vertical quads and then triangle meshes. Cell
coordinates are (row, col); world coordinates are metres in the world frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def pool_occupancy(occupied: np.ndarray, factor: int) -> np.ndarray:
    """Max-pool a boolean grid by ``factor`` (cells), padding bottom/right with free cells."""
    if factor < 1:
        raise ValueError(f"pool factor must be >= 1, got {factor}")
    rows, cols = occupied.shape
    out_r, out_c = -(-rows // factor), -(-cols // factor)
    padded = np.zeros((out_r * factor, out_c * factor), dtype=bool)
    padded[:rows, :cols] = occupied
    return padded.reshape(out_r, factor, out_c, factor).any(axis=(1, 3))


def merge_rectangles(grid: np.ndarray) -> np.ndarray:
    """Cover the True cells of ``grid`` with disjoint axis-aligned rectangles.

    Runs along each row are found vectorised; runs with the same column span in
    consecutive rows are merged greedily. Returns (M, 4) int rows
    ``(row0, row1, col0, col1)``, half-open.
    """
    rows, cols = grid.shape
    padded = np.zeros((rows, cols + 2), dtype=np.int8)
    padded[:, 1:-1] = grid
    step = np.diff(padded, axis=1)
    run_rows, run_c0 = np.nonzero(step == 1)
    _, run_c1 = np.nonzero(step == -1)
    bounds = np.searchsorted(run_rows, np.arange(rows + 1))
    rects: list[tuple[int, int, int, int]] = []
    open_rects: dict[tuple[int, int], int] = {}
    for r in range(rows + 1):
        lo, hi = (bounds[r], bounds[r + 1]) if r < rows else (0, 0)
        spans = set(zip(run_c0[lo:hi].tolist(), run_c1[lo:hi].tolist()))
        for span in [s for s in open_rects if s not in spans]:
            rects.append((open_rects.pop(span), r, span[0], span[1]))
        for span in spans:
            open_rects.setdefault(span, r)
    return np.array(rects, dtype=int).reshape(-1, 4)


def outline_segments(grid: np.ndarray, tolerance: float) -> np.ndarray:
    """Outline of the True cells as segments (N, 4) ``(r0, c0, r1, c1)`` in cell units.

    Points are continuous (row, col) positions of cell centres (cell edges lie
    on half-integers). In the frame x = col, y = -row (the world's axes), the
    occupied cells lie on the left of each segment. ``tolerance`` (cells) is
    the polyline simplification.
    """
    import cv2
    from skimage import measure

    contours = measure.find_contours(np.pad(grid, 1).astype(np.float32), 0.5, positive_orientation="high")
    segments = []
    for contour in contours:
        simple = cv2.approxPolyDP(contour.astype(np.float32).reshape(-1, 1, 2), tolerance, True).reshape(-1, 2)
        if len(simple) < 2:
            continue
        closed = np.vstack([simple, simple[:1]]) - 1.0
        segments.append(np.hstack([closed[:-1], closed[1:]]))
    return np.vstack(segments) if segments else np.zeros((0, 4))


def split_segments(segments: np.ndarray, longest: float) -> np.ndarray:
    """Cut segments (N, 4) ``(x0, y0, x1, y1)`` into equal pieces no longer than ``longest``."""
    a, b = segments[:, :2], segments[:, 2:]
    pieces = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / longest)).astype(int)
    owner = np.repeat(np.arange(len(segments)), pieces)
    index = np.arange(len(owner)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    t0 = (index / pieces[owner])[:, None]
    t1 = ((index + 1) / pieces[owner])[:, None]
    d = b[owner] - a[owner]
    return np.hstack([a[owner] + t0 * d, a[owner] + t1 * d])


@dataclass(frozen=True)
class Mesh:
    """Quads as triangles with per-vertex normals, in world coordinates (m)."""

    vertices: np.ndarray  # (4Q, 3)
    normals: np.ndarray  # (4Q, 3)
    indices: np.ndarray  # (6Q,)


def quad_mesh(corners: np.ndarray) -> Mesh:
    """Quads (Q, 4, 3), counter-clockwise as seen from the side they face."""
    q = len(corners)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    faces = np.array([0, 1, 2, 0, 2, 3])
    return Mesh(corners.reshape(-1, 3), np.repeat(normal, 4, axis=0),
                 (faces[None, :] + 4 * np.arange(q)[:, None]).reshape(-1))


def wall_quads(segments: np.ndarray, height: float) -> np.ndarray:
    """Vertical quads (N, 4, 3) over segments ``(x0, y0, x1, y1)`` whose wall lies on their left."""
    n = len(segments)
    lo, hi = np.zeros((n, 1)), np.full((n, 1), height)
    a, b = segments[:, :2], segments[:, 2:]
    # seen from the right (the free side), a -> b runs left to right: counter-clockwise is a, b, b', a'
    return np.stack([np.hstack([a, lo]), np.hstack([b, lo]), np.hstack([b, hi]), np.hstack([a, hi])], axis=1)


def rect_quads(boxes: np.ndarray, z: float) -> np.ndarray:
    """Horizontal quads (M, 4, 3) facing up over boxes ``(x_min, x_max, y_min, y_max)``."""
    x0, x1, y0, y1 = boxes.T
    zz = np.full_like(x0, z)
    return np.stack([np.stack([x0, y0, zz], 1), np.stack([x1, y0, zz], 1),
                     np.stack([x1, y1, zz], 1), np.stack([x0, y1, zz], 1)], axis=1)
