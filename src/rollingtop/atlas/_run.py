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
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import tomllib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._checks import short_repr
from rollingtop._errors import RollingTopError, ScenarioError
from rollingtop._types import FloatArray
from rollingtop.atlas._cells import BODY_KEYS, LEVEL_KEYS, classify_cells
from rollingtop.atlas._store import (
    _dataset,
    _load_partial,
    _partial_folder,
    _save_chunk,
    _write,
    check_atlas_output,
)
from rollingtop.io import read_input_text, write_bytes_atomic

if TYPE_CHECKING:
    import xarray as xr
    from distributed import Client

__all__ = [
    "AtlasError",
    "AtlasSpec",
    "atlas",
    "check_atlas_output",
    "classify_cells",
    "load_atlas_spec",
]

AXIS_KEYS = BODY_KEYS + LEVEL_KEYS
#: Largest number of cells of one atlas.
MAX_CELLS = 10_000_000
#: Cells per Dask task (a chunk, and a file of the partial folder).
DEFAULT_CHUNK = 200
#: Bumped when the classification changes: partial results of another version are not reused.
ATLAS_VERSION = 1
#: Status of a cell.
STATUS = {
    0: "classified",
    1: "inadmissible body",
    2: "pole level (C1 = +-M3)",
    3: "level too large",
}
#: Most worker processes per core of the embedded local cluster.
MAX_WORKERS_PER_CORE = 4
MAX_SPEC_BYTES = 1_000_000


class AtlasError(RollingTopError):
    """A bad atlas spec, output, or cluster."""


@dataclass(frozen=True)
class AtlasSpec:
    """A validated atlas spec.

    Attributes
    ----------
    fixed : dict of str to float
        Every key of :data:`AXIS_KEYS` with its fixed value (the first axis value for keys on
        an axis).
    axes : dict of str to ndarray
        The axes, in order (the Dataset's dimensions).
    """

    fixed: dict[str, float]
    axes: dict[str, FloatArray]

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    def digest(self, chunk: int) -> str:
        """What a partial result must match to be reused."""
        axes = {k: v.tolist() for k, v in self.axes.items()}
        text = json.dumps({"version": ATLAS_VERSION, "fixed": self.fixed, "chunk": chunk,
                           "axes": axes}, sort_keys=True)  # fmt: skip
        return hashlib.sha256(text.encode()).hexdigest()

    def cells(self) -> FloatArray:
        """Every cell's axis values, shape (size, n_axes), in C order of the axes."""
        grids = np.meshgrid(*self.axes.values(), indexing="ij")
        return np.stack([g.ravel() for g in grids], axis=1)


def _axis(key: str, value: object) -> FloatArray:
    try:
        return _axis_values(key, value)
    except ScenarioError as exc:  # a value that is not a finite number (rollingtop._checks)
        raise AtlasError(str(exc)) from None


def _axis_values(key: str, value: object) -> FloatArray:
    from rollingtop._checks import number

    where = f"axes.{key}"
    if isinstance(value, list):
        if not value:
            raise AtlasError(f"{where} is empty")
        out = np.array([number("axes", key, v) for v in value], dtype=float)
    elif isinstance(value, dict):
        unknown = set(value) - {"start", "stop", "num"}
        if unknown or {"start", "stop", "num"} - set(value):
            raise AtlasError(f"{where} must be a list or {{start, stop, num}}, got "
                             f"{short_repr(value)}")  # fmt: skip
        num = int(number("axes", f"{key}.num", value["num"], integer=True))
        if num < 1:
            raise AtlasError(f"{where}.num = {num} must be >= 1")
        if num > MAX_CELLS:
            raise AtlasError(f"{where}.num = {num} is more than {MAX_CELLS} values")
        start = number("axes", f"{key}.start", value["start"])
        stop = number("axes", f"{key}.stop", value["stop"])
        out = np.linspace(start, stop, num)
    else:
        raise AtlasError(f"{where} must be a list of numbers or {{start, stop, num}}, got "
                         f"{short_repr(value)}")  # fmt: skip
    if not np.all(np.isfinite(out)):
        raise AtlasError(f"{where} has non-finite values")
    return out


