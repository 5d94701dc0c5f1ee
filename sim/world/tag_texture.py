"""AprilTag textures: the real 36h11 image of a tag id with its white quiet zone, cached as PNG."""

from __future__ import annotations

import tempfile
from pathlib import Path

from abstract_map.files import atomic_path


def tag_png(tag_id: int, *, px_per_cell: int, margin_cells: int, blur_cells: float,
            folder: Path | None = None) -> Path:
    """Path of the cached PNG of an AprilTag 36h11 with its white quiet zone.

    The image is slightly blurred: TinyRenderer samples textures without
    filtering, so hard edges would land on whole pixels; soft edges keep the
    sub-pixel position of the tag's corners in the rendered grey levels (as a
    real lens would), which the detector's corner refinement needs for a
    usable pose at a few tens of pixels.
    """
    import cv2

    folder = folder or Path(tempfile.gettempdir()) / "abstract_map_tags"
    folder.mkdir(parents=True, exist_ok=True)
    cell, margin = px_per_cell, margin_cells
    blur = blur_cells * cell
    path = folder / f"tag36h11_{tag_id}_{cell}px_{margin}m_{blur:.2f}b.png"
    if not path.is_file():
        dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
        if not 0 <= tag_id < dictionary.bytesList.shape[0]:
            raise ValueError(f"tag id {tag_id} is not in the AprilTag 36h11 family")
        marker = cv2.aruco.generateImageMarker(dictionary, tag_id, 8 * cell)
        image = cv2.copyMakeBorder(marker, *(4 * [margin * cell]), cv2.BORDER_CONSTANT, value=255)
        if blur > 0:
            image = cv2.GaussianBlur(image, (0, 0), blur, borderType=cv2.BORDER_REPLICATE)
        with atomic_path(path) as tmp:
            if not cv2.imwrite(str(tmp), image):
                raise OSError(f"{path}: OpenCV could not write the tag image")
    return path
