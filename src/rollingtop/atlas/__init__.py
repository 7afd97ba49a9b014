"""A parameter atlas of the classification, computed on Dask (issue 14, section 4).

Body parameters (``R, m, g, a3, I1, I3`` of a dynamically symmetric body) times integrals
(``M3, C1, C2``) on a grid; every cell classified as :mod:`rollingtop.reduction.bifurcation`
classifies a level: the number of steady motions (critical points of ``U`` in ``(-1, 1)``) and
of centres and saddles among them, the folds of the ``(M3, C1)`` diagram, and the rotation number
at each centre (:func:`rollingtop.reduction.rotation.centre_rotation_number`).

The grid is cut into chunks of cells, each a Dask task (``dask.distributed``): by default on an
embedded local cluster of worker processes (no setup), or on an existing cluster given by its
scheduler's address or a :class:`distributed.Client`. Every finished chunk is saved at once in a
folder beside the output (``OUTPUT.partial/``, one ``.npz`` per chunk, each written atomically,
with the spec's digest): a run that stops (a signal, a lost worker, a crash) resumes where it
stopped and computes only the chunks not saved. The output (NetCDF ``.nc`` or a Zarr store
``.zarr``) appears only when complete, atomically; then the partial folder is removed.

The spec is a scenario file (``[body]``, ``[contact]``, ``[level]`` give the fixed values) plus
an ``[axes]`` table whose keys are body or level keys, each a list of values or
``{start, stop, num}``; the Dataset's dimensions follow the order of ``[axes]``.

A spec whose contact model has no reduction (``oblique`` over its constraint ``angle``,
``parallel``) is a *chaos atlas* (issue 39): each cell's chaos indicators, phase-volume rate and
periodic orbits on the level of the spec's initial state (:mod:`._chaos`).

The package's modules, each imported only by those after it: :mod:`._cells` (the classification
of a chunk of cells, one Dask task), :mod:`._spec` (the spec and its validation), :mod:`._store`
(the partial folder and the output), :mod:`._run` (the run on Dask); :mod:`._display` registers
``ds.rollingtop`` on xarray's Datasets (an atlas's summary in a notebook and its ``plot()``).
"""

from rollingtop.atlas._cells import BODY_KEYS, FIELDS, LEVEL_KEYS, MAX_CENTRES, classify_cells
from rollingtop.atlas._display import AtlasAccessor
from rollingtop.atlas._run import atlas, classify_in_process
from rollingtop.atlas._spec import (
    ATLAS_VERSION,
    AXIS_KEYS,
    DEFAULT_CHUNK,
    MAX_CELLS,
    MAX_SCHEDULER_TIMEOUT,
    MAX_SPEC_BYTES,
    MAX_WORKERS_PER_CORE,
    STATUS,
    AtlasError,
    AtlasSpec,
    atlas_spec_from_dict,
    load_atlas_spec,
)
from rollingtop.atlas._store import AtlasResumeWarning, check_atlas_output

__all__ = [
    "ATLAS_VERSION",
    "AXIS_KEYS",
    "BODY_KEYS",
    "DEFAULT_CHUNK",
    "FIELDS",
    "LEVEL_KEYS",
    "MAX_CELLS",
    "MAX_SCHEDULER_TIMEOUT",
    "MAX_CENTRES",
    "MAX_SPEC_BYTES",
    "MAX_WORKERS_PER_CORE",
    "STATUS",
    "AtlasAccessor",
    "AtlasError",
    "AtlasResumeWarning",
    "AtlasSpec",
    "atlas",
    "atlas_spec_from_dict",
    "check_atlas_output",
    "classify_cells",
    "classify_in_process",
    "load_atlas_spec",
]
