"""Cap mechanics curves of this process: one FElupe run per distinct cap case
(:class:`matcad.mechanics.case.CapCase` is frozen and hashable), shared by predictions and inference."""

_CAP_CURVES: dict = {}


def cap_curve(case, progress=None):
    """:func:`matcad.mechanics.solver.cap_curve` of a cap case (forces N, displacements mm, volumes mm³), computed
    once per distinct case; ``progress(steps done, steps)`` is told as the load steps converge."""
    if case not in _CAP_CURVES:
        from matcad.mechanics import solver

        _CAP_CURVES[case] = solver.cap_curve(case, progress)
    return _CAP_CURVES[case]
