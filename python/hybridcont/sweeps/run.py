"""The sweep itself: the grid's tasks on Dask (a local cluster or a scheduler's), in the order the strategy
needs, resumable, with progress; then the table, the maps and the report."""
import contextlib
import json
import os
import shutil
import sys
import time

from .grid import (MAX_GRID_POINTS, _definition, curve_points, grid_points, grid_values, neighbour_tree,
                   read_definition)
from .maps import plot_maps
from .report import write_report
from .table import assemble, read_rows
from .task import _starts_of_folder, guess_starts, model_document, passed_on, run_grid_point


@contextlib.contextmanager
def _main_script_hidden():
    """While the local cluster starts its worker processes: the main module without its file and spec, so that
    multiprocessing does not run the user's script again in each worker (spawn does, to find functions defined
    there; the tasks of a sweep are this module's). A script that sweeps at its top level, or one read from
    standard input, would otherwise start a cluster in every worker, or fail to start any."""
    main = sys.modules.get("__main__")
    saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if main is not None and k in main.__dict__}
    try:
        if main is not None:
            main.__dict__.pop("__file__", None)
            main.__dict__["__spec__"] = None
        yield
    finally:
        if main is not None:
            main.__dict__.pop("__spec__", None)
            main.__dict__.update(saved)


