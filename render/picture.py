"""Pictures with Pillow (the one render module that imports it): caption bands, contact sheets, PNG and GIF.

GIFs share one 255-colour palette over the whole animation (octree over a sample of the frames, no
dithering): the pictures hold few colours (flat role and robot colours, shaded), a shared palette keeps them
steady from frame to frame, and Pillow then stores only what changed between frames.  That is about ten
times faster than a palette per frame and gives smaller files.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, Sequence

import numpy as np

BAND = (32, 32, 36)  # caption band colour
TEXT = (245, 245, 245)
SHEET_BACKGROUND = 255
#: how long the last frame of an animation stays (s) before it loops
HOLD_LAST = 1.5
PALETTE_SAMPLES = 12  # frames the GIF palette is made from


@lru_cache(maxsize=8)
def _font(size: int) -> Any:
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def caption(image: np.ndarray, text: str) -> np.ndarray:
    """``image`` (H, W, 3 uint8) with ``text`` in a dark band over its bottom edge, shortened with "..." to
    fit the width."""
    from PIL import Image, ImageDraw

    h, w = image.shape[:2]
    size = max(9, round(h / 26))
    font = _font(size)
    pad = max(2, size // 3)
    band = size + 2 * pad
    pic = Image.fromarray(np.ascontiguousarray(image))
    draw = ImageDraw.Draw(pic)
    draw.rectangle((0, h - band, w, h), fill=BAND)
    room = w - 2 * pad
    if font.getlength(text) > room:
        while text and font.getlength(text + "...") > room:
            text = text[:-1]
        text += "..."
    draw.text((pad, h - band + pad), text, fill=TEXT, font=font)
    return np.asarray(pic)


def sheet(images: Sequence[np.ndarray], columns: int | None = None, gap: int = 4) -> np.ndarray:
    """The images (all of one size) tiled row by row, ``columns`` wide (default: about square), on white."""
    if not images:
        raise ValueError("a contact sheet needs at least one image")
    h, w = images[0].shape[:2]
    cols = columns or max(1, math.ceil(math.sqrt(len(images) * h / w)))
    cols = min(cols, len(images))
    rows = math.ceil(len(images) / cols)
    out = np.full((rows * h + (rows - 1) * gap, cols * w + (cols - 1) * gap, 3), SHEET_BACKGROUND, dtype=np.uint8)
    for i, img in enumerate(images):
        r, c = divmod(i, cols)
        out[r * (h + gap) : r * (h + gap) + h, c * (w + gap) : c * (w + gap) + w] = img
    return out


def write_png(path: str, image: np.ndarray) -> None:
    """``image`` (H, W, 3 uint8) as a PNG."""
    from PIL import Image

    Image.fromarray(np.ascontiguousarray(image)).save(path, format="PNG", optimize=True)


def write_gif(path: str, images: Sequence[np.ndarray], fps: float) -> None:
    """A looping GIF of ``images`` at ``fps``, the last one held :data:`HOLD_LAST` seconds."""
    from PIL import Image

    stride = max(1, len(images) // PALETTE_SAMPLES)
    sample = np.concatenate([images[i] for i in range(0, len(images), stride)], axis=0)
    palette = Image.fromarray(sample).quantize(colors=255, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
    frames = [
        Image.fromarray(np.ascontiguousarray(img)).quantize(palette=palette, dither=Image.Dither.NONE) for img in images
    ]
    ms = round(1000.0 / fps)
    durations = [ms] * (len(frames) - 1) + [max(ms, round(HOLD_LAST * 1000))]
    frames[0].save(path, format="GIF", save_all=True, append_images=frames[1:], duration=durations, loop=0, disposal=1)
