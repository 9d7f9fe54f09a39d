"""What gearbody writes about a run, engine-free: :mod:`.summary` (the values of summary.json),
:mod:`.html` (the self-contained report.html of ``gearbody run --report``) and :mod:`.mesh` (the mesh
report of ``gearbody mesh``, its figure in :mod:`.mesh.figure`). Figures are drawn with
:mod:`gearbody.plotting`."""
