"""The one figure helper of gearbody: a matplotlib Figure of an exact pixel size on an Agg canvas, and
saving it as PNG (to a file, or as base64 text for an HTML page).

No pyplot, no display, the global backend untouched. matplotlib is imported when a figure is made,
so importing :mod:`gearbody.plotting` stays cheap.
"""

from __future__ import annotations

import base64
import io
import os
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DEFAULT_SIZE_PX", "PathLike", "new_figure", "png_base64", "save_figure"]

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


def save_figure(fig: Figure, path: PathLike, dpi: int = 100) -> Path:
    """Write ``fig`` as PNG to ``path`` (parent folders created) at the requested pixel size."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi, format="png")  # no bbox_inches="tight": keeps the requested pixel size
    return out


def png_base64(fig: Figure, dpi: int = 100) -> str:
    """``fig`` as PNG, base64-encoded (for ``<img src="data:image/png;base64,...">``)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return base64.b64encode(buf.getvalue()).decode("ascii")
