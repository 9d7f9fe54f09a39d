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
    result: Result,
    frames: int,
    start_s: float | None = None,
    end_s: float | None = None,
    input_signal: str = "pinion_angle_rad",
) -> np.ndarray:
    """``frames`` equally spaced times in [start_s, end_s] of the result.

    Default window: one revolution of the input shaft (``input_signal``) at its mean speed, ending at the end
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
        phi = result[input_signal]
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
            raise RenderError(
                f"the result has no rotation for {missing} (needs at least {layout.input_signal!r})"
            )
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

    A planet rides on the drawn carrier: its centre is the carrier's pin point (the carrier's drawn,
    magnified centre, turned by the drawn carrier angle), plus its own true bearing deflection
    (centre signal minus the pin point of the true carrier centre); without magnification it is
    exactly its centre signal.
    """
    scale = layout.lateral_scale if lateral_scale is None else lateral_scale
    if not scale >= 0:
        raise RenderError(f"lateral_scale = {scale:g}: must be >= 0")
    angles = body_angles_rad(layout, result, times)
    poses = np.zeros((len(times), 3 * len(layout.bodies)))
    index = {b.name: k for k, b in enumerate(layout.bodies)}

    def signal(name):
        return np.interp(times, result.time_s, result[name]) if name in result else None

    for k, b in enumerate(layout.bodies):
        if b.lateral_signals:
            for d, name in enumerate(b.lateral_signals):
                u = signal(name)
                if u is not None:
                    u = u * (b.mirror if d == 1 else 1)
                    poses[:, 3 * k + d] = scale * (u - u.mean() if lateral_about_mean else u)
        poses[:, 3 * k + 2] = b.sense * angles[b.name]
    for k, b in enumerate(layout.bodies):
        if b.orbit is None:
            continue
        o, c = b.orbit, index[b.orbit.carrier]
        carrier = layout.bodies[c]
        drawn = poses[:, 3 * c : 3 * c + 3]  # the carrier's drawn offset and angle
        true = [signal(n) for n in (*(carrier.lateral_signals or ()), *o.centre_signals)]
        if all(u is not None for u in true):  # the centre signal, moved as the carrier's drawing is
            cx, cy, px, py = true
            pin = np.column_stack([px - cx, b.mirror * (py - cy)]) + drawn[:, :2]
        else:  # on its pin, the carrier rigid
            turn = drawn[:, 2] + o.angle_rad
            pin = drawn[:, :2] + o.radius_m * np.column_stack([np.cos(turn), np.sin(turn)])
        centre = np.asarray(o.centre_xy_m) + pin
        poses[:, 3 * k : 3 * k + 2] = centre - np.asarray(b.axis_xy_m)
    return poses


def drawn_signals(layout: Layout, result: Result) -> list[str]:
    """The result's signals a drawing of ``layout`` reads: time, the input rotation, every body's rotation
    and centre motion the result holds."""
    names = ["time_s", layout.input_signal]
    for b in layout.bodies:
        names += [b.angle_signal, *(b.lateral_signals or ()), *(b.orbit.centre_signals if b.orbit else ())]
    return [n for n in dict.fromkeys(names) if n in result]


def check_drawable(layout: Layout, result: Result) -> None:
    """RenderError naming the first signal the drawing reads that holds a NaN or an infinity (where and
    how many), or a time axis that does not increase."""
    t = np.asarray(result.time_s, dtype=float)
    for name in drawn_signals(layout, result):
        values = np.asarray(result[name], dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            k = int(np.argmax(bad))
            at = f"t = {t[k]:g} s" if name != "time_s" and np.isfinite(t[k]) else f"sample {k}"
            raise RenderError(
                f"result: {name} holds {int(bad.sum())} of {values.size} values that are not finite (NaN or "
                f"inf, the first at {at}); nothing can be drawn from them: simulate the scene again"
            )
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise RenderError("result: time_s does not increase strictly; nothing can be drawn from it")


def kinematic_result(
    speed_rad_s: float, duration_s: float, samples: int = 2001, signal: str = "pinion_angle_rad"
) -> Result:
    """A result of rigid rotation at ``speed_rad_s`` of the input shaft (no simulation): pictures of
    the machine alone. ``signal`` names the input's rotation (``Layout.input_signal``)."""
    t = np.linspace(0.0, duration_s, samples)
    return Result(time_s=t, signals={signal: speed_rad_s * t}, meta={"kinematic": True})
