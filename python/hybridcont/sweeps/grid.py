"""The grid of a sweep and its folder's definition: values per parameter, grid point ids, the breadth-first
tree of neighbours, the grid points that continue curves, and sweep.json."""
import itertools
import json
import os

import numpy as np


SWEEP_FORMAT = 1


def grid_values(spec):
    """{name: (start, stop, count)} or {name: [values]} as {name: [values]} (linspace for a triple)."""
    out = {}
    for name, values in spec.items():
        if isinstance(values, tuple) and len(values) == 3:
            start, stop, count = values
            if int(count) != count or count < 1:
                raise ValueError("grid %s: the count must be a positive whole number, got %r" % (name, count))
            out[name] = [float(v) for v in np.linspace(float(start), float(stop), int(count))]
        else:
            vals = [float(v) for v in values]
            if not vals:
                raise ValueError("grid %s: no values" % name)
            out[name] = vals
    if not out:
        raise ValueError("sweep: the grid has no parameter")
    return out


def grid_points(values):
    """[(id, {name: value})] in row-major order; id "i_j" holds the indices along each grid parameter."""
    names = list(values)
    points = []
    for index in itertools.product(*(range(len(values[n])) for n in names)):
        points.append(("_".join(str(i) for i in index), {n: values[n][i] for n, i in zip(names, index)}))
    return points


def _read_json(path, what):
    """A sweep file read back (untrusted: a damaged or foreign file is a ValueError naming it)."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise ValueError("'%s': not %s (%s)" % (path, what, e))


def neighbour_tree(values, origin):
    """{point id: parent id or None}: the grid covered from the point nearest `origin` ({name: value}) outwards
    in breadth-first order, each point's parent a grid neighbour (one index apart along one parameter)."""
    names = list(values)
    shape = [len(values[n]) for n in names]

    def nearest(n):
        v = values[n]
        return min(range(len(v)), key=lambda i: abs(v[i] - origin.get(n, v[0])))
    root = tuple(nearest(n) for n in names)
    parent = {root: None}
    queue = [root]
    for index in queue:
        for axis in range(len(names)):
            for step in (-1, 1):
                j = list(index)
                j[axis] += step
                j = tuple(j)
                if 0 <= j[axis] < shape[axis] and j not in parent:
                    parent[j] = index
                    queue.append(j)
    key = lambda t: "_".join(str(i) for i in t)  # noqa: E731
    return {key(i): (key(p) if p is not None else None) for i, p in parent.items()}, [key(i) for i in queue]


def curve_points(values, parameter, own):
    """{point id: extra options}: on each line of the grid along `parameter`, the grid point nearest the model's
    own value (`own`) runs the curves in (H, parameter), bounded to the grid's range of it."""
    names = list(values)
    axis = names.index(parameter)
    v = values[parameter]
    at = min(range(len(v)), key=lambda i: abs(v[i] - (own if own is not None else v[0])))
    extra = {"curves": parameter, "bound": {parameter: (min(v), max(v))}}
    return {pid: extra for pid, _ in grid_points(values) if int(pid.split("_")[axis]) == at}


def _definition(model, grid, options, strategy):
    return {"format": SWEEP_FORMAT, "model": model, "grid": grid,
            "options": {k: v for k, v in sorted(options.items())}, "strategy": strategy}


def read_definition(out):
    """<out>/sweep.json, checked (a ValueError names the file)."""
    path = os.path.join(out, "sweep.json")
    definition = _read_json(path, "a sweep's definition")
    grid = definition.get("grid") if isinstance(definition, dict) else None
    if not isinstance(grid, dict) or not grid or not all(
            isinstance(v, list) and v and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
            for v in grid.values()):
        raise ValueError("'%s': not a sweep's definition (its grid: {parameter: [values]} expected)" % path)
    if not isinstance(definition.get("model"), str):
        raise ValueError("'%s': not a sweep's definition (its model's name expected)" % path)
    return definition
