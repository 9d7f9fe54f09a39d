"""The one figure helper of gearbody: a matplotlib Figure of an exact pixel size on an Agg canvas, and
saving it as PNG (to a file, or as base64 text for an HTML page).

No pyplot, no display, the global backend untouched. matplotlib is imported when a figure is made,
so importing :mod:`gearbody.plotting` stays cheap.
"""

from __future__ import annotations

import base64
import io
import os
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

from gearbody.folders import atomic_write

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.text import Text

__all__ = [
    "DEFAULT_SIZE_PX",
    "PathLike",
    "drop_overlapping",
    "new_figure",
    "png_base64",
    "save_figure",
    "set_title",
]

PathLike = str | os.PathLike[str]
DEFAULT_SIZE_PX: tuple[int, int] = (1000, 600)


def new_figure(size_px: tuple[int, int] = DEFAULT_SIZE_PX, dpi: int = 100) -> Figure:
    """A figure of ``size_px`` (width, height) pixels at ``dpi``, constrained layout, on an Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    width_px, height_px = size_px
    if width_px < 1 or height_px < 1 or dpi < 1:
        raise ValueError(f"size_px and dpi must be positive, got {size_px}, {dpi}")
    fig = Figure(figsize=(width_px / dpi, height_px / dpi), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def set_title(ax: Axes, title: str, **kwargs) -> None:
    """``ax.set_title(title)``, wrapped onto several lines where it is wider than the axes would fit."""
    fig = ax.get_figure()
    size_pt = float(kwargs.get("fontsize", 12)) if not isinstance(kwargs.get("fontsize"), str) else 12.0
    axes_px = fig.get_figwidth() * fig.dpi * ax.get_position().width
    chars = max(20, int(axes_px / (0.52 * size_pt * fig.dpi / 72)))  # a mean glyph is ~0.5 em wide
    ax.set_title(textwrap.fill(title, chars, break_on_hyphens=False), **kwargs)


def drop_overlapping(texts: list[Text], within: Axes | None = None) -> list[Text]:
    """Hide every text of ``texts`` (most important first) that overlaps an earlier one or leaves the
    figure (the axes ``within``, when given); returns those kept. Lays the figure out first, so extents
    are the final ones."""
    if not texts:
        return []
    fig = texts[0].get_figure()
    if not hasattr(fig.canvas, "get_renderer"):  # a bare Figure(): measure on an Agg canvas
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame = fig.bbox if within is None else within.get_window_extent(renderer)
    kept, boxes = [], []
    for text in texts:
        box = text.get_window_extent(renderer)
        inside = box.x0 >= frame.x0 and box.y0 >= frame.y0 and box.x1 <= frame.x1 and box.y1 <= frame.y1
        if inside and not any(box.overlaps(other) for other in boxes):
            kept.append(text)
            boxes.append(box)
        else:
            text.set_visible(False)
    return kept


def save_figure(fig: Figure, path: PathLike, dpi: int = 100) -> Path:
    """Write ``fig`` as PNG to ``path`` (parent folders created) at the requested pixel size, atomically
    (:func:`gearbody.folders.atomic_write`: OutputError naming ``path`` if it cannot be written)."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    # no bbox_inches="tight": keeps the requested pixel size; atomic: a full disk leaves no part
    return atomic_write(out, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))


def png_bytes(fig: Figure, dpi: int = 100) -> bytes:
    """``fig`` as PNG bytes (drawn once: write them to a file and embed them in a page alike)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def png_base64(fig: Figure, dpi: int = 100) -> str:
    """``fig`` as PNG, base64-encoded (for ``<img src="data:image/png;base64,...">``)."""
    return base64.b64encode(png_bytes(fig, dpi)).decode("ascii")
