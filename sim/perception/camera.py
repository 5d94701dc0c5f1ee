"""Camera perception: render a panoramic camera with pybullet and detect AprilTags in the images.

The panorama is ``n_views`` level pinhole views around the robot's camera
(view 0 looks along the camera's yaw), each rendered with pybullet's
TinyRenderer. Each image is searched with OpenCV's ArUco detector for
AprilTag 36h11 tags. A detection's corners are refined on the black square's
edges (:func:`refine_corners`), ``cv2.solvePnP`` (IPPE_SQUARE) with the known
tag size gives candidate poses, and a 4-degree-of-freedom fit of an upright
tag (tags hang vertically; the camera is level) picks and polishes one.
Detections are then filtered by the rules of the original study (range,
reading cone, ids of this world), one sighting per tag id.

Frames: world frame, metres, radians counter-clockwise from +x. OpenCV's
camera frame is x right, y down, z forward; a view with yaw psi maps it to
the world as x -> (sin psi, -cos psi, 0), y -> (0, 0, -1), z -> (cos psi, sin psi, 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType

import cv2
import numpy as np
import pybullet as p

from sim.perception.sighting import Sighting
from sim.world.robot import Robot
from sim.world.scene import Scene, TagPose
from sim.world.visibility import readable

_REFINEMENT = MappingProxyType({
    "none": cv2.aruco.CORNER_REFINE_NONE,
    "subpix": cv2.aruco.CORNER_REFINE_SUBPIX,
    "contour": cv2.aruco.CORNER_REFINE_CONTOUR,
    "apriltag": cv2.aruco.CORNER_REFINE_APRILTAG,
})


@dataclass(frozen=True)
class CameraParams:
    """The panoramic camera, the detector and the reading rules.

    With the defaults each view spans 76 deg horizontally (16 deg overlap, so
    a tag 1.2 m away, with a cell of its quiet zone, is whole in at least one
    view), the focal length is ~262 px (a 0.25 m tag 4 m away spans ~16 px),
    and the rows look from ``up_deg`` above to ~22 deg below the horizon: a
    tag 0.2 m below the camera is whole in the image from ~1 m away. Closer
    tags are not read (geometric perception has no such limit).
    """

    n_views: int = 6  # pinhole views around the panorama
    overlap_deg: float = 16.0  # deg, horizontal overlap between neighbouring views
    width_px: int = 410  # px, per view
    height_px: int = 110  # px, per view (square pixels)
    up_deg: float = 1.0  # deg, how far above the horizon the top image row looks
    near_m: float = 0.05  # m, near clipping plane
    max_range_m: float = 4.0  # m, detections farther (floor-plane distance) are rejected
    cone_half_angle_deg: float = 45.0  # deg, detections seen more obliquely are rejected
    render_margin_m: float = 0.5  # m, walls and tags are drawn up to max_range_m + this
    visibility_rays: int = 360  # horizontal rays choosing which wall tiles to draw
    corner_refinement: str = "subpix"  # one of "none", "subpix", "contour", "apriltag"
    skip_empty_views: bool = True  # render only views that can contain a tag (same result, faster)
    # deg beyond the reading cone within which a tag is still drawn. Of 1,120 detections (zoo Lion, a generated
    # office) those the cone passed were at most 45.3 deg off in truth, and no facing erred by more than 11.3 deg.
    render_cone_margin_deg: float = 15.0

    @property
    def hfov(self) -> float:
        """Horizontal field of view of one view (rad)."""
        return math.tau / self.n_views + math.radians(self.overlap_deg)

    @property
    def focal_px(self) -> float:
        """Focal length (px), the same along both image axes."""
        return self.width_px / (2.0 * math.tan(self.hfov / 2.0))


def _sample(grey: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Bilinear samples of a float image at pixel positions (..., 2) ``(u, v)``."""
    u = np.clip(points[..., 0], 0, grey.shape[1] - 1.001)
    v = np.clip(points[..., 1], 0, grey.shape[0] - 1.001)
    u0, v0 = np.floor(u).astype(int), np.floor(v).astype(int)
    fu, fv = u - u0, v - v0
    return ((1 - fu) * (1 - fv) * grey[v0, u0] + fu * (1 - fv) * grey[v0, u0 + 1]
            + (1 - fu) * fv * grey[v0 + 1, u0] + fu * fv * grey[v0 + 1, u0 + 1])


