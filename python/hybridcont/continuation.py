"""Point-by-point continuation of one branch, for loops of the user's own (BifurcationKit's ``iterator``).

    import hybridcont as hc
    slip = hc.model("slip")
    u0 = study.u(2, 10)                               # a point of a study, or any guess near the family
    for point in hc.continuation(slip, u0, max_points=50):
        print(point["index"], point["u"][-1])         # stop whenever: the branch so far stays
"""
import numpy as np

from . import _hybridcont as native


class continuation:
    """Iterates over the points of one branch of the time-based map through (near) u0.

    free / fix: free parameters and the unknowns that hold them (as Model.evaluate). Options: direction
    (+1/-1), initial_step, max_step, min_step, max_points, bounds={name: (lo, hi)}, rtol, atol. Each point is
    a dict: index, u, tangent, step, arclength, newton_iterations. After the loop, ``termination`` and
    ``message`` say why the branch ended."""

    def __init__(self, model, u0, free=None, fix=None, direction=1, initial_step=None, max_step=None,
                 min_step=None, max_points=None, bounds=None, rtol=None, atol=None):
        options = {"direction": int(direction)}
        for key, value in (("initial_step", initial_step), ("max_step", max_step), ("min_step", min_step),
                           ("max_points", max_points), ("rtol", rtol), ("atol", atol)):
            if value is not None:
                options[key] = value
        if bounds:
            options["bounds"] = [(str(k), -np.inf if lo is None else float(lo), np.inf if hi is None else float(hi))
                                 for k, (lo, hi) in bounds.items()]
        self._run = native.NativeContinuation(model._native, np.asarray(u0, dtype=float).tolist(),
                                              model._spec(free, fix), options)
        self._next = 0

    @property
    def unknowns(self):
        return list(self._run.unknowns)

    @property
    def termination(self):
        return self._run.termination

    @property
    def message(self):
        return self._run.message

    def __iter__(self):
        return self

    def __next__(self):
        while self._next >= self._run.num_points:
            if self._run.finished or self._run.step() == "finished" and self._next >= self._run.num_points:
                raise StopIteration
        point = dict(self._run.point(self._next))
        self._next += 1
        return point
