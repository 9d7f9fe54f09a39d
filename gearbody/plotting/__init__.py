"""Every figure gearbody draws, one module per figure family, all on :mod:`.figure`'s one helper
(:func:`new_figure`, :func:`save_figure`: an Agg canvas of exact pixel size, no pyplot, no display).

:mod:`.result` K_d over time, folded K_d, spectra, signals; :mod:`.run` a run's standard PNGs;
:mod:`.report` the HTML report's figures; :mod:`.mesh` the mesh report; :mod:`.kd_speed` K_d against
speed; :mod:`.campbell` the Campbell diagram; :mod:`.study` a parameter study.
The only package that imports matplotlib, and only when a figure is made.
"""

from .figure import DEFAULT_SIZE_PX, new_figure, png_base64, save_figure

__all__ = ["DEFAULT_SIZE_PX", "new_figure", "png_base64", "save_figure"]
