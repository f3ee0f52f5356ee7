"""hybridcont: families of periodic orbits of hybrid dynamical systems, from Python.

    import hybridcont as hc
    study = hc.run("slip")                    # the SLIP's complete diagram (as `hybridcont run slip`)
    print(study)                              # its answer: families, where physical and stable, special points
    study.points, study.special_points        # pandas DataFrames
    study                                     # in Jupyter: the interactive report

Models: ``hc.model(name or path or text=...)`` and models written with SymPy, ``hc.ModelBuilder``.
Studies: ``hc.run``, ``hc.load``, ``Study.continue_from``, ``Study.save``, ``Study.plot``.
Maps over parameter grids on Dask: ``hc.sweep`` (``python -m hybridcont.sweeps``, ``hybridcont sweep``).
Maps: ``Model.evaluate`` (r, dr), ``Model.floquet`` (monodromy, multipliers), ``hc.continuation`` (a branch
point by point). Tutorial: docs/python.md.
"""
from . import _hybridcont
from .continuation import continuation
from .models import Model, ModelBuilder, builtin_models, model, shipped_models
from .study import Study, load, run


def sweep(model, grid, out, **kwargs):
    """A study at every point of a parameter grid, on Dask (hybridcont.sweeps.sweep; its doc for the options).

    Imported when first called: `python -m hybridcont.sweeps` (what `hybridcont sweep` runs) then executes a
    module that the package has not imported before."""
    from .sweeps import sweep as run_sweep
    return run_sweep(model, grid, out, **kwargs)

__version__ = _hybridcont.__version__

__all__ = ["Model", "ModelBuilder", "Study", "builtin_models", "continuation", "load", "model", "run",
           "shipped_models", "sweep", "__version__"]
