"""The pybullet world of a building: floor, walls extruded from the floor plan, AprilTags.

Frames: world frame, metres, radians counter-clockwise from +x, z up.

Walls: the occupancy grid is max-pooled to ``wall_cell_m`` cells (so thin walls
survive), its outlines are traced (marching squares) and simplified to
polylines, and each outline segment is extruded to a vertical quad of
``world.wall_height``. The quads are grouped by square tiles of
``wall_tile_m``; each tile is one static body holding a concave triangle mesh
(collision) and the same mesh as its visual. Tiles exist so that a camera can
draw only the walls it can see: pybullet's TinyRenderer has no culling of its
own and costs ~100 ns per pixel of every triangle's screen bounding box,
hidden or not (see :meth:`Scene.focus_rendering`).
The merged rectangles of the pooled grid (``wall_boxes``) give the wall tops,
a visual drawn only in the GUI.

Tags are visual-only textured squares (the real AprilTag 36h11 image with a
white quiet zone) with a white back, hung ``tag_wall_gap_m`` in front of the
wall face found along the tag's normal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pybullet as p

from sim.world.data import Tag, World
from sim.world.tag_texture import tag_png
from sim.world.walls import (
    Mesh,
    merge_rectangles,
    outline_segments,
    pool_occupancy,
    quad_mesh,
    rect_quads,
    split_segments,
    wall_quads,
)

# Collision filter groups. Static bodies only collide with robots (pybullet's
# group/mask filter would otherwise pair the floor with every wall tile); a
# ray query belongs to group 1 and hits the groups in its mask.
RAY_GROUP = 1  # bullet's group of ray queries
ROBOT_GROUP = 2  # robots: collide with walls, floor and other robots, never hit by rays
WALL_GROUP = 4  # walls: collide with robots, hit by rays
FLOOR_GROUP = 8  # the floor: collides with robots
ROBOT_MASK = ROBOT_GROUP | WALL_GROUP | FLOOR_GROUP
_MAX_MESH_QUADS = 25_000  # pybullet refuses meshes above 131072 vertices (4 per quad)
_MAX_RAY_BATCH = 16_000  # rays per rayTestBatch call
_HIDDEN = (1.0, 1.0, 1.0, 0.0)


@dataclass(frozen=True)
class SceneParams:
    """How the simulated building is built and stepped."""

    # s, physics step: three per 0.1 s control tick. A scripted 24 s drive ends within 5 cm and 0.1 rad of
    # where it ends at 1/60 s, at half the cost (physics was a third of a geometric trial's wall time).
    time_step_s: float = 1.0 / 30.0
    # Build what only cameras and the GUI see (wall tiles, tag squares, floor and wall tops). Off for perception
    # that renders nothing: pybullet's step costs per body, and ~500 visual bodies made it ~6x slower.
    visuals: bool = True
    gravity_mps2: float = -9.81  # m/s^2, along world z
    wall_cell_m: float = 0.06  # m, target cell of the pooled occupancy grid
    wall_simplify_cells: float = 0.35  # cells, polyline simplification tolerance
    wall_piece_m: float = 0.5  # m, longest wall quad, so that each lies within its tile
    wall_tile_m: float = 1.5  # m, edge of the square tiles grouping wall quads into bodies
    wall_friction: float = 0.5  # Coulomb coefficient of the walls
    floor_friction: float = 1.0  # Coulomb coefficient of the floor
    tag_wall_gap_m: float = 0.02  # m, tag face in front of the wall face
    tag_through_m: float = 0.2  # m, a wall starting this close ahead of a drawn tag carries it (see _placed_pose)
    tag_snap_m: float = 0.2  # m, longest wall thickness and distance behind a drawn tag that carry it
    tag_margin_cells: int = 2  # white quiet zone around the black square, in tag cells (8 per tag)
    tag_px_per_cell: int = 16  # texture pixels per tag cell
    tag_blur_cells: float = 0.2  # tag cells, std of the Gaussian blur of the texture (see tag_texture.tag_png)
    # white walls: a tag's white quiet zone then draws no second square around the tag
    wall_rgba: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    top_rgba: tuple[float, float, float, float] = (0.35, 0.35, 0.38, 1.0)
    floor_rgba: tuple[float, float, float, float] = (0.55, 0.52, 0.48, 1.0)
    texture_dir: Path | None = None  # where tag PNGs are cached; None: the system temp dir


@dataclass(frozen=True)
class TagPose:
    """Where a tag's face was actually placed (world frame)."""

    x: float  # m
    y: float  # m
    z: float  # m, height of the centre
    theta: float  # rad, outward normal of the face