def atlas_spec_from_dict(data: Mapping[str, Any]) -> AtlasSpec:
    """Validate a parsed spec (module docstring)."""
    from rollingtop.scenario import Scenario

    data = dict(data)
    axes_t = data.pop("axes", None)
    if not isinstance(axes_t, dict) or not axes_t:
        raise AtlasError("missing or empty table [axes] (keys: " + ", ".join(AXIS_KEYS) + ")")
    for key in axes_t:
        if key not in AXIS_KEYS:
            raise AtlasError(f"unknown axis {short_repr(key)} (allowed: {', '.join(AXIS_KEYS)})")
    axes = {key: _axis(key, value) for key, value in axes_t.items()}
    size = int(np.prod([len(v) for v in axes.values()], dtype=float))
    if size > MAX_CELLS:
        raise AtlasError(f"the atlas has {size} cells, more than {MAX_CELLS}")
    # the fixed values: the scenario's, with each axis at its first value
    level_t = dict(data.get("level", {})) if isinstance(data.get("level", {}), dict) else {}
    for key in LEVEL_KEYS:
        if key in axes:
            level_t[key] = float(axes[key][0])
    missing = [k for k in LEVEL_KEYS if k not in level_t]
    if missing:
        raise AtlasError(f"[level] or [axes] must give {', '.join(missing)}")
    level_t = {k: v for k, v in level_t.items() if k in LEVEL_KEYS}
    body_t = dict(data.get("body", {})) if isinstance(data.get("body", {}), dict) else {}
    for key in BODY_KEYS:
        if key in axes:
            body_t[key] = float(axes[key][0])
    data["body"], data["level"] = body_t, level_t
    data.pop("initial", None)
    sc = Scenario.from_dict(data)
    if not sc.model.has_reduction:
        raise AtlasError(f"the atlas classifies the reduction of the meridian model, not model "
                         f"{sc.model.name!r}")  # fmt: skip
    if not sc.body.symmetric:
        raise AtlasError(f"the atlas needs a dynamically symmetric body (I1 = I2), got "
                         f"I1 = {sc.body.I1:g}, I2 = {sc.body.I2:g}")  # fmt: skip
    fixed = {k: float(getattr(sc.body, k)) for k in BODY_KEYS}
    fixed.update({k: float(level_t[k]) for k in LEVEL_KEYS})
    return AtlasSpec(fixed, axes)


def load_atlas_spec(path: str | os.PathLike[str]) -> AtlasSpec:
    """Read and validate an atlas spec (a TOML scenario file with an ``[axes]`` table)."""
    path = Path(path)
    text = read_input_text(path, "atlas spec", MAX_SPEC_BYTES, ScenarioError)
    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError, ValueError) as exc:
        raise AtlasError(f"{path}: invalid TOML: {exc}") from None
    try:
        return atlas_spec_from_dict(data)
    except RollingTopError as exc:
        raise AtlasError(f"{path}: {exc}") from None


@contextlib.contextmanager
def _client(client: Client | None, workers: int | None, scheduler: str | None) -> Iterator[Client]:
    """The given client; else one connected to ``scheduler``; else an embedded local cluster of
    ``workers`` processes (default: the cores), closed at the end."""
    if client is not None:
        yield client
        return
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            remote = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise AtlasError(f"cannot reach the Dask scheduler at {short_repr(scheduler)}: "
                             f"{why}") from None  # fmt: skip
        try:
            yield remote
        finally:
            remote.close()
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=50)  # fmt: skip
    try:
        local = Client(cluster)
        try:
            yield local
        finally:
            local.close()
    finally:
        cluster.close()


