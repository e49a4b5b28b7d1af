"""A floorplan's image as the browser is sent it: PGM and negated maps as PNG, and its thumbnail.

Pillow is imported here only when an image is drawn or checked: a robot with no floorplans never
loads it (issue 32).
"""

from __future__ import annotations

import io
from pathlib import Path

MAP_IMAGE_FORMATS = ("PNG", "PPM")  # Pillow reads PGM as its PPM format; nothing else is opened
MAX_IMAGE_SIDE_PX = 8192
THUMBNAIL_SIDE_PX = 320


def make_thumbnail(png: bytes, side_px: int = THUMBNAIL_SIDE_PX) -> bytes:
    from PIL import Image  # here and below: a robot with no floorplans never loads Pillow (issue 32)

    with Image.open(io.BytesIO(png), formats=("PNG",)) as image:
        image = image.convert("RGBA" if "A" in image.getbands() else "RGB")
        image.thumbnail((side_px, side_px), Image.Resampling.BOX)  # BOX keeps thin walls visible as grey
        out = io.BytesIO()
        image.save(out, "PNG", optimize=True)
        return out.getvalue()


def display_png(path: Path, params: dict) -> bytes:
    """Browsers cannot show PGM, and a negated map would show free space dark: fix both for display."""
    negate = bool(params.get("negate", 0))
    if path.suffix.lower() == ".png" and not negate:
        return path.read_bytes()
    from PIL import Image, ImageOps

    with Image.open(path, formats=MAP_IMAGE_FORMATS) as image:
        image.load()
        if negate:
            if image.mode in ("LA", "RGBA"):
                *colour, alpha = image.split()
                colour = [ImageOps.invert(band) for band in colour]
                image = Image.merge(image.mode, (*colour, alpha))
            else:
                image = ImageOps.invert(image.convert("RGB" if image.mode not in ("L", "RGB") else image.mode))
        out = io.BytesIO()
        image.save(out, "PNG")
        return out.getvalue()
