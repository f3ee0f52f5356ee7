"""The grid of a sweep and its folder's definition: values per parameter, grid point ids, the breadth-first
tree of neighbours, the grid points that continue curves, and sweep.json."""
import itertools
import json
import os

import numpy as np


SWEEP_FORMAT = 1


# Grid points a sweep computes at most unless told otherwise (each is a whole study): a larger grid is most often
# a mistyped count, and its table, folders and tasks would fill the machine before anything was said.
MAX_GRID_POINTS = 10000


def grid_values(spec, max_grid_points=MAX_GRID_POINTS):
    """{name: (start, stop, count)} or {name: [values]} as {name: [values]} (linspace for a triple). Values must be
    finite, counts whole and positive, and the grid at most ``max_grid_points`` points (None: no limit)."""
    sizes = {}
    for name, values in spec.items():
        if not isinstance(name, str) or not name:
            raise ValueError("grid %r: a parameter's name is a non-empty string" % (name,))
        if isinstance(values, tuple) and len(values) == 3:
            count = values[2]
            if isinstance(count, bool) or int(count) != count or count < 1:
                raise ValueError("grid %s: the count must be a positive whole number, got %r" % (name, count))
            sizes[name] = int(count)
        else:
            sizes[name] = len(values)
    total = int(np.prod([float(n) for n in sizes.values()])) if sizes else 0
    if max_grid_points is not None and total > max_grid_points:
        raise ValueError("grid: %s grid points (%s), each a whole study: more than %d; a mistyped count? "
                         "(max_grid_points=N, --max-grid-points N, lifts the limit)"
                         % (format(total, ","), ", ".join("%s: %d" % kv for kv in sizes.items()), max_grid_points))
    out = {}
    for name, values in spec.items():
        if isinstance(values, tuple) and len(values) == 3:
            start, stop, count = values
            out[name] = [float(v) for v in np.linspace(float(start), float(stop), int(count))]
        else:
            out[name] = [float(v) for v in values]
            if not out[name]:
                raise ValueError("grid %s: no values" % name)
        if not all(np.isfinite(out[name])):
            raise ValueError("grid %s: the values must be finite, got %r" % (name, values))
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
