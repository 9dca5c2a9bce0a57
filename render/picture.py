"""Pictures with Pillow (the one render module that imports it): names, legends, caption bands, contact
sheets, PNG and GIF.

A replay frame is laid out as a :class:`Layout`: a legend band on top (each robot's colour and name, the
object roles, region kinds and fixed objects present; left out when it would take more than a quarter of the
picture), the rendered scene with its names drawn on it (:func:`draw_labels`), and a caption band at the
bottom holding the step and what moves, wrapped over up to :data:`CAPTION_LINES` lines.  A contact sheet
has one legend over all its tiles.

GIFs share one 255-colour palette over the whole animation (octree over a sample of the frames, no
dithering): the pictures hold few colours (flat role and robot colours, shaded), a shared palette keeps them
steady from frame to frame, and Pillow then stores only what changed between frames.  That is about ten
times faster than a palette per frame and gives smaller files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Iterable, Sequence

import numpy as np

from mrgc.render.labels import Label
from mrgc.render.palette import REGION_FLOOR_ALPHA, RGB, LegendEntry, byte_colour, darker

BAND = (32, 32, 36)  # caption band colour
TEXT = (245, 245, 245)
SHEET_BACKGROUND = 255
#: how long the last frame of an animation stays (s) before it loops
HOLD_LAST = 1.5
PALETTE_SAMPLES = 12  # frames the GIF palette is made from
CAPTION_LINES = 2  # a caption longer than this many lines is cut with "..."
LEGEND_SHARE = 0.25  # most of a picture's height a legend may take
INK = (30, 30, 34)  # legend text


@lru_cache(maxsize=8)
def _font(size: int) -> Any:
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def text_size(height: int) -> int:
    """The font size (pixels) of captions, legends and names in a picture ``height`` pixels high."""
    return max(9, round(height / 26))


def _pad(size: int) -> int:
    return max(2, size // 3)


def wrap(text: str, size: int, room: float, lines: int) -> list[str]:
    """``text`` broken at spaces into at most ``lines`` lines ``room`` pixels wide; the last cut with "..."
    when the text does not fit."""
    font = _font(size)
    out: list[str] = []
    words = text.split(" ")
    while words and len(out) < lines:
        line = words.pop(0)
        while words and font.getlength(line + " " + words[0]) <= room:
            line += " " + words.pop(0)
        out.append(line)
    if words or (out and font.getlength(out[-1]) > room):
        last = " ".join([out[-1], *words]) if words else out[-1]
        while last and font.getlength(last + "...") > room:
            last = last[:-1]
        out[-1] = last + "..."
    return out


@dataclass(frozen=True)
class Layout:
    """Where things go in a ``width`` × ``height`` frame: ``top`` rows of legend, then the scene, then
    ``bottom`` rows of caption (``lines`` lines); text ``size`` pixels; ``labels`` the kinds named."""

    width: int
    height: int
    size: int
    top: int = 0
    bottom: int = 0
    lines: int = 0
    legend: tuple[LegendEntry, ...] = ()
    labels: tuple[str, ...] = ()

    @property
    def scene_height(self) -> int:
        """Rows of the rendered scene."""
        return self.height - self.top - self.bottom


def layout(
    width: int,
    height: int,
    captions: Iterable[str] = (),
    legend: Sequence[LegendEntry] = (),
    labels: tuple[str, ...] = (),
) -> Layout:
    """The layout of frames ``width`` × ``height`` with these captions (none: no caption band; dropped when it
    would take more than half the height), legend (dropped when it would take more than
    :data:`LEGEND_SHARE` of the height) and kinds of label."""
    size = text_size(height)
    pad = _pad(size)
    texts = set(captions)
    lines = max((len(wrap(t, size, width - 2 * pad, CAPTION_LINES)) for t in texts), default=0)
    bottom = lines * (size + 2) + 2 * pad if lines else 0
    if height - bottom < height / 2:  # a tiny picture: the caption would leave too little scene (none at 16 px)
        lines, bottom = 0, 0
    top = legend_band(width, legend, size).shape[0] if legend else 0
    if top > LEGEND_SHARE * height or height - top - bottom < height / 2:
        top, legend = 0, ()
    return Layout(width, height, size, top, bottom, lines, tuple(legend), labels)


def compose(scene: np.ndarray, lay: Layout, text: str, labels: Sequence[Label] = ()) -> np.ndarray:
    """A whole frame: the legend band, ``scene`` (``lay.scene_height`` rows) with ``labels`` drawn on it,
    and ``text`` in the caption band."""
    from PIL import Image, ImageDraw

    img = draw_labels(scene, place_labels(labels, lay.size, lay.width, lay.scene_height), lay.size)
    parts = [legend_band(lay.width, lay.legend, lay.size)] if lay.top else []
    parts.append(img)
    if lay.bottom:
        band = Image.new("RGB", (lay.width, lay.bottom), BAND)
        draw = ImageDraw.Draw(band)
        pad = _pad(lay.size)
        for i, line in enumerate(wrap(text, lay.size, lay.width - 2 * pad, lay.lines)):
            draw.text((pad, pad + i * (lay.size + 2)), line, fill=TEXT, font=_font(lay.size))
        parts.append(np.asarray(band))
    return np.concatenate(parts, axis=0)


def caption(image: np.ndarray, text: str) -> np.ndarray:
    """``image`` (H, W, 3 uint8) with ``text`` in a dark band over its bottom edge (wrapped, then cut)."""
    h, w = image.shape[:2]
    lay = layout(w, h, [text])
    return compose(image[: lay.scene_height], lay, text)


Box = tuple[int, int, int, int]  # x0, y0, x1, y1 (inclusive)


def label_size(label: Label, size: int) -> tuple[int, int, int]:
    """A label's font size and its box's width and height (pixels)."""
    fs = size if label.kind != "object" else max(8, size - 2)
    pad = max(2, fs // 4)
    return fs, round(_font(fs).getlength(label.text)) + 2 * pad, fs + 2 * pad


def place_labels(labels: Sequence[Label], size: int, width: int, height: int) -> list[tuple[Label, Box]]:
    """Each label's box in a ``width`` × ``height`` picture: centred on its anchor, above it (or below),
    kept inside the picture and moved up or down, a box height at a time, out of the boxes placed before
    it (robots first, then regions, then objects)."""
    order = {"robot": 0, "region": 1, "object": 2}
    placed: list[tuple[Label, Box]] = []
    for label in sorted(labels, key=lambda lb: order.get(lb.kind, 3)):
        _, w, h = label_size(label, size)
        x0 = int(min(max(0, round(label.x - w / 2)), max(0, width - w)))
        y = round(label.y + 3) if label.below else round(label.y - 3 - h)
        box = (x0, y, x0 + w - 1, y + h - 1)
        for k in (0, -1, 1, -2, 2, -3, 3):
            yk = int(min(max(0, y + k * (h + 1)), max(0, height - h)))
            candidate = (x0, yk, x0 + w - 1, yk + h - 1)
            if not any(_overlap(candidate, b) for _, b in placed):
                box = candidate
                break
        else:
            box = (x0, int(min(max(0, y), max(0, height - h))), x0 + w - 1, int(min(max(0, y), height - h)) + h - 1)
        placed.append((label, box))
    return placed


def _overlap(a: Box, b: Box) -> bool:
    return not (a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1])


def label_style(label: Label) -> tuple[tuple[int, int, int], tuple[int, int, int], tuple[int, int, int]]:
    """Fill, outline and text colours of a label: a robot's name white on its colour; a region's in its
    dark colour on white; an object's in black on its role's colour."""
    if label.kind == "robot":
        return byte_colour(label.colour), byte_colour(darker(label.colour)), (255, 255, 255)
    if label.kind == "region":
        return (255, 255, 255), byte_colour(darker(label.colour, 0.55)), byte_colour(darker(label.colour, 0.45))
    return byte_colour(label.colour), (20, 20, 20), (0, 0, 0)


def draw_labels(image: np.ndarray, placed: Sequence[tuple[Label, Box]], size: int) -> np.ndarray:
    """``image`` with each placed label drawn: its name in a box of its style."""
    if not placed:
        return image
    from PIL import Image, ImageDraw

    pic = Image.fromarray(np.ascontiguousarray(image))
    draw = ImageDraw.Draw(pic)
    for label, (x0, y0, x1, y1) in placed:
        fs, _, _ = label_size(label, size)
        fill, outline, ink = label_style(label)
        draw.rectangle((x0, y0, x1, y1), fill=fill, outline=outline)
        pad = max(2, fs // 4)
        draw.text((x0 + pad, y0 + pad), label.text, fill=ink, font=_font(fs))
    return np.asarray(pic)


def legend_band(width: int, entries: Sequence[LegendEntry], size: int) -> np.ndarray:
    """A white band ``width`` wide holding each entry's swatch and text, in rows as wide as it allows."""
    from PIL import Image, ImageDraw

    font = _font(size)
    pad, gap = _pad(size), max(6, size)
    rows: list[list[tuple[LegendEntry, int]]] = [[]]
    x = pad
    for e in entries:
        w = size + 4 + round(font.getlength(e.text))
        if rows[-1] and x + w > width - pad:
            rows.append([])
            x = pad
        rows[-1].append((e, x))
        x += w + gap
    height = len(rows) * (size + 4) + 2 * pad - 4
    band = Image.new("RGB", (width, height), (SHEET_BACKGROUND,) * 3)
    draw = ImageDraw.Draw(band)
    for i, row in enumerate(rows):
        y = pad + i * (size + 4)
        for e, x in row:
            fill = _on_white(e.colour, REGION_FLOOR_ALPHA) if e.kind == "region" else e.colour  # as drawn
            outline = darker(e.colour, 0.55) if e.kind == "region" else darker(e.colour)
            draw.rectangle((x, y, x + size - 1, y + size - 1), fill=byte_colour(fill), outline=byte_colour(outline))
            draw.text((x + size + 4, y - 1), e.text, fill=INK, font=font)
    return np.asarray(band)


def _on_white(rgb: RGB, alpha: float) -> RGB:
    r, g, b = ((1 - alpha) + alpha * c for c in rgb)
    return r, g, b


def with_legend(image: np.ndarray, entries: Sequence[LegendEntry], size: int) -> np.ndarray:
    """``image`` under a legend band as wide as it."""
    if not entries:
        return image
    return np.concatenate([legend_band(image.shape[1], entries, size), image], axis=0)


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