def atlas(
    spec: AtlasSpec,
    output: str | os.PathLike[str] | None = None,
    *,
    client: Client | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    chunk: int = DEFAULT_CHUNK,
    progress: Callable[[int, int], None] | None = None,
) -> xr.Dataset:
    """Classify every cell of ``spec`` on Dask; write ``output`` (``.nc`` or ``.zarr``) if given.

    Parameters
    ----------
    spec : AtlasSpec
    output : path, optional
        Where to write the Dataset. With an output the run is resumable: finished chunks are
        kept in ``OUTPUT.partial/`` until the output is written.
    client : distributed.Client, optional
        Run on this client's cluster (not closed here).
    workers : int, optional
        Worker processes of the embedded local cluster (default: the cores); ignored with
        ``client`` or ``scheduler``.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``).
    chunk : int
        Cells per task.
    progress : callable, optional
        ``progress(done_cells, total_cells)``.

    Returns
    -------
    xarray.Dataset
        One dimension per axis (in the spec's order), coordinates the axis values; the
        variables of :func:`classify_cells`.
    """
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        raise AtlasError(f"chunk = {short_repr(chunk)} must be an integer >= 1")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):  # fmt: skip
        raise AtlasError(f"workers = {short_repr(workers)} must be an integer >= 1")
    cores = os.cpu_count() or 1
    if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
        raise AtlasError(f"workers = {workers} is more than {MAX_WORKERS_PER_CORE} per core "
                         f"({cores} cores) for the local cluster; use a scheduler to go "
                         "wide")  # fmt: skip
    out_path = None if output is None else check_atlas_output(output)
    cells = spec.cells()
    names = tuple(spec.axes)
    starts = list(range(0, spec.size, chunk))
    digest = spec.digest(chunk)
    folder = None if out_path is None else _partial_folder(out_path)
    done = {} if folder is None else _load_partial(folder, digest)
    created = False
    if folder is not None and not folder.exists():
        folder.mkdir()
        created = True
        write_bytes_atomic(folder / "spec.json", json.dumps({"digest": digest}).encode())
    try:
        _compute(spec, cells, names, starts, chunk, done, folder, client, workers, scheduler,
                 progress)  # fmt: skip
    except BaseException:
        if created and folder is not None and not any(folder.glob("chunk-*.npz")):
            shutil.rmtree(folder, ignore_errors=True)  # nothing saved: leave no trace
        raise
    ds = _dataset(spec, done)
    if out_path is not None and folder is not None:
        _write(ds, out_path)
        shutil.rmtree(folder, ignore_errors=True)
    return ds


def _compute(
    spec: AtlasSpec,
    cells: FloatArray,
    names: tuple[str, ...],
    starts: list[int],
    chunk: int,
    done: dict[int, dict[str, np.ndarray]],
    folder: Path | None,
    client: Client | None,
    workers: int | None,
    scheduler: str | None,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Submit the chunks not in ``done`` and collect them into it (saving each at once)."""
    finished = sum(min(chunk, spec.size - starts[k]) for k in done)
    if progress is not None:
        progress(finished, spec.size)
    todo = [k for k in range(len(starts)) if k not in done]
    if todo:
        with _client(client, workers, scheduler) as c:
            futures = {c.submit(classify_cells, spec.fixed, names,
                                cells[starts[k] : starts[k] + chunk], pure=False): k
                       for k in todo}  # fmt: skip
            try:
                _collect(futures, done, folder, spec.size, finished, progress)
            except BaseException:
                c.cancel(list(futures))  # stop what is still queued before the cluster goes
                raise


def _collect(
    futures: dict[Any, int],
    done: dict[int, dict[str, np.ndarray]],
    folder: Path | None,
    total: int,
    finished: int,
    progress: Callable[[int, int], None] | None,
) -> None:
    """Collect the chunks as they finish, saving each at once. A task that failed on a worker
    (a lost worker, an error) is reported as one :class:`AtlasError`."""
    from distributed import as_completed

    for fut in as_completed(futures):
        k = futures[fut]
        try:
            result = fut.result()
        except RollingTopError:
            raise
        except Exception as exc:
            raise AtlasError(f"a Dask task failed ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''}); the chunks "
                             "finished so far are kept: run again to resume") from None  # fmt: skip
        done[k] = result
        if folder is not None:
            _save_chunk(folder, k, result)
        finished += len(result["status"])
        if progress is not None:
            progress(finished, total)


def classify_in_process(spec: AtlasSpec) -> xr.Dataset:
    """The same Dataset computed in this process, without Dask (small atlases, tests)."""
    return _dataset(spec, {0: classify_cells(spec.fixed, tuple(spec.axes), spec.cells())})
