"""The pybullet client: the one module that imports pybullet, and nothing of mrgc's kinematics.

Everything here is lazy: ``import pybullet`` (and its build banner, silenced with :func:`quiet_output`)
happens on first use.  Two kinds of client:

- one shared DIRECT client per process (:func:`shared_client`, created again after a fork) for URDF
  validity checks (:func:`check_urdf`) and the kinematics references of :mod:`mrgc.testing.pybullet_reference`
  (URDFs loaded once each: :func:`shared_body`);
- private DIRECT clients (:func:`private_client`), one per world of its own: the validator's
  :class:`~mrgc.validator.world.ReplayScene`.

Frames: a link's frame is its URDF link frame (pybullet's ``worldLinkFrame``, not its centre of mass);
:func:`pose_of` turns pybullet's (position, quaternion) into a 4×4 transform.
"""

from __future__ import annotations

import contextlib
import os
import sys
from typing import Any, Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from mrgc.geometry import transforms as tf

# -------------------------------------------------------------------------------- clients


_CLIENT: dict[str, Any] = {}

#: URDF files pybullet has loaded in this process or the process it was forked from, by (real path, size,
#: modification time): a file accepted once is not loaded again to be checked, so phase 1's forked workers
#: never start a pybullet client of their own (0.2 s of CPU each, measured on the Panda)
_ACCEPTED: set[tuple[str, int, int]] = set()


@contextlib.contextmanager
def quiet_output() -> Iterator[None]:
    """Silence C-level writes to fds 1 and 2 (pybullet's build-time banner, which goes to stdout or stderr
    depending on the build, and its loader warnings) so JSON on stdout and diagnostics stay clean."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError):
            pass
    saved: list[tuple[int, int]] = []
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
    except OSError:  # pragma: no cover
        yield
        return
    try:
        for fd in (1, 2):
            try:
                saved.append((fd, os.dup(fd)))
            except OSError:  # that fd is closed: nothing to protect
                continue
            os.dup2(devnull, fd)
        yield
    finally:
        _c_fflush()
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)


def _c_fflush() -> None:
    """Flush C stdio buffers: printf output buffered while fd 1 was redirected must go to /dev/null."""
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # pragma: no cover - non-POSIX
        pass


def shared_client() -> tuple[Any, int]:
    """The pybullet module and this process's shared DIRECT client (created on first use, again after fork):
    the client of URDF checks and of the kinematics references (a replay world makes its own)."""
    if _CLIENT.get("pid") != os.getpid():
        with quiet_output():
            import pybullet

            cid = pybullet.connect(pybullet.DIRECT)
        _CLIENT.clear()
        _CLIENT.update(pid=os.getpid(), pb=pybullet, cid=cid, bodies={})
    return _CLIENT["pb"], _CLIENT["cid"]


def data_path() -> str:
    """pybullet_data's folder (URDFs not found beside a .mrg file are looked up there)."""
    with quiet_output():
        import pybullet_data
    return str(pybullet_data.getDataPath())


def private_client() -> tuple[Any, int]:
    """The pybullet module and a new DIRECT client of the caller's own (disconnect it when done)."""
    with quiet_output():
        import pybullet

        return pybullet, int(pybullet.connect(pybullet.DIRECT))


def _file_key(path: str) -> tuple[str, int, int]:
    """A file as its (real path, size, modification time): a file edited since is another key."""
    st = os.stat(path)
    return os.path.realpath(path), st.st_size, st.st_mtime_ns


def shared_body(urdf: str) -> int:
    """The body id of the resolved URDF in the shared client, loaded once per version of the file (fixed base,
    identity base pose), without its visual shapes: nothing here draws, and the Panda's visual meshes are 90 %
    of its loading time (0.32 s of CPU with them, 0.03 s without, measured here)."""
    pb, cid = shared_client()
    bodies: dict[tuple[str, int, int], int] = _CLIENT["bodies"]
    key = _file_key(urdf)
    if key not in bodies:
        with quiet_output():
            bodies[key] = pb.loadURDF(urdf, useFixedBase=True, flags=pb.URDF_IGNORE_VISUAL_SHAPES, physicsClientId=cid)
    return bodies[key]


def check_urdf(path: str) -> str | None:
    """Why pybullet refuses to load the URDF at ``path`` (None: it loads): its links, joints and collision
    shapes; visual shapes are not loaded (:func:`shared_body`), so a broken visual mesh is not reported
    (nothing in mrgc reads visual shapes: the renderer draws collision geometry).  A version of the file
    accepted before (the same path, size and modification time) is not loaded again, in this process or a
    fork of it, and pybullet_data's own files are not loaded to be checked (:func:`_pybullets_own`)."""
    try:
        key = _file_key(path)
    except OSError as exc:
        return str(exc)
    if key in _ACCEPTED or _pybullets_own(key[0]):
        return None
    pb, _ = shared_client()
    try:
        shared_body(path)
    except pb.error as exc:
        return str(exc) or "loadURDF failed"
    _ACCEPTED.add(key)
    return None


def _pybullets_own(real: str) -> bool:
    """Whether the real path ``real`` is one of pybullet_data's own files (the Panda of most problems): the
    files pybullet ships load in it, and checking one would start a pybullet client in every planning run
    (0.05 s of CPU) only to load what the validator's world loads anyway (tests/test_kinematics.py loads
    them)."""
    folder = os.path.realpath(data_path())
    return os.path.commonpath([folder, real]) == folder


def pose_of(pos: Sequence[float], orn: Sequence[float]) -> NDArray[np.float64]:
    """The 4×4 transform of a pybullet position and quaternion (x, y, z, w), the quaternion normalised
    (pybullet's are single precision)."""
    quat = np.asarray(orn, dtype=float)
    return tf.from_quaternion(pos, quat / np.linalg.norm(quat))
