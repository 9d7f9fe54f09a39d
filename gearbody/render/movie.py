"""Write rendered frames as PNG files, an animated GIF (Pillow) and an MP4 (ffmpeg, where installed)."""

from __future__ import annotations

import ctypes
import errno
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np

from gearbody.folders import atomic_write

from .poses import RenderError

FORMATS = ("gif", "mp4", "none")
"""The movie formats :func:`gearbody.render.render` writes (``mp4`` needs ffmpeg; ``none``: frames only)."""


def write_png(image: np.ndarray, path: Path) -> Path:
    """One frame as PNG, atomically (OutputError naming ``path`` if it cannot be written)."""
    from PIL import Image

    picture = Image.fromarray(np.asarray(image, dtype=np.uint8))
    return atomic_write(path, lambda tmp: picture.save(tmp, format="PNG", optimize=True))


def write_gif(frames: list[Path], path: Path, fps: float) -> Path:
    """Animated GIF of the PNG frames, looping, one shared adaptive palette."""
    from PIL import Image

    if not frames:
        raise RenderError("no frames to write")
    images = [Image.open(f).convert("RGB") for f in frames]
    # one palette for all frames (from a mosaic of them) keeps colours steady between frames
    palette = images[0].quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    quantised = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    return atomic_write(
        path,
        lambda tmp: quantised[0].save(
            tmp,
            format="GIF",
            save_all=True,
            append_images=quantised[1:],
            duration=max(int(round(1000 / fps)), 20),
            loop=0,
            optimize=False,
        ),
    )


def ffmpeg_available() -> bool:
    return shutil.which("ffmpeg") is not None


def _die_with_parent() -> None:
    """The encoder's ``preexec_fn`` on Linux: SIGTERM to it when the process that started it dies
    (``prctl(PR_SET_PDEATHSIG)``), so a render killed with SIGKILL leaves no ffmpeg running."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0)  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def write_mp4(frame_pattern: Path, path: Path, fps: float) -> Path:
    """H.264 MP4 from numbered PNG frames (needs ffmpeg on PATH)."""
    if not ffmpeg_available():
        raise RenderError("format = 'mp4': ffmpeg is not installed (use 'gif', or install ffmpeg)")
    cmd = [
        "ffmpeg",
        "-y",
        "-loglevel",
        "error",
        "-framerate",
        f"{fps:g}",
        "-i",
        str(frame_pattern),
        "-vf",
        "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        "-pix_fmt",
        "yuv420p",
        "-c:v",
        "libx264",
    ]

    def encode(tmp: Path) -> None:
        linux = sys.platform.startswith("linux")
        done = subprocess.run(
            [*cmd, str(tmp)], capture_output=True, text=True, preexec_fn=_die_with_parent if linux else None
        )
        if "No space left on device" in done.stderr:
            raise OSError(errno.ENOSPC, "No space left on device", str(tmp))
        if done.returncode != 0:
            raise RenderError(f"ffmpeg failed ({done.returncode}): {done.stderr.strip()[:500]}")

    return atomic_write(path, encode)
