"""Sweeps: a study at every point of a parameter grid, on Dask, that survives a killed worker and resumes.

    import hybridcont as hc
    table = hc.sweep("slip", grid={"k": (10, 160, 8), "w2": (2, 10, 8)}, out="results/slip-map")
    table.query("family == 'hopping in place' and stable")     # where hopping in place has a stable range

    hybridcont sweep slip --grid k=10:160:8 --grid w2=2:10:8 --out results/slip-map [--scheduler tcp://...]

Every grid point is one task: the study of the model with the grid's parameters set (every option of
``hybridcont run`` applies to each), run by a Dask worker on one thread, its results folder saved under
``<out>/points/<id>/`` and its families summarized as rows of the tidy table ``<out>/table.csv``: one row per
grid point and family (the grid's parameters by name, the family, whether it exists there, is physical
somewhere, is stable somewhere, its physical and stable ranges, its located special points).

Where it runs: a local cluster of one single-threaded worker process per core by default; ``scheduler=``
(``--scheduler tcp://HOST:PORT``) an existing Dask cluster of many machines (a SLURM or PBS user starts one
with dask-jobqueue and passes its address; the workers need the package and a shared ``out`` folder).

Nothing lost, nothing twice. A task writes its study into a folder of its own and renames it to
``points/<id>`` when complete (atomic on one file system); a second copy of a task (Dask re-runs the tasks of
a worker that died) finds the folder there and keeps it. The table is assembled from the folders, so each
grid point is in it exactly once. ``resume=True`` (``--resume``) skips the grid points whose folder is
complete and computes the rest; the sweep's definition (``<out>/sweep.json``) must be the same.

Strategies (the table's ``strategy`` column says which one each grid point took):
  ``explore``    (the default) every grid point explored whole from the model's starts.
  ``continue``   the grid is covered breadth-first from the point nearest the model's own parameters, each
                 point after a neighbour one step closer (Dask runs a task once its neighbour's is done), whose
                 families it continues: its study leaves out the half-branches whose counterparts at the
                 neighbour led to no family (``families_of``, src/study/stages/family_guide.h). The SLIP's exploration
                 is 23 half-branches, its families' 5. Where a family of the neighbour is not found, the grid
                 point is explored whole instead ("explore (a family of 3_4 not continued)"); so is the first
                 grid point, and a point whose neighbour's study did not complete (stopped at max_branches: it
                 never followed some branches) or lacks a family of `families` ("explore (3_4 did not
                 complete)").
                 What it cannot see: a branch that had no physical orbit at the neighbour and has some here (the
                 guide left it out). Over the SLIP's (k, w2) plane its table is the whole explorations' to the last
                 bit; over the bipedal model's (k, beta) plane, at 5 of 64 grid points walking's stable range began
                 later than the whole exploration says (a stable walking branch the guide had seen without
                 physical orbits). Not the default for that reason: a model's maps are checked against
                 ``explore`` on a coarse grid before ``continue`` is trusted on a fine one.
A model file whose starts are guesses (orbits given by their unknowns) has them replaced, in either strategy, by
the orbits its neighbour's study found nearest to them (same word, same level H), corrected there by Newton: a
continuation of the starts in the grid's parameters (the grid is then covered breadth-first in either
strategy). The bipedal model's walking guess, written for k = 25.5, fails at k = 17.9, beta = 0.30; from its
neighbours' orbits it walks there."""
from .grid import SWEEP_FORMAT, grid_points, grid_values, read_definition
from .maps import MAP_CLASSES, curve_lines, map_classes, plot_maps
from .report import write_report
from .run import sweep
from .table import assemble, family_rows, read_rows
from .task import run_grid_point
from .cli import main

__all__ = ["SWEEP_FORMAT", "MAP_CLASSES", "assemble", "curve_lines", "family_rows", "grid_points", "grid_values",
           "main", "map_classes", "plot_maps", "read_definition", "read_rows", "run_grid_point", "sweep",
           "write_report"]