def refine_corners(grey: np.ndarray, quad: np.ndarray, samples: int = 12) -> np.ndarray:
    """Sub-pixel corners (4, 2) of a tag's black square from its edges.

    For each edge, points along it are moved across it to where the grey level
    crosses half-way between the black border (half a cell inside) and the
    white quiet zone (half a cell outside); a line fitted to them per edge and
    the intersections of neighbouring lines give the corners. Falls back to the
    given corners where an edge cannot be measured.
    """
    centre = quad.mean(axis=0)
    cell = np.mean(np.linalg.norm(np.roll(quad, -1, axis=0) - quad, axis=1)) / 8.0
    offsets = np.linspace(-0.5 * cell, 0.5 * cell, 17)
    starts, ends = quad, np.roll(quad, -1, axis=0)  # edge i runs from corner i to corner i + 1
    normals = np.empty((4, 2))
    for i, (a, b) in enumerate(zip(starts, ends)):
        direction = (b - a) / max(np.linalg.norm(b - a), 1e-9)
        normal = np.array([direction[1], -direction[0]])
        normals[i] = -normal if np.dot(normal, (a + b) / 2 - centre) < 0 else normal  # pointing out of the square
    ts = np.linspace(0.15, 0.85, samples)
    base = starts[:, None, :] + ts[None, :, None] * (ends - starts)[:, None, :]  # (edge, sample, 2)
    profile = _sample(grey, base[:, :, None, :] + offsets[None, None, :, None] * normals[:, None, None, :])
    level = 0.5 * (profile[..., 0] + profile[..., -1])
    above = profile >= level[..., None]
    crossing = ~above[..., :-1] & above[..., 1:]  # dark to light between offsets j and j + 1
    # per sample, the crossing nearest the expected edge; samples without contrast or crossing are dropped
    j = np.where(crossing, np.abs(offsets[:-1]), np.inf).argmin(axis=2)
    usable = (profile[..., -1] - profile[..., 0] >= 20.0) & crossing.any(axis=2)
    p0 = np.take_along_axis(profile, j[..., None], axis=2)[..., 0]
    p1 = np.take_along_axis(profile, j[..., None] + 1, axis=2)[..., 0]
    across = offsets[j] + (level - p0) / np.maximum(p1 - p0, 1e-6) * (offsets[j + 1] - offsets[j])
    points = base + across[..., None] * normals[:, None, :]
    lines = []
    for i in range(4):
        if usable[i].sum() < 3:
            return quad
        pts = points[i][usable[i]]
        mean = pts.mean(axis=0)
        _, _, vt = np.linalg.svd(pts - mean)
        lines.append((mean, vt[0]))
    refined = np.empty_like(quad)
    for i in range(4):
        (p, d), (q, e) = lines[i - 1], lines[i]
        matrix = np.array([d, -e]).T
        if abs(np.linalg.det(matrix)) < 1e-6:
            return quad
        s, _ = np.linalg.solve(matrix, q - p)
        refined[i] = p + s * d
    if np.abs(refined - quad).max() > cell:
        return quad
    return refined


@dataclass(frozen=True)
class Detection:
    """One tag found in one view, before the reading rules."""

    tag_id: int
    x: float  # m, world frame
    y: float  # m, world frame
    z: float  # m, world frame
    theta: float  # rad, world yaw of the tag's outward normal
    off_centre: float  # |u - cx| / width, 0 at the view's centre column
    corners_px: np.ndarray | None = field(default=None, compare=False)  # (4, 2) refined corners (u, v), px


@dataclass(frozen=True)
class Sweep:
    """One panoramic sweep as the camera saw it (the latest is kept, by reference, for recordings)."""

    images: dict[int, np.ndarray]  # view index -> grey image (height_px, width_px) uint8, rendered views only
    detections: dict[int, list[Detection]]  # view index -> every tag found in it, before the reading rules
    read: frozenset[int]  # ids that passed the reading rules (the sweep's sightings)


