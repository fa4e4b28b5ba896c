"""Offscreen rendering of the MuJoCo gripper scenes on the CPU: frames for the report and an
optional MP4.

MuJoCo picks its OpenGL back end from ``MUJOCO_GL`` when it is first imported; without a display
:func:`choose_gl_backend` sets EGL (Mesa's software EGL: Debian packages ``libegl1``,
``libegl-mesa0``, ``libgl1-mesa-dri``) or OSMesa (``libosmesa6``): the first that opens a context. It
must run before ``mujoco`` is imported: this module imports MuJoCo only inside the functions
that render. MP4 files are written through ``imageio-ffmpeg`` (a pip
wheel that carries its own ffmpeg; ``pip install "lugrip[video]"``).
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np


__all__ = [
    "GL_PACKAGES",
    "FrameRecorder",
    "RenderUnavailable",
    "choose_gl_backend",
    "video_writer_available",
]

#: Debian packages of each offscreen OpenGL back end (documented in validation/mujoco/README.md).
GL_PACKAGES = {
    "egl": "libegl1 libegl-mesa0 libgl1-mesa-dri",
    "osmesa": "libosmesa6",
}


def choose_gl_backend() -> str | None:
    """Set ``MUJOCO_GL`` for offscreen rendering when it is unset and there is no display:
    "egl" when libEGL is installed and opens a context, else "osmesa" when libOSMesa does. MuJoCo reads the variable
    when it is first imported, so this must run before. Returns the back end in force (None:
    none found, or MuJoCo was imported already; rendering then reports why it failed)."""
    current = os.environ.get("MUJOCO_GL")
    if current:
        return current.lower()
    if os.environ.get("DISPLAY"):
        return "glfw"
    if "mujoco" in sys.modules:
        return None
    for backend, lib in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(lib) and _gl_context_works(backend):
            os.environ["MUJOCO_GL"] = backend
            return backend
    return None


def _gl_context_works(backend: str) -> bool:
    """Whether MuJoCo can open an offscreen context with `backend` here, tried in a child
    process (MuJoCo fixes its back end at import; libEGL may be installed without a usable
    device, as on a container without a GPU, where OSMesa still renders)."""
    import subprocess

    probe = "import mujoco; c = mujoco.GLContext(8, 8); c.make_current(); c.free()"
    try:
        p = subprocess.run(
            [sys.executable, "-c", probe],
            env={**os.environ, "MUJOCO_GL": backend},
            capture_output=True,
            timeout=60,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return False
    return p.returncode == 0



class RenderUnavailable(RuntimeError):
    """No OpenGL back end (or no video writer) is available; the message says what to install."""


def video_writer_available() -> bool:
    try:
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        return False
    return True


def _no_gl_message(err: Exception) -> str:
    return (
        f"offscreen rendering is not available ({type(err).__name__}: {err}); MUJOCO_GL="
        f"{os.environ.get('MUJOCO_GL', '(unset)')}. Install EGL (apt-get install "
        f"{GL_PACKAGES['egl']}) or OSMesa (apt-get install {GL_PACKAGES['osmesa']}) and set "
        "MUJOCO_GL=egl or osmesa before starting Python"
    )


class FrameRecorder:
    """Frame callback for :func:`lugrip.sim.mujoco.loop.run_mujoco_loop`: renders the scene's
    ``side`` camera at the `snapshot_times` [s] (kept in ``frames``: list of (t, RGB array)) and,
    when `video` is a path, every 1/fps s into an MP4.

    Raises:
        RenderUnavailable: at the first frame when no OpenGL context can be made, or at
            construction when `video` is given and imageio-ffmpeg is missing.
    """

    def __init__(
        self,
        snapshot_times: Sequence[float] = (),
        *,
        video: str | Path | None = None,
        fps: float = 25.0,
        width: int = 480,
        height: int = 360,
        camera: str = "side",
    ):
        self.snapshot_times = sorted(float(t) for t in snapshot_times)
        self.frames: list[tuple[float, np.ndarray]] = []
        self.video = Path(video) if video is not None else None
        self.fps = float(fps)
        self.size = (int(height), int(width))
        self.camera = camera
        self._renderer = None
        self._writer = None
        self._next_snap = 0
        self._next_video = 0.0
        self.video_frames = 0
        if self.video is not None and not video_writer_available():
            raise RenderUnavailable(
                'writing MP4 needs imageio-ffmpeg (pip install "lugrip[video]")'
            )

    def _render(self, m, d) -> np.ndarray:
        import mujoco

        if self._renderer is None:
            try:
                self._renderer = mujoco.Renderer(m, *self.size)
            except Exception as err:
                raise RenderUnavailable(_no_gl_message(err)) from err
        self._renderer.update_scene(d, camera=self.camera)
        return self._renderer.render().copy()

    def __call__(self, m, d, t: float) -> None:
        snap = (
            self._next_snap < len(self.snapshot_times)
            and t >= self.snapshot_times[self._next_snap] - 1e-9
        )
        vid = self.video is not None and t >= self._next_video - 1e-9
        if not (snap or vid):
            return
        img = self._render(m, d)
        if snap:
            self.frames.append((t, img))
            while (
                self._next_snap < len(self.snapshot_times)
                and t >= self.snapshot_times[self._next_snap] - 1e-9
            ):
                self._next_snap += 1
        if vid:
            if self._writer is None:
                import imageio_ffmpeg

                self.video.parent.mkdir(parents=True, exist_ok=True)
                self._writer = imageio_ffmpeg.write_frames(
                    str(self.video),
                    (self.size[1], self.size[0]),
                    fps=self.fps,
                    macro_block_size=8,
                    quality=6,
                )
                self._writer.send(None)
            self._writer.send(np.ascontiguousarray(img))
            self.video_frames += 1
            self._next_video += 1.0 / self.fps

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