class Scene:
    """A building in its own pybullet client. Always close() it (or use it as a context manager).

    Attributes: ``client`` (pybullet client id), ``world``, ``params``,
    ``wall_body_ids`` (visual-only wall tiles, shown or hidden per camera view), ``wall_collision_ids`` (the
    walls' static collision meshes, as few as pybullet allows),
    ``wall_boxes`` ((M, 4) merged rectangles of the pooled wall grid,
    ``x_min, x_max, y_min, y_max`` in m), ``wall_segments`` ((N, 4) wall faces
    ``x0, y0, x1, y1`` in m, wall on their left), ``tag_body_ids`` (tag id ->
    visual body), ``tag_poses`` (tag id -> where its face was placed),
    ``floor_body_id``.
    """

    def __init__(self, world: World, params: SceneParams, *, gui: bool = False) -> None:
        self.world = world
        self.params = params
        self.gui = gui
        self.client: int = p.connect(p.GUI if gui else p.DIRECT)
        if self.client < 0:
            raise RuntimeError("pybullet: cannot connect a physics client")
        self._textures: dict[int, int] = {}
        self._shown: dict[int, bool] = {}
        self._rgba: dict[int, tuple[float, float, float, float]] = {}
        self._decor_ids: list[int] = []
        self.wall_body_ids: list[int] = []
        self.wall_collision_ids: list[int] = []
        self.tag_body_ids: dict[int, int] = {}
        self.tag_poses: dict[int, TagPose] = {}
        try:
            if gui:
                p.configureDebugVisualizer(p.COV_ENABLE_GUI, 0, physicsClientId=self.client)
            p.setGravity(0, 0, params.gravity_mps2, physicsClientId=self.client)
            p.setTimeStep(params.time_step_s, physicsClientId=self.client)
            self._build_floor()
            self._build_walls()
            self._build_tags()
        except BaseException:
            self.close()
            raise

    # -- construction -------------------------------------------------------

    def _visual(self, mesh: Mesh, rgba: tuple[float, float, float, float]) -> int:
        visual = p.createVisualShape(p.GEOM_MESH, vertices=mesh.vertices.tolist(), indices=mesh.indices.tolist(),
                                     normals=mesh.normals.tolist(), rgbaColor=rgba, physicsClientId=self.client)
        if visual < 0:
            raise RuntimeError(f"pybullet: cannot create a visual mesh for world {self.world.name!r}")
        return visual

    def _add_decor(self, corners: np.ndarray, rgba: tuple[float, float, float, float]) -> None:
        """Visual-only quads (floor, wall tops) that only the GUI shows, never the cameras."""
        if not self.params.visuals:
            return
        for start in range(0, len(corners), _MAX_MESH_QUADS):
            visual = self._visual(quad_mesh(corners[start:start + _MAX_MESH_QUADS]), rgba)
            body = _visual_body(visual, physicsClientId=self.client)
            self._decor_ids.append(body)
            self._rgba[body] = rgba
            self._shown[body] = True

    def _build_floor(self) -> None:
        """A static collision box whose top is z = 0, and a floor quad for the GUI."""
        cid, fp = self.client, self.world.floorplan
        x_min, x_max, y_min, y_max = fp.extent
        half = [(x_max - x_min) / 2 + 1.0, (y_max - y_min) / 2 + 1.0, 0.05]
        centre = [(x_min + x_max) / 2, (y_min + y_max) / 2, -0.05]
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=cid)
        self.floor_body_id = p.createMultiBody(0, shape, -1, basePosition=centre, physicsClientId=cid)
        # without a visual shape pybullet draws the collision box; keep it out of the images
        p.changeVisualShape(self.floor_body_id, -1, rgbaColor=_HIDDEN, physicsClientId=cid)
        p.changeDynamics(self.floor_body_id, -1, lateralFriction=self.params.floor_friction, physicsClientId=cid)
        p.setCollisionFilterGroupMask(self.floor_body_id, -1, FLOOR_GROUP, ROBOT_GROUP, physicsClientId=cid)
        self._add_decor(rect_quads(np.array([[x_min, x_max, y_min, y_max]]), 0.0), self.params.floor_rgba)

    def _build_walls(self) -> None:
        fp, params = self.world.floorplan, self.params
        self._pool = max(1, round(params.wall_cell_m / fp.resolution))
        self._grid = pool_occupancy(fp.occupied, self._pool)
        cell = self._pool * fp.resolution
        x0, y_top = fp.origin[0], fp.origin[1] + fp.occupied.shape[0] * fp.resolution

        rects = merge_rectangles(self._grid)
        self.wall_boxes = np.stack([x0 + rects[:, 2] * cell, x0 + rects[:, 3] * cell,
                                    y_top - rects[:, 1] * cell, y_top - rects[:, 0] * cell], axis=1)
        outline = outline_segments(self._grid, params.wall_simplify_cells)
        # cell centre (r, c) lies at x0 + (c + 0.5) cell, y_top - (r + 0.5) cell
        self.wall_segments = np.stack([x0 + (outline[:, 1] + 0.5) * cell, y_top - (outline[:, 0] + 0.5) * cell,
                                       x0 + (outline[:, 3] + 0.5) * cell, y_top - (outline[:, 2] + 0.5) * cell],
                                      axis=1)
        pieces = split_segments(self.wall_segments, params.wall_piece_m)
        middle = (pieces[:, :2] + pieces[:, 2:]) / 2
        tile = np.floor((middle - np.array([x0, fp.origin[1]])) / params.wall_tile_m).astype(int)
        keys, owner = np.unique(tile, axis=0, return_inverse=True)
        quads = wall_quads(pieces, self.world.wall_height)
        order = np.argsort(owner.ravel(), kind="stable")
        bounds = np.searchsorted(owner.ravel()[order], np.arange(len(keys) + 1))
        # Collision: all walls in as few bodies as pybullet allows (its step costs per body, not per triangle).
        for start in range(0, len(quads), _MAX_MESH_QUADS):
            self._add_wall_collision(quad_mesh(quads[start:start + _MAX_MESH_QUADS]))
        # Looks: one visual-only body per tile, so the cameras can be shown only the tiles in sight.
        self._tile_origin = np.array([x0, fp.origin[1]])
        self._tile_bodies: dict[tuple[int, int], list[int]] = {}
        for k in range(len(keys) if params.visuals else 0):
            members = order[bounds[k]:bounds[k + 1]]
            for start in range(0, len(members), _MAX_MESH_QUADS):
                body = self._add_wall_tile(quad_mesh(quads[members[start:start + _MAX_MESH_QUADS]]))
                self._tile_bodies.setdefault((int(keys[k][0]), int(keys[k][1])), []).append(body)
        self._add_decor(rect_quads(self.wall_boxes, self.world.wall_height), params.top_rgba)

    def _add_wall_collision(self, mesh: Mesh) -> None:
        cid = self.client
        shape = p.createCollisionShape(p.GEOM_MESH, vertices=mesh.vertices.tolist(), indices=mesh.indices.tolist(),
                                       flags=p.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=cid)
        if shape < 0:
            raise RuntimeError(f"pybullet: cannot create a wall mesh for world {self.world.name!r}")
        body = p.createMultiBody(0, shape, -1, physicsClientId=cid)
        p.changeVisualShape(body, -1, rgbaColor=_HIDDEN, physicsClientId=cid)  # drawn by the tiles
        p.setCollisionFilterGroupMask(body, -1, WALL_GROUP, ROBOT_GROUP | RAY_GROUP, physicsClientId=cid)
        p.changeDynamics(body, -1, lateralFriction=self.params.wall_friction, physicsClientId=cid)
        self.wall_collision_ids.append(body)

    def _add_wall_tile(self, mesh: Mesh) -> int:
        body = _visual_body(self._visual(mesh, self.params.wall_rgba), physicsClientId=self.client)
        self.wall_body_ids.append(body)
        self._rgba[body] = self.params.wall_rgba
        self._shown[body] = True
        return body

    def _tiles_near(self, points: np.ndarray) -> set[int]:
        """The visual wall tiles that may hold a wall face at ``points`` (N, 2) (m).

        A wall piece belongs to the tile of its middle, at most half a piece from any point on it.
        """
        reach = self.params.wall_piece_m / 2
        tiles: set[int] = set()
        for dx in (-reach, reach):
            for dy in (-reach, reach):
                keys = np.floor((points + [dx, dy] - self._tile_origin) / self.params.wall_tile_m).astype(int)
                for key in set(map(tuple, keys.tolist())):
                    tiles.update(self._tile_bodies.get(key, ()))
        return tiles

    def _occupied_along(self, points: np.ndarray) -> np.ndarray:
        """Whether the pooled wall grid is occupied at world points (N, 2) (m); outside the map counts as free."""
        rc = self.world.floorplan.world_to_pixel(points) // self._pool
        inside = (rc[:, 0] >= 0) & (rc[:, 0] < self._grid.shape[0]) & (rc[:, 1] >= 0) & (rc[:, 1] < self._grid.shape[1])
        occupied = np.zeros(len(points), dtype=bool)
        occupied[inside] = self._grid[rc[inside, 0], rc[inside, 1]]
        return occupied

    def _placed_pose(self, tag: Tag) -> TagPose:
        """Where to hang a tag: on the face, towards its normal, of the wall it belongs to.

        Floor plans draw tags a little off their wall. Along the tag's normal on
        the pooled grid, the wall is the first one that starts within
        ``tag_through_m`` ahead of the drawn point (the point inside it, or
        behind a thin wall) and ends within ``tag_snap_m`` after that; failing
        that, a wall at most ``tag_snap_m`` behind; failing that, the tag stands
        free where it is drawn. A short ray then finds the wall mesh's face
        (simplification may move it by a centimetre or two) and the tag hangs
        ``tag_wall_gap_m`` in front of it.
        """
        prm, step = self.params, 0.005
        n = np.array([math.cos(tag.theta), math.sin(tag.theta)])
        origin = np.array([tag.x, tag.y])
        ahead = np.arange(0.0, prm.tag_through_m + prm.tag_snap_m, step)
        occupied = self._occupied_along(origin + ahead[:, None] * n)
        face = None
        starts = np.nonzero(occupied & (ahead <= prm.tag_through_m))[0]
        if len(starts):
            ends = np.nonzero(~occupied[starts[0]:])[0]
            if len(ends) and ahead[starts[0] + ends[0]] - ahead[starts[0]] <= prm.tag_snap_m:
                face = ahead[starts[0] + ends[0]]
        tolerance = prm.wall_simplify_cells * self._pool * self.world.floorplan.resolution
        z = self.world.tag_height
        if face is None:
            behind = np.arange(step, prm.tag_snap_m, step)
            hits = np.nonzero(self._occupied_along(origin - behind[:, None] * n))[0]
            if len(hits):
                face = -behind[hits[0]] + step
        if face is None:
            placed = origin
        else:
            free = origin + (face + tolerance + step) * n
            depth = 2 * tolerance + 2 * step
            hit = self.ray_fractions(np.array([[*free, z]]), np.array([[*(free - depth * n), z]]))[0]
            placed = free - hit * depth * n + prm.tag_wall_gap_m * n
        placed = self._clear_sideways(placed, n, tolerance + step)
        return TagPose(float(placed[0]), float(placed[1]), z, tag.theta)

    def _clear_sideways(self, centre: np.ndarray, normal: np.ndarray, ahead: float) -> np.ndarray:
        """Slide a tag along its face, out of a wall that cuts into one side of it (m, world frame).

        Checked on the pooled grid along a line ``ahead`` (m) in front of the
        face; a tag with walls on both sides stays where it is.
        """
        half = self.world.tag_size * (8 + 2 * self.params.tag_margin_cells) / 16.0 + self.params.tag_wall_gap_m
        tangent = np.array([-normal[1], normal[0]])
        offsets = np.linspace(-half, half, 41)
        occupied = self._occupied_along(centre + ahead * normal + offsets[:, None] * tangent)
        left, right = occupied & (offsets < 0), occupied & (offsets > 0)
        if left.any() and not right.any():
            return centre + (offsets[left].max() + half) * tangent
        if right.any() and not left.any():
            return centre + (offsets[right].min() - half) * tangent
        return centre

    def tag_visual_shape(self) -> int:
        """A new visual shape of a tag: a front square to texture (normal local +x), a white back square."""
        cells = 8 + 2 * self.params.tag_margin_cells
        h = self.world.tag_size * cells / 8 / 2
        back = -0.003
        vertices = [[0, -h, -h], [0, h, -h], [0, h, h], [0, -h, h],
                    [back, -h, -h], [back, h, -h], [back, h, h], [back, -h, h]]
        # seen from the front, local +y is the reader's right; texture u runs right, v up
        uvs = [[0, 0], [1, 0], [1, 1], [0, 1]] + 4 * [[0.02, 0.02]]
        normals = 4 * [[1, 0, 0]] + 4 * [[-1, 0, 0]]
        indices = [0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6]
        return p.createVisualShape(p.GEOM_MESH, vertices=vertices, indices=indices, uvs=uvs,
                                   normals=normals, physicsClientId=self.client)

    def _build_tags(self) -> None:
        cid = self.client
        for tag in self.world.tags.values():
            pose = self._placed_pose(tag)
            self.tag_poses[tag.id] = pose
            if not self.params.visuals:
                continue
            orientation = p.getQuaternionFromEuler([0, 0, pose.theta])
            body = _visual_body(self.tag_visual_shape(), basePosition=[pose.x, pose.y, pose.z],
                                     baseOrientation=orientation, physicsClientId=cid)
            p.changeVisualShape(body, -1, textureUniqueId=self.texture(tag.id), rgbaColor=[1, 1, 1, 1],
                                physicsClientId=cid)
            self.tag_body_ids[tag.id] = body
            self._rgba[body] = (1.0, 1.0, 1.0, 1.0)
            self._shown[body] = True

    def texture(self, tag_id: int) -> int:
        """The pybullet texture id of a tag's image in this client (loaded once)."""
        if tag_id not in self._textures:
            tex = p.loadTexture(str(tag_png(tag_id, px_per_cell=self.params.tag_px_per_cell,
                                                    margin_cells=self.params.tag_margin_cells,
                                                    blur_cells=self.params.tag_blur_cells,
                                                    folder=self.params.texture_dir)), physicsClientId=self.client)
            if tex < 0:
                raise RuntimeError(f"pybullet: cannot load the texture of tag {tag_id}")
            self._textures[tag_id] = tex
        return self._textures[tag_id]

    # -- use ----------------------------------------------------------------

    @property
    def time_step(self) -> float:
        """Physics step (s)."""
        return self.params.time_step_s

    def step(self, n: int = 1) -> None:
        """Advance the physics by ``n`` steps of ``time_step`` seconds."""
        for _ in range(n):
            p.stepSimulation(physicsClientId=self.client)

    def _ray_hits(self, origins: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(fractions (N,), body ids (N,), -1 for none) of the first wall hit of each ray."""
        origins = np.atleast_2d(np.asarray(origins, dtype=float))
        ends = np.atleast_2d(np.asarray(ends, dtype=float))
        if origins.shape != ends.shape or origins.ndim != 2 or origins.shape[1] != 3:
            raise ValueError(f"rays: origins {origins.shape} and ends {ends.shape} must both be (N, 3)")
        fractions = np.ones(len(origins))
        bodies = np.full(len(origins), -1)
        for start in range(0, len(origins), _MAX_RAY_BATCH):
            hits = p.rayTestBatch(origins[start:start + _MAX_RAY_BATCH].tolist(),
                                  ends[start:start + _MAX_RAY_BATCH].tolist(),
                                  collisionFilterMask=WALL_GROUP, physicsClientId=self.client)
            ids = np.fromiter((hit[0] for hit in hits), dtype=int, count=len(hits))
            along = np.fromiter((hit[2] for hit in hits), dtype=float, count=len(hits))
            hit = ids >= 0
            bodies[start:start + len(hits)][hit] = ids[hit]
            fractions[start:start + len(hits)][hit] = along[hit]
        return fractions, bodies

    def ray_fractions(self, origins: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Fraction (N,) along each ray (world frame, m, (N, 3) each) of its first wall hit; 1.0 if none.

        Only walls are hit (rays are masked to :data:`WALL_GROUP`), never robots or tags.
        """
        return self._ray_hits(origins, ends)[0]

    def focus_rendering(self, x: float, y: float, z: float, radius_m: float, *, n_rays: int = 360) -> None:
        """Show the cameras only what can be seen from (x, y, z) (m) within ``radius_m``.

        Walls are extruded floor plans, so what is visible at height ``z`` is
        visible at any height: ``n_rays`` horizontal rays find the wall tiles in
        sight; tags within the radius stay shown (walls in front hide them in
        the image); floor and wall tops are hidden. Ignored in GUI mode.
        """
        if self.gui:
            return
        angles = np.linspace(0.0, 2 * math.pi, n_rays, endpoint=False)
        origins = np.tile([x, y, z], (n_rays, 1))
        ends = origins + radius_m * np.stack([np.cos(angles), np.sin(angles), np.zeros(n_rays)], axis=1)
        fractions = self._ray_hits(origins, ends)[0]
        hit = fractions < 1.0
        points = origins[hit, :2] + fractions[hit, None] * (ends[hit, :2] - origins[hit, :2])
        seen = self._tiles_near(points)
        show = {body: body in seen for body in self.wall_body_ids}
        show.update({body: False for body in self._decor_ids})
        for tag_id, body in self.tag_body_ids.items():
            pose = self.tag_poses[tag_id]
            show[body] = math.hypot(pose.x - x, pose.y - y) <= radius_m
        self._set_shown(show)

    def unfocus_rendering(self) -> None:
        """Show everything again (undo :meth:`focus_rendering`)."""
        self._set_shown({body: True for body in self._shown})

    def _set_shown(self, show: dict[int, bool]) -> None:
        for body, visible in show.items():
            if self._shown[body] != visible:
                rgba = self._rgba[body] if visible else (*self._rgba[body][:3], 0.0)
                p.changeVisualShape(body, -1, rgbaColor=rgba, physicsClientId=self.client)
                self._shown[body] = visible

    def close(self) -> None:
        """Disconnect the pybullet client (idempotent)."""
        if self.client >= 0:
            p.disconnect(physicsClientId=self.client)
            self.client = -1

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _visual_body(visual: int, **kwargs: Any) -> int:
    """A static body that is only drawn: a rigid body (maximal coordinates), which pybullet's step skips, unlike
    the multibody it makes by default (~500 of those doubled a camera trial's physics step)."""
    return p.createMultiBody(0, -1, visual, useMaximalCoordinates=True, **kwargs)


def build_scene(world: World, *, gui: bool = False, params: SceneParams | None = None) -> Scene:
    """Build ``world`` in a new pybullet client (DIRECT unless ``gui``)."""
    return Scene(world, params or SceneParams(), gui=gui)
