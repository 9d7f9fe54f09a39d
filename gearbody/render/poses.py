"""Frames of an animation: which times to show and where every body is at each (no Exudyn).

A pose row holds, per :class:`~gearbody.render.layout.Body` in layout order, ``[x, y, theta]``: the
centre offset from its axis (lateral signals times the layout's ``lateral_scale``, so micrometres
become visible) and the drawn rotation ``sense * angle``. Angles come from the result's
``<body>_angle_rad`` signals; a body without one (the Muller scene's gears, a two-wheel scene's
motor and machine) turns rigidly with the body it follows.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import RenderError  # bad render request: option, value and what is allowed
from ..result import Result
from .layout import Layout

MAX_FRAMES = 2000
"""Most frames of one render (each is a raytraced picture of ~0.1-1 s)."""
GIF_LIMIT_BYTES = 2**30
"""An animated GIF holds every frame in memory while it is written (width x height x 3 bytes each)."""


def check_frames(frames: int, width_px: int, height_px: int, movie: str = "none") -> None:
    """Refuse a frame count that cannot be rendered within the limits, before anything runs."""
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_FRAMES:
        raise RenderError(f"frames = {frames!r}: must be a whole number in [1, {MAX_FRAMES}]")
    need = frames * width_px * height_px * 3
    if movie == "gif" and need > GIF_LIMIT_BYTES:
        most = GIF_LIMIT_BYTES // (width_px * height_px * 3)
        raise RenderError(
            f"frames = {frames} at {width_px}x{height_px}: an animated GIF holds every frame in memory "
            f"({need / 2**20:.0f} MiB, limit {GIF_LIMIT_BYTES / 2**20:.0f} MiB); at this size at most "
            f"{most} frames, or a smaller picture, or movie 'mp4' / 'none'"
        )


def frame_times(
    result: Result, frames: int, start_s: float | None = None, end_s: float | None = None
) -> np.ndarray:
    """``frames`` equally spaced times in [start_s, end_s] of the result.

    Default window: one revolution of the input (pinion) shaft at its mean speed, ending at the end
    of the result, so the default animation shows the drive running in steady state (capped at the
    result's length); its first frame is one step after the window's start, so a looping animation
    does not show the same pose twice.
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_FRAMES:
        raise RenderError(f"frames = {frames!r}: must be a whole number in [1, {MAX_FRAMES}]")
    t = result.time_s
    t0, t1 = float(t[0]), float(t[-1])
    default_window = start_s is None
    if end_s is None:
        end_s = t1
    if start_s is None:
        phi = result["pinion_angle_rad"]
        tail = t >= t1 - 0.1 * (t1 - t0)
        speed = abs(phi[tail][-1] - phi[tail][0]) / max(t[tail][-1] - t[tail][0], 1e-12)
        span = 2 * math.pi / speed if speed > 1e-9 else t1 - t0
        start_s = max(t0, end_s - span)
    for name, value in (("start_s", start_s), ("end_s", end_s)):
        if not t0 <= value <= t1:
            raise RenderError(f"{name} = {value:g}: must lie in the result's time range [{t0:g}, {t1:g}] s")
    if frames > 1 and not end_s > start_s:
        raise RenderError(f"end_s = {end_s:g}: must be > start_s = {start_s:g} for {frames} frames")
    if frames == 1:
        return np.array([end_s])
    if default_window:
        return np.linspace(start_s, end_s, frames + 1)[1:]
    return np.linspace(start_s, end_s, frames)


def body_angles_rad(layout: Layout, result: Result, times: np.ndarray) -> dict[str, np.ndarray]:
    """Model rotation angle of every body at ``times`` (own driven direction positive)."""
    out: dict[str, np.ndarray] = {}
    pending = list(layout.bodies)
    while pending:
        progress = False
        for b in list(pending):
            if b.angle_signal in result:
                out[b.name] = np.interp(times, result.time_s, result[b.angle_signal])
            elif b.follows in out:
                out[b.name] = b.ratio * out[b.follows]
            else:
                continue
            pending.remove(b)
            progress = True
        if not progress:
            missing = ", ".join(b.angle_signal for b in pending)
            raise RenderError(f"the result has no rotation for {missing} (needs at least 'pinion_angle_rad')")
    return out


def body_poses(
    layout: Layout,
    result: Result,
    times: np.ndarray,
    lateral_scale: float | None = None,
    lateral_about_mean: bool = True,
) -> np.ndarray:
    """Pose rows, shape (len(times), 3 * bodies): x, y offsets (m, magnified) and drawn angle.

    With ``lateral_about_mean`` (default) the gear centres move about their mean position over
    ``times``: the vibration is magnified, not the static bearing deflection under load (which at
    x1000 would push the drawn teeth out of mesh).
    """
    scale = layout.lateral_scale if lateral_scale is None else lateral_scale
    if not scale >= 0:
        raise RenderError(f"lateral_scale = {scale:g}: must be >= 0")
    angles = body_angles_rad(layout, result, times)
    poses = np.zeros((len(times), 3 * len(layout.bodies)))
    for k, b in enumerate(layout.bodies):
        if b.lateral_signals:
            for d, name in enumerate(b.lateral_signals):
                if name in result:
                    u = np.interp(times, result.time_s, result[name])
                    poses[:, 3 * k + d] = scale * (u - u.mean() if lateral_about_mean else u)
        poses[:, 3 * k + 2] = b.sense * angles[b.name]
    return poses


def kinematic_result(speed_rad_s: float, duration_s: float, samples: int = 2001) -> Result:
    """A result of rigid rotation at ``speed_rad_s`` of the input shaft (no simulation): pictures of
    the machine alone."""
    t = np.linspace(0.0, duration_s, samples)
    return Result(time_s=t, signals={"pinion_angle_rad": speed_rad_s * t}, meta={"kinematic": True})