def _importing_main_script():
    """True while a process started by multiprocessing runs the parent's main script as ``__mp_main__``."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals.get("__name__") == "__mp_main__":
            return True
        frame = frame.f_back
    return False


def sweep(model, grid, out, scheduler=None, workers=None, resume=False, overwrite=False, progress=True,
          maps=True, strategy="explore", curves=None, families=None, max_grid_points=MAX_GRID_POINTS, **options):
    """Runs a study at every point of ``grid`` and returns the tidy table (also ``<out>/table.csv``).

    model: a name, a model file's path, or a Model (sent to the workers as its model text).
    grid: {parameter: (start, stop, count)} or {parameter: [values]}.
    scheduler: a Dask scheduler's address (tcp://HOST:PORT); None starts a local cluster of ``workers``
    single-threaded worker processes (default: one per core).
    resume: compute only the grid points whose folder is not complete (the same sweep, same options).
    maps: draw ``map-<family>.png`` (plot_maps) when the sweep is complete.
    strategy: "explore" (every grid point explored whole from the model's starts) or "continue" (each grid point
    continues its neighbour's families, explored whole where one is not found; the module's docstring says
    what it cannot see).
    curves: a grid parameter p: on every line of the grid along p, one grid point (the one nearest the model's
    own p) continues its families' special points in (H, p) over the grid's range of p (``run``'s curves), and
    the report draws them over the families' ranges along the line (``curve_lines``).
    families: the families to map (names, e.g. ["hopping in place"]): the table has their rows only, and with
    "continue" each grid point traces only the half-branches that led to them (the first is explored whole).
    max_grid_points: the most grid points the sweep computes (default 10,000; None: no limit): a larger grid is
    refused before anything runs.
    options: those of ``hybridcont.run`` (set, until, bound, rtol, ...), for every grid point."""
    if scheduler is None and _importing_main_script():
        # A local cluster's worker process starts by importing the main script: a sweep at the script's top
        # level would start a cluster in every worker, which then never starts.
        raise RuntimeError("hybridcont.sweep: called while a worker process imports the script that sweeps; "
                           "call it under `if __name__ == \"__main__\":` (as every local Dask cluster needs)")

    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError("workers %r: a whole number of processes, at least 1" % (workers,))
    values = grid_values(grid, max_grid_points)
    points = grid_points(values)
    m, model, model_text, options = _checked_model(model, values, options, curves)
    model_name = m.name if model is None else os.fspath(model)
    out = os.path.abspath(os.fspath(out))
    document = model_document(model) if model_text is None else __import__("tomllib").loads(model_text)
    if not guess_starts(document):
        document = None  # nothing to carry from a neighbour: every grid point explores from the model's starts
    families = [families] if isinstance(families, str) else list(families) if families else None
    strategy = _checked_choices(m, values, options, families, curves, strategy)
    guided = strategy == "continue"
    definition = _definition(model_name, values, options, strategy + (" (starts from the neighbours' orbits)"
                                                                       if document is not None else ""))
    if curves is not None:
        definition["curves"] = curves
    if families:
        definition["families"] = families
    _prepare_folder(out, definition, strategy, points, document, resume, overwrite)

    done = {pid for pid, _ in points if os.path.exists(os.path.join(out, "points", pid, "rows.json"))}
    todo = [(pid, v) for pid, v in points if pid not in done]
    # Partial folders of an interrupted sweep stay until this one ends: a task of it may still run on an
    # external cluster and write into its own (each task's name is unique), never into this sweep's.
    say = _progress(progress, len(points), len(points) - len(todo))
    # The order of the tasks: a tree over the grid from the point nearest the model's own parameters, each point
    # after the neighbour it continues from; none (any order) where nothing passes between grid points.
    tree_order = neighbour_tree(values, {n: m.parameters.get(n) for n in values}) \
        if guided or document is not None else None
    extras = curve_points(values, curves, m.parameters.get(curves)) if curves is not None else {}
    if todo:
        task = dict(model=model, model_text=model_text, options=options, out=out, document=document, guided=guided,
                    extras=extras, families=families)
        _run_tasks(task, points, todo, done, tree_order, definition, scheduler, workers, say)
    for stale in os.listdir(os.path.join(out, "points")):  # copies of tasks whose worker died
        if stale.startswith(".partial-"):
            shutil.rmtree(os.path.join(out, "points", stale), ignore_errors=True)
    say(done=True)
    table = assemble(out, points)
    write_report(out)
    if maps:
        try:
            plot_maps(out)
        except ImportError as e:  # matplotlib is the figures' (python3-matplotlib), not the sweep's
            import warnings
            warnings.warn("maps not drawn: %s" % e, RuntimeWarning, stacklevel=2)
    return table


def _checked_model(model, values, options, curves):
    """(Model, what the workers get: a name or absolute path, or None with the model's text, the text, the
    options): bad options end the sweep before anything runs (checked at the model's own parameters, the grid's
    names against its parameters, each grid value within its parameter's range); what fails later at one grid
    point is that point's, in its rows."""
    from ..models import Model
    from ..models import model as make_model
    m = model if isinstance(model, Model) else make_model(os.fspath(model))
    unknown = [n for n in values if n not in m.parameters]
    if unknown:
        raise ValueError("grid %s: model '%s' has no parameter '%s' (parameters: %s)"
                         % (unknown[0], m.name, unknown[0], ", ".join(m.parameters)))
    probe = m.with_parameters()
    for name, vals in values.items():
        for v in vals:
            try:
                probe.set_parameter(name, v)
            except ValueError as e:
                raise ValueError("grid %s: the value %.12g: %s" % (name, v, e))
    model_text = None
    if isinstance(model, Model):
        # Workers get the model as data (its text, or its name or path): a Model object holds the library's
        # model, which does not travel between processes. Its parameters travel as `set`.
        options = dict(options, set=dict(m.parameters, **(options.get("set") or {})))
        model_text = model.text
        model = None if model_text is not None else model.source
    if isinstance(model, os.PathLike):
        model = os.fspath(model)
    if isinstance(model, str) and model.endswith(".toml") and os.path.exists(model):
        model = os.path.abspath(model)  # the workers may run elsewhere (a str or a pathlib.Path alike)
    if model_text is None:
        from ..study import check
        check(model, **dict(options, curves=curves) if curves is not None else options)
    return m, model, model_text, options


def _checked_choices(m, values, options, families, curves, strategy):
    """The strategy the sweep takes (``continue`` needs families in H); families, curves and strategy checked."""
    for name in families or []:
        # A family is named by the model's rules, by its word (an automaton's family of another word), or as a
        # period-doubled family of the rules' names.
        if name not in m.families and " > " not in name and not name.startswith("period-doubled "):
            raise ValueError("family '%s': not a family of model '%s' (families: %s; an automaton's family of "
                             "another word is named by its word, 'stance > flight > ...')"
                             % (name, m.name, ", ".join(m.families) or "none named"))
    if curves is not None and curves not in values:
        raise ValueError("curves '%s': not a parameter of the grid (%s)" % (curves, ", ".join(values)))
    if strategy not in ("continue", "explore"):
        raise ValueError("sweep: strategy '%s': expected 'continue' or 'explore'" % strategy)
    if strategy == "continue" and (options.get("free") or options.get("formulation", "time") != "time"):
        # A guide continues families in H, in the time-based formulation (StudyOptions::families_of).
        import warnings
        warnings.warn("sweep: strategy 'continue' needs families in H in the time-based formulation: every grid "
                      "point is explored whole", RuntimeWarning, stacklevel=3)
        return "explore"
    return strategy


def _remove_sweep(out):
    """Removes what a sweep writes into its folder (sweep.json, points/, table.csv, the report and the maps), and
    nothing else: a folder that also holds the user's own files keeps them."""
    import glob
    shutil.rmtree(os.path.join(out, "points"), ignore_errors=True)
    written = ["sweep.json", "sweep.json.tmp", "table.csv", "table.csv.tmp", "sweep-report.html"]
    for name in written + [os.path.basename(p) for pattern in ("map-*.png", "map-*.svg", "map-*.pdf", "plane-*.png",
                                                                 "plane-*.svg", "plane-*.pdf")
                           for p in glob.glob(os.path.join(glob.escape(out), pattern))]:
        path = os.path.join(out, name)
        if os.path.isfile(path) or os.path.islink(path):
            os.remove(path)


def _prepare_folder(out, definition, strategy, points, document, resume, overwrite):
    """The sweep's folder with its definition (sweep.json): a new one, the same sweep resumed (its finished grid
    points' files checked before anything runs), or one replaced with overwrite; refused otherwise."""
    definition_file = os.path.join(out, "sweep.json")
    if os.path.exists(definition_file) and overwrite and not resume:
        _remove_sweep(out)  # what the sweep wrote; the user's own files there are kept
    elif os.path.exists(definition_file):
        saved = read_definition(out)
        same = {k: v for k, v in saved.items() if k != "strategy"} == \
            {k: v for k, v in json.loads(json.dumps(definition)).items() if k != "strategy"}
        # 0.5.0 wrote "explore" or "neighbour" (every point whole, from its neighbour's orbits): both "explore".
        saved_strategy = str(saved.get("strategy", "explore")).split(" ")[0].replace("neighbour", "explore")
        if resume and same and saved_strategy != strategy:
            raise ValueError("resume '%s': the sweep there has strategy '%s'; resume it with strategy='%s' "
                             "(--strategy %s)" % (out, saved_strategy, saved_strategy, saved_strategy))
        if resume and not same:
            raise ValueError("resume '%s': the sweep there has another definition (model, grid or options); "
                             "resume it with its own" % out)
        if not resume:
            raise ValueError("sweep '%s': a sweep is there (resume=True continues it, overwrite=True replaces it)"
                             % out)
    elif resume:
        raise ValueError("resume '%s': no sweep there to resume" % out)
    if resume:  # the finished points' files are read back: checked before anything runs
        for pid, _ in points:
            folder = os.path.join(out, "points", pid)
            if os.path.exists(os.path.join(folder, "rows.json")):
                read_rows(folder)
                if document is not None:
                    _starts_of_folder(folder, document, None)
    os.makedirs(os.path.join(out, "points"), exist_ok=True)
    with open(definition_file + ".tmp", "w") as f:
        json.dump(definition, f, indent=1)
    os.replace(definition_file + ".tmp", definition_file)


def _run_tasks(task, points, todo, done, tree_order, definition, scheduler, workers, say):
    """The grid points still to compute, one Dask task each, on a local cluster or the scheduler's; in the tree's
    order where a grid point continues its neighbour's (its task gets the neighbour's result as a future)."""
    from dask.base import tokenize
    from dask.distributed import Client, LocalCluster, as_completed
    cluster = None
    if scheduler is None:
        with _main_script_hidden():
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                                   processes=True, dashboard_address=":0")
    client = Client(scheduler or cluster)
    out, document, extras = task["out"], task["document"], task["extras"]

    def submit(pid, values, document, parent, guided):
        return client.submit(run_grid_point, task["model"], task["model_text"], pid, values, task["options"], out,
                             document, parent, guided, extras.get(pid), task["families"], key=prefix + pid,
                             pure=False)
    try:
        # Task names of this sweep's own (a shared scheduler runs other sweeps: the same name would be taken for
        # the same task).
        prefix = "point-%s-" % tokenize(out, json.dumps(definition, sort_keys=True))[:12]
        futures = []
        if not tree_order:
            futures = [submit(pid, v, None, None, False) for pid, v in todo]
        else:
            # Breadth-first from the point nearest the model's own parameters: each task gets its neighbour's
            # result (a future: Dask runs it after that one); finished points pass theirs from their folder.
            tree, order = tree_order
            by_id = dict(points)
            results = {}
            for pid in order:
                parent = results.get(tree[pid]) if tree[pid] is not None else None
                if pid in done:
                    results[pid] = passed_on(os.path.join(out, "points", pid), document, None)
                    continue
                results[pid] = submit(pid, by_id[pid], document, parent, task["guided"])
                futures.append(results[pid])
        for future in as_completed(futures):
            future.result()
            say()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _progress(progress, total, done):
    """A function to call after each grid point: done/total, rate, time left (tqdm where installed)."""
    start = time.perf_counter()
    state = {"done": done, "new": 0}
    if progress is False or progress is None:
        return lambda done=False: None
    try:
        from tqdm.auto import tqdm
        bar = tqdm(total=total, initial=done, unit=" points", desc="sweep")
    except ImportError:
        bar = None

    def say(done=False):
        if done:
            if bar is not None:
                bar.close()
            return
        state["done"] += 1
        state["new"] += 1
        if bar is not None:
            bar.update(1)
            return
        elapsed = time.perf_counter() - start
        rate = state["new"] / elapsed if elapsed > 0 else 0.0
        left = (total - state["done"]) / rate if rate > 0 else float("nan")
        print("sweep: %d/%d grid points, %.2f points/s, %.0f s left" % (state["done"], total, rate, left),
              file=sys.stderr)
    return say
