"""Mesh files (OBJ, STL): read once, checked, bounded.

Every mesh mrgc uses, of a ``(mesh "file")`` shape or of a URDF link, is read by :func:`read_mesh`, which
refuses with a located diagnostic (E403, ``file:line``) what would otherwise give garbage facts: a
coordinate that is not a finite number (``nan``, ``inf``, ``1e999``) or beyond :data:`MAX_COORD` metres,
a face index outside the vertex list, a line that is not a vertex, a file that is not a regular file
(a FIFO is refused before it is read) or larger than :data:`MAX_BYTES`.
"""

from __future__ import annotations

import functools
import math
import struct

import numpy as np

from mrgc.errors import Diagnostic, InputError, Span
from mrgc.language.files import FileTooLarge, read_regular

#: code of "mesh file unreadable or invalid"
E_MESH = "E403"
#: mesh files larger than this are refused (64 MiB: a 1.3-million-triangle binary STL)
MAX_BYTES = 64 * 1024 * 1024
#: largest coordinate magnitude, in metres after scaling (10 km: anything larger is a unit mistake)
MAX_COORD = 1e4


def mesh_error(path: str, message: str, line: int = 1) -> InputError:
    """E403 located at ``path:line``."""
    return InputError([Diagnostic(E_MESH, f"mesh file '{path}': {message}", Span(path, line, 1, line, 2))])


def _read(path: str) -> bytes:
    try:
        return read_regular(path, MAX_BYTES)
    except FileTooLarge as exc:
        raise mesh_error(path, f"{exc.size} bytes; the limit is {MAX_BYTES} bytes") from None
    except OSError as exc:
        raise mesh_error(path, f"cannot be read: {exc.strerror or exc}") from None


@functools.lru_cache(maxsize=256)
def read_mesh(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (F, 3) of an OBJ (``v``/``f`` lines) or STL file, unscaled."""
    data = _read(path)
    v, f = _read_stl(path, data) if path.lower().endswith(".stl") else _read_obj(path, data)
    v.setflags(write=False)
    f.setflags(write=False)
    return v, f


def checked_vertices(path: str, scale: float | tuple[float, ...] = 1.0) -> np.ndarray:
    """The vertices of ``path`` scaled by ``scale``, E403 when a scaled coordinate exceeds MAX_COORD."""
    v, _ = read_mesh(path)
    scaled: np.ndarray = v * np.asarray(scale, dtype=float)
    if scaled.size and float(np.abs(scaled).max()) > MAX_COORD:
        raise mesh_error(path, f"a coordinate times the scale {scale} exceeds {MAX_COORD:g} m (wrong units?)")
    return scaled


def _number(tok: str, path: str, line: int) -> float:
    try:
        x = float(tok)
    except ValueError:
        raise mesh_error(path, f"{tok[:40]!r} is not a number", line) from None
    if not math.isfinite(x) or abs(x) > MAX_COORD:
        raise mesh_error(path, f"coordinate {tok[:40]!r} is not a finite number within {MAX_COORD:g}", line)
    return x


def _read_obj(path: str, data: bytes) -> tuple[np.ndarray, np.ndarray]:
    verts: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []
    for n, raw in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        if raw.startswith("v "):
            toks = raw.split()[1:4]
            if len(toks) != 3:
                raise mesh_error(path, "a vertex needs 3 coordinates", n)
            verts.append((_number(toks[0], path, n), _number(toks[1], path, n), _number(toks[2], path, n)))
        elif raw.startswith("f "):
            try:
                idx = [int(tok.split("/")[0]) for tok in raw.split()[1:]]
            except ValueError:
                raise mesh_error(path, "a face lists vertex numbers", n) from None
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            if len(idx) < 3 or any(not 0 <= i < len(verts) for i in idx):
                raise mesh_error(
                    path,
                    f"face {raw.split(None, 1)[-1][:40]!r} needs 3 or more vertices among "
                    f"the {len(verts)} defined before it",
                    n,
                )
            faces.extend((idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1))
    return np.array(verts, dtype=float).reshape(-1, 3), np.array(faces, dtype=np.int64).reshape(-1, 3)


def _read_stl(path: str, data: bytes) -> tuple[np.ndarray, np.ndarray]:
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * count == len(data):
            rec = np.frombuffer(
                data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=count, offset=84
            )
            tri = rec["v"].astype(float).reshape(-1, 3)
            bad = ~np.isfinite(tri).all(axis=1) | (np.abs(tri) > MAX_COORD).any(axis=1)
            if bad.any():
                raise mesh_error(
                    path,
                    f"triangle {int(np.argmax(bad)) // 3 + 1} of the binary STL has a "
                    f"coordinate that is not a finite number within {MAX_COORD:g}",
                )
            return tri, np.arange(len(tri)).reshape(-1, 3)
    pts = []
    for n, raw in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        toks = raw.split()
        if toks and toks[0] == "vertex":
            if len(toks) != 4:
                raise mesh_error(path, "a vertex needs 3 coordinates", n)
            pts.append([_number(t, path, n) for t in toks[1:4]])
    tri = np.array(pts, dtype=float).reshape(-1, 3)
    return tri, np.arange(len(tri) - len(tri) % 3).reshape(-1, 3)
