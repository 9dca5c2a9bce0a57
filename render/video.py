"""Videos (``.mp4``) with imageio's ffmpeg plugin (the one render module that imports imageio).

The plugin is the ``imageio-ffmpeg`` package, which ships an ffmpeg binary; without it, asking for ``.mp4``
is a :class:`~mrgc.errors.MissingBackendError` (exit code 4) raised before anything is drawn.  Frames are
H.264 in yuv420p, padded by one pixel to even sizes where needed.
"""

from __future__ import annotations

import importlib.util
from typing import Any, Sequence

import numpy as np

from mrgc.errors import MissingBackendError


def mp4_available() -> bool:
    """Whether imageio's ffmpeg plugin (package ``imageio-ffmpeg``) is installed."""
    return importlib.util.find_spec("imageio_ffmpeg") is not None


def require_mp4(path: str) -> None:
    """MissingBackendError unless ``.mp4`` can be written."""
    if not mp4_available():
        raise MissingBackendError(
            f"cannot write {path}: .mp4 needs imageio's ffmpeg plugin "
            "(pip install imageio-ffmpeg); .gif works without it"
        )


def write_mp4(path: str, images: Sequence[np.ndarray], fps: float, hold_last: float) -> None:
    """``images`` as an H.264 video at ``fps``, the last one shown ``hold_last`` seconds."""
    require_mp4(path)
    import imageio.v2 as iio2

    h, w = images[0].shape[:2]
    hold = max(1, round(hold_last * fps))
    writer: Any = iio2.get_writer(
        path,
        format="FFMPEG",
        mode="I",
        fps=fps,
        codec="libx264",
        macro_block_size=1,
        ffmpeg_log_level="error",
        output_params=["-pix_fmt", "yuv420p"],
    )
    with writer as out:
        for i, img in enumerate(images):
            even = np.pad(img, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
            for _ in range(hold if i == len(images) - 1 else 1):
                out.append_data(even)
