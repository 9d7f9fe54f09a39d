"""Write rendered frames as PNG files, an animated GIF (Pillow) and an MP4 (ffmpeg, where installed)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

from .poses import RenderError

FORMATS = ("gif", "mp4", "none")


def write_png(image: np.ndarray, path: Path) -> Path:
    from PIL import Image

    Image.fromarray(np.asarray(image, dtype=np.uint8)).save(path, optimize=True)
    return path


def write_gif(frames: list[Path], path: Path, fps: float) -> Path:
    """Animated GIF of the PNG frames, looping, one shared adaptive palette."""
    from PIL import Image

    if not frames:
        raise RenderError("no frames to write")
    images = [Image.open(f).convert("RGB") for f in frames]
    # one palette for all frames (from a mosaic of them) keeps colours steady between frames
    palette = images[0].quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    quantised = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    quantised[0].save(
        path,
        save_all=True,
        append_images=quantised[1:],
        duration=max(int(round(1000 / fps)), 20),
        loop=0,
        optimize=False,
    )
    return path


def ffmpeg_available() -> bool:
    return shutil.which("ffmpeg") is not None


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
        str(path),
    ]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RenderError(f"ffmpeg failed ({done.returncode}): {done.stderr.strip()[:500]}")
    return path
