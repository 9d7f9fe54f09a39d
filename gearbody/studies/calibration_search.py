"""The two searches of a calibration (:mod:`gearbody.studies.calibration`), in normalised coordinates u in
[0, 1] per parameter: the global, gradient-free search (nevergrad's differential evolution, ``batch``
points asked at a time) and the local least-squares polish (scipy's trust-region reflective
``least_squares``, its forward-difference Jacobian evaluated as one batch). ``run(us, stage)`` evaluates
a batch of points and returns their residuals."""

from __future__ import annotations

import numpy as np

OPTIMIZER = "TwoPointsDE"
"""nevergrad optimiser of the global search."""


def step(u: np.ndarray, j: int, h: float) -> np.ndarray:
    """The forward-difference step ``h`` of coordinate ``j`` at ``u`` (backwards where it would leave
    [0, 1])."""
    e = np.zeros_like(u)
    e[j] = h if u[j] + h <= 1.0 else -h  # stay inside the bounds
    return e


def global_search(run, u_start: np.ndarray, budget: int, batch: int, seed: int) -> None:
    """``budget`` evaluations of nevergrad's :data:`OPTIMIZER` from ``u_start``, ``batch`` per round."""
    try:
        import nevergrad as ng
    except ImportError as exc:
        raise ImportError("calibration needs nevergrad: pip install gearbody[calibrate]") from exc
    param = ng.p.Array(init=u_start).set_mutation(sigma=0.25).set_bounds(0.0, 1.0)
    param.random_state.seed(seed)
    # NGOpt's automatic choice picks a metamodel that fails with numpy 2 in nevergrad 1.0.12 (TypeError in
    # metamodel.py): differential evolution, robust on small bounded problems and batch-parallel
    opt = ng.optimizers.registry[OPTIMIZER](parametrization=param, budget=budget, num_workers=batch)
    opt.suggest(u_start)  # the stated start is the first point asked
    done = 0
    while done < budget:
        n = min(batch, budget - done)
        cands = [opt.ask() for _ in range(n)]
        us = [np.clip(np.asarray(c.value, float), 0.0, 1.0) for c in cands]
        for c, r in zip(cands, run(us, "global"), strict=True):
            opt.tell(c, 0.5 * float(r @ r))
        done += n


def least_squares_polish(run, u0: np.ndarray, n_targets: int, max_evaluations: int, h: float) -> np.ndarray:
    """The least-squares optimum from ``u0`` within about ``max_evaluations`` evaluations."""
    from scipy.optimize import least_squares

    def fun(u):
        return run([np.asarray(u, float)], "polish")[0]

    def jac(u):
        u = np.asarray(u, float)
        r0 = fun(u)
        steps = [u + step(u, j, h) for j in range(u.size)]
        rs = run(steps, "polish")
        return np.column_stack(
            [(r - r0) / (s[j] - u[j]) for j, (s, r) in enumerate(zip(steps, rs, strict=True))]
        )

    fit = least_squares(
        fun,
        u0,
        jac=jac,
        bounds=(0.0, 1.0),
        max_nfev=max(1, max_evaluations // (u0.size + 2)),
        x_scale=1.0,
        method="trf",
    )
    return np.asarray(fit.x, float)