class CameraPerception:
    """Reads tags from rendered images of a panoramic camera on the robot."""

    renders = True  # needs the scene's looks (SceneParams.visuals)

    def __init__(self, scene: Scene, params: CameraParams | None = None, *,
                 rng: np.random.Generator | None = None) -> None:
        prm = params or CameraParams()
        if not scene.params.visuals:
            raise ValueError("camera perception needs a scene built with SceneParams(visuals=True)")
        if prm.corner_refinement not in _REFINEMENT:
            raise ValueError(f"CameraParams.corner_refinement {prm.corner_refinement!r} is not one of "
                             f"{sorted(_REFINEMENT)}")
        if prm.n_views < 1 or prm.width_px < 8 or prm.height_px < 8:
            raise ValueError(f"CameraParams: need n_views >= 1 and images >= 8 px, got {prm}")
        self.scene = scene
        self.params = prm
        self.last_sweep: Sweep | None = None  # the latest sweep's images and detections
        self._rng = rng  # unused: rendering is deterministic; kept for a uniform constructor
        detector_params = cv2.aruco.DetectorParameters()
        detector_params.cornerRefinementMethod = _REFINEMENT[prm.corner_refinement]
        self._detector = cv2.aruco.ArucoDetector(
            cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11), detector_params)
        f = prm.focal_px
        top = math.tan(math.radians(prm.up_deg))
        bottom = prm.height_px / f - top
        n = prm.near_m
        half_w = prm.width_px / (2.0 * f)
        self._projection = p.computeProjectionMatrix(-half_w * n, half_w * n, -bottom * n, top * n, n,
                                                     prm.max_range_m + prm.render_margin_m + 2.0,
                                                     physicsClientId=scene.client)
        # TinyRenderer samples pixel (u, v) at its integer position and flips rows:
        # u = cx + f X/Z, v = cy + f Y/Z (OpenCV axes)
        self.intrinsics = np.array([[f, 0.0, prm.width_px / 2.0],
                                    [0.0, f, prm.height_px - 1.0 - bottom * f],
                                    [0.0, 0.0, 1.0]])
        s = scene.world.tag_size / 2.0
        self._object_points = np.array([[-s, s, 0.0], [s, s, 0.0], [s, -s, 0.0], [-s, -s, 0.0]])

    def views_to_render(self, x: float, y: float, yaw: float) -> list[int]:
        """Indices of the views that can show a tag's face from (x, y) m with view 0 along ``yaw`` rad.

        Tags beyond ``max_range_m + render_margin_m`` are not drawn at all, a
        tag seen from behind shows its blank back, a tag seen more obliquely
        than the reading cone plus ``render_cone_margin_deg`` is never read
        (its detection's facing would have to err by that much), and a tag whose black square
        has both side edges behind walls cannot be decoded (walls are extruded,
        so what hides an edge at the camera's height hides it at every height).
        A view without any other tag in its field of view yields no detection:
        skipping it changes nothing but the time a sweep takes.
        """
        prm = self.params
        radius = prm.max_range_m + prm.render_margin_m
        half_size = self.scene.world.tag_size * (8 + 2 * self.scene.params.tag_margin_cells) / 16.0
        poses = list(self.scene.tag_poses.values())
        faces = np.array([(pose.x, pose.y, pose.theta) for pose in poses]).reshape(-1, 3)
        # in range and in front, within the widened cone: the reading rules with the margins above
        drawn = readable(x, y, faces[:, 0], faces[:, 1], faces[:, 2], max_range_m=radius,
                         cone_half_angle_deg=min(90.0, prm.cone_half_angle_deg + prm.render_cone_margin_deg))
        near = [poses[i] for i in np.flatnonzero(drawn)]
        views: set[int] = set()
        for pose, hidden in zip(near, self._edges_hidden(x, y, near), strict=True):
            if hidden:
                continue
            dx, dy = pose.x - x, pose.y - y
            distance = math.hypot(dx, dy)
            bearing = math.atan2(dy, dx)
            reach = prm.hfov / 2.0 + math.atan2(half_size, distance)
            for k in range(prm.n_views):
                if abs(math.remainder(bearing - yaw - k * math.tau / prm.n_views, math.tau)) <= reach:
                    views.add(k)
        return sorted(views)

    def _edges_hidden(self, x: float, y: float, poses: list[TagPose]) -> list[bool]:
        """Whether walls hide both side edges of each tag's black square from (x, y) m (rays at one height).

        The rays end 1 cm in front of the face and 1 cm inside the square's edges, so that neither the tag's own
        wall nor a wall meeting it at a corner counts as hiding an edge that can be seen.
        """
        if not poses:
            return []
        inset = self.scene.world.tag_size / 2.0 - 0.01
        origins, ends = [], []
        for pose in poses:  # rays at the tag's centre height, below the walls' tops
            c, s = math.cos(pose.theta), math.sin(pose.theta)
            front_x, front_y = pose.x + 0.01 * c, pose.y + 0.01 * s
            origins += [(x, y, pose.z)] * 2
            ends += [(front_x - inset * s, front_y + inset * c, pose.z), (front_x + inset * s, front_y - inset * c,
                                                                         pose.z)]
        fractions = self.scene.ray_fractions(np.array(origins), np.array(ends))
        return (fractions.reshape(-1, 2) < 1.0).all(axis=1).tolist()

    def render(self, x: float, y: float, z: float, yaw: float,
               views: list[int] | None = None) -> dict[int, np.ndarray]:
        """Grey images (height_px, width_px) uint8 of the given views (default all) from (x, y, z) m.

        View k looks along ``yaw + k * 2 pi / n_views`` (rad).
        """
        prm, cid = self.params, self.scene.client
        views = list(range(prm.n_views)) if views is None else views
        if not views:
            return {}
        self.scene.focus_rendering(x, y, z, prm.max_range_m + prm.render_margin_m, n_rays=prm.visibility_rays)
        images = {}
        for k in views:
            psi = yaw + k * math.tau / prm.n_views
            target = [x + math.cos(psi), y + math.sin(psi), z]
            view = p.computeViewMatrix([x, y, z], target, [0, 0, 1], physicsClientId=cid)
            _, _, rgba, _, _ = p.getCameraImage(prm.width_px, prm.height_px, view, self._projection,
                                                renderer=p.ER_TINY_RENDERER, shadow=0,
                                                flags=p.ER_NO_SEGMENTATION_MASK, physicsClientId=cid)
            rgba = np.asarray(rgba, dtype=np.uint8).reshape(prm.height_px, prm.width_px, 4)
            images[k] = cv2.cvtColor(rgba, cv2.COLOR_RGBA2GRAY)
        return images

    def detect(self, image: np.ndarray, x: float, y: float, z: float, psi: float) -> list[Detection]:
        """Tags in one view's grey image, posed in the world; the view's eye is (x, y, z) m, yaw ``psi`` rad."""
        corners, ids, _ = self._detector.detectMarkers(image)
        if ids is None:
            return []
        to_world = np.array([[math.sin(psi), 0.0, math.cos(psi)],
                             [-math.cos(psi), 0.0, math.sin(psi)],
                             [0.0, -1.0, 0.0]])
        found = []
        grey = image.astype(np.float32)
        # one quad per id: the detector may report a marker twice (nearly equal candidates);
        # keep the smallest, which is the black square itself
        smallest: dict[int, np.ndarray] = {}
        for quad, tag_id in zip(corners, ids.ravel().tolist()):
            if tag_id not in smallest or cv2.arcLength(quad, True) < cv2.arcLength(smallest[tag_id], True):
                smallest[tag_id] = quad
        for tag_id, quad in smallest.items():
            pixels = refine_corners(grey, quad.reshape(4, 2).astype(np.float64))
            pose = self._solve(pixels)
            if pose is None:
                continue
            t, normal_cam = pose
            centre = np.array([x, y, z]) + to_world @ t
            normal = to_world @ normal_cam
            u = float(pixels[:, 0].mean())
            found.append(Detection(int(tag_id), float(centre[0]), float(centre[1]), float(centre[2]),
                                   math.atan2(normal[1], normal[0]),
                                   abs(u - self.intrinsics[0, 2]) / self.params.width_px, pixels))
        return found

    def _project(self, poses: np.ndarray) -> np.ndarray:
        """Pixels (m, 8), corners' (u, v) in turn, of upright tags at poses (m, 4): centre t (camera frame, m) and
        turn angle (rad) about the camera's vertical axis away from facing the camera.

        The tag's x maps to the camera's x, its y (up) to -y, its z (out of the face) to -z, then the tag turns
        about y; the corners lie in the tag's plane (z = 0), so each camera coordinate is one product.
        """
        angle = poses[:, 3:4]
        ox, oy = self._object_points[:, 0], self._object_points[:, 1]
        z = ox * -np.sin(angle) + poses[:, 2:3]
        pixels = np.empty((len(poses), 4, 2))
        k = self.intrinsics
        pixels[:, :, 0] = k[0, 0] * (ox * np.cos(angle) + poses[:, 0:1]) / z + k[0, 2]
        pixels[:, :, 1] = k[1, 1] * (-oy + poses[:, 1:2]) / z + k[1, 2]
        return pixels.reshape(len(poses), 8)

    def _solve(self, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Pose of a tag from its corners: (centre, outward normal), camera frame; None if it fails.

        IPPE gives up to two candidate poses; each (and the tag facing the
        camera) seeds :meth:`_upright`, and the fit with the smallest
        reprojection error wins.
        """
        count, rvecs, tvecs, _ = cv2.solvePnPGeneric(self._object_points, pixels, self.intrinsics, None,
                                                     flags=cv2.SOLVEPNP_IPPE_SQUARE)
        if count == 0:
            return None
        seeds = [(tvecs[0].ravel(), 0.0)]
        for rvec, tvec in zip(rvecs, tvecs):
            normal = cv2.Rodrigues(rvec)[0][:, 2]
            seeds.append((tvec.ravel(), math.atan2(-normal[0], -normal[2])))
        fits = [fit for fit in (self._upright(pixels, t, angle) for t, angle in seeds) if math.isfinite(fit[2])]
        if not fits:
            return None
        t, angle, _ = min(fits, key=lambda fit: fit[2])
        if t[2] <= 0:
            return None
        return t, np.array([-math.sin(angle), 0.0, -math.cos(angle)])

    def _upright(self, pixels: np.ndarray, t: np.ndarray, angle: float,
                 iterations: int = 8) -> tuple[np.ndarray, float, float]:
        """Fit a vertical tag to its corners: (centre t, turn angle, squared reprojection error).

        The camera is level, so a vertical tag has 4 degrees of freedom: its
        centre t (camera frame, m) and its turn about the camera's vertical
        axis (rad, see :meth:`_project`). Gauss-Newton from (t, angle).
        """
        params = np.array([*t, angle], dtype=float)
        target = pixels.ravel()
        steps = np.diag([1e-6, 1e-6, 1e-6, 1e-7])  # finite-difference step per parameter (m, m, m, rad)
        for _ in range(iterations):
            projected = self._project(np.vstack([params, params + steps]))  # the fit and its 4 nudges
            residual = projected[0] - target
            if params[2] <= 0 or not np.all(np.isfinite(residual)):
                return params[:3], float(params[3]), math.inf
            jacobian = ((projected[1:] - target - residual) / np.diag(steps)[:, None]).T
            delta = np.linalg.lstsq(jacobian, -residual, rcond=None)[0]
            params += delta
            if np.abs(delta).max() < 1e-8:
                break
        if params[2] <= 0:
            return params[:3], float(params[3]), math.inf
        error = float(np.sum((self._project(params[None, :])[0] - target) ** 2))
        return params[:3], float(params[3]), error if math.isfinite(error) else math.inf

    def observe(self, robot: Robot) -> list[Sighting]:
        """The tags read in one panoramic sweep from the robot's camera, one per tag id, nearest first."""
        prm = self.params
        x, y, z, yaw = robot.camera_pose()
        best: dict[int, Detection] = {}
        views = self.views_to_render(x, y, yaw) if prm.skip_empty_views else None
        images = self.render(x, y, z, yaw, views)
        found: dict[int, list[Detection]] = {}
        for k, image in images.items():
            found[k] = self.detect(image, x, y, z, yaw + k * math.tau / prm.n_views)
            for det in found[k]:
                if det.tag_id not in self.scene.world.tags:
                    continue
                if not readable(x, y, det.x, det.y, det.theta, max_range_m=prm.max_range_m,
                                cone_half_angle_deg=prm.cone_half_angle_deg):
                    continue
                if det.tag_id not in best or det.off_centre < best[det.tag_id].off_centre:
                    best[det.tag_id] = det
        sightings = [Sighting(d.tag_id, d.x, d.y, d.theta, math.hypot(d.x - x, d.y - y)) for d in best.values()]
        self.last_sweep = Sweep(images, found, frozenset(best))
        return sorted(sightings, key=lambda s: s.range_m)
