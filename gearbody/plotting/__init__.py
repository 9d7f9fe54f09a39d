"""The figures gearbody draws, one module per figure family, all on :mod:`.figure`'s one helper
(:func:`new_figure`, :func:`save_figure`: an Agg canvas of exact pixel size, no pyplot, no display).

:mod:`.result` K_d over time, folded K_d, spectra, signals; :mod:`.run` a run's standard PNGs;
:mod:`.planetary` a planetary run's; :mod:`.report` the HTML report's figures; :mod:`.kd_speed` K_d
against speed; :mod:`.campbell` the Campbell diagram; :mod:`.study`, :mod:`.sensitivity` and
:mod:`.calibration` a study's. The mesh report's figure, drawn from the scenario, is
:mod:`gearbody.reports.mesh.figure` (on :mod:`.figure` too).
The only package that imports matplotlib, and only when a figure is made.

A layer of its own (pyproject.toml's import contracts): it draws what it is given (arrays, analysis
results, a Result read by name) and imports only analysis, physics, the signal names and the folders;
the reports, the studies, Result and the command line import it, nothing below them does.
"""

from .figure import DEFAULT_SIZE_PX, new_figure, png_base64, save_figure

__all__ = ["DEFAULT_SIZE_PX", "new_figure", "png_base64", "save_figure"]
