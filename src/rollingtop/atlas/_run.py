"""The run of the parameter atlas (:mod:`rollingtop.atlas`) on Dask: the cluster, the chunks
submitted as tasks and collected as they finish (each saved at once, so that a run resumes), and
the same Dataset computed in process."""

from __future__ import annotations

import contextlib
import functools
import json
import logging
import os
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._checks import short_repr
from rollingtop._errors import RollingTopError
from rollingtop._types import FloatArray
from rollingtop.atlas._cells import classify_cells
from rollingtop.atlas._spec import (
    DEFAULT_CHUNK,
    MAX_SCHEDULER_TIMEOUT,
    MAX_WORKERS_PER_CORE,
    SCHEDULER_TIMEOUT,
    AtlasError,
    AtlasSpec,
)
from rollingtop.atlas._store import (
    CellsKept,
    _dataset,
    _load_partial,
    _partial_folder,
    _save_chunk,
    _write,
    check_atlas_output,
)
from rollingtop.io import write_bytes_atomic

if TYPE_CHECKING:
    import xarray as xr
    from distributed import Client

__all__ = ["atlas", "classify_in_process"]


def _probe(address: str, timeout: float) -> None:
    """Ask ``address`` who it is, within ``timeout`` seconds: :class:`AtlasError` unless a Dask
    scheduler answers. ``Client``'s own timeout covers the connection, not a listener that
    accepts and never answers (measured: still waiting after 150 s). The question runs on a
    loop of its own in a thread, so that a caller's running loop (a notebook) is no obstacle."""
    import asyncio
    import concurrent.futures

    from distributed.core import rpc

    async def identity() -> object:
        remote = rpc(address, timeout=timeout)
        try:
            return await asyncio.wait_for(remote.identity(), timeout)
        finally:
            await remote.close_rpc()

    where = f"the Dask scheduler at {short_repr(address)}"
    _connectable(address, timeout, where)
    pool = concurrent.futures.ThreadPoolExecutor(1)
    try:
        answer = pool.submit(asyncio.run, identity()).result(timeout + 5.0)
    except (TimeoutError, concurrent.futures.TimeoutError):
        raise AtlasError(
            f"{where} did not answer within {timeout:g} s (--scheduler-timeout)"
        ) from None
    except Exception as exc:  # refused, unresolvable, a garbled answer: distributed's own types
        why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise AtlasError(f"cannot reach {where}: {why}") from None
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
    if not (isinstance(answer, dict) and answer.get("type") == "Scheduler"):
        raise AtlasError(f"{short_repr(address)} answered, but not as a Dask scheduler")


def _connectable(address: str, timeout: float, where: str) -> None:
    """Fail at once where a TCP address refuses the connection (``rpc`` would retry until the
    timeout and then report no answer)."""
    import socket

    from distributed.comm.addressing import get_address_host_port, parse_address

    try:
        if parse_address(address)[0] not in ("tcp", "tls"):
            return
        host, port = get_address_host_port(address)
        socket.create_connection((host, port), timeout=timeout).close()
    except (OSError, ValueError, TypeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise AtlasError(f"cannot reach {where}: {why or type(exc).__name__}") from None


@contextlib.contextmanager
def _client(
    client: Client | None, workers: int | None, scheduler: str | None, timeout: float
) -> Iterator[Client]:
    """The given client; else one connected to ``scheduler`` (which must answer as a Dask
    scheduler within ``timeout`` seconds); else an embedded local cluster of ``workers``
    processes (default: the cores), closed at the end."""
    if client is not None:
        yield client
        return
    from distributed import Client, LocalCluster

    if scheduler is not None:
        _probe(scheduler, timeout)
        try:
            remote = Client(scheduler, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise AtlasError(
                f"cannot reach the Dask scheduler at {short_repr(scheduler)}: {why}"
            ) from None
        try:
            yield remote
        finally:
            remote.close()
        return
    import dask

    n = workers if workers is not None else (os.cpu_count() or 1)
    # the cluster's scratch space (``dask-scratch-space``) in a folder of its own, removed with
    # it: Dask would leave it in the temporary folder
    scratch = tempfile.TemporaryDirectory(prefix="rollingtop-dask-", ignore_cleanup_errors=True)
    with _quiet_logs(), scratch as tmp, dask.config.set({"temporary-directory": tmp}):
        # No dashboard; the scheduler's HTTP endpoints (health, metrics) still start, on port
        # 8787 unless told otherwise, and warn in three lines when it is taken: a free port.
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=50,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        )
        try:
            local = Client(cluster)
            try:
                from rollingtop.atlas._quiet import QuietWorker

                local.register_plugin(QuietWorker(), name="rollingtop-quiet-worker")
                yield local
            finally:
                local.close()
        except BaseException:
            _kill_workers(cluster)
            raise
        finally:
            cluster.close()


@contextlib.contextmanager
def _quiet_logs() -> Iterator[None]:
    """The stream handlers on Dask's loggers (``distributed``, ``tornado``, ``bokeh``: where
    Dask's configuration installs its own) pass only CRITICAL records while the embedded
    cluster lives, its close included; their levels are restored after it.

    ``LocalCluster(silence_logs=...)`` does the same, but ends it inside its own close, before
    its IO loop stops: a record logged in between reached the terminal (measured: after a
    Ctrl-C 6.5 s into ``atlas``, 4 runs of 22 printed the scheduler's "Batched Comm Closed" of
    a killed worker and its 10-line traceback before the one line). Written here: Dask's own
    helper for it (``distributed.utils.silence_logging_cmgr``) is not public API.
    """
    with contextlib.ExitStack() as stack:
        for name in ("distributed", "tornado", "bokeh"):
            for handler in logging.getLogger(name).handlers:
                if isinstance(handler, logging.StreamHandler) and handler.level < logging.CRITICAL:
                    stack.callback(handler.setLevel, handler.level)
                    handler.setLevel(logging.CRITICAL)
        yield


def _kill_workers(cluster: Any) -> None:
    """Kill the worker processes of a local cluster whose run stopped (a signal, an error),
    whether they are still starting or running a chunk. A worker running a compiled chunk
    holds its GIL and answers no one, and a starting one is importing: the cluster's close
    would wait for either (seconds). Its finished chunks are saved by this process. Each
    nanny is first told not to start a new worker when its worker dies (Dask's own signal for
    a cluster that shuts down, ``Nanny.close_gracefully``)."""
    for nanny in list(cluster.workers.values()):
        nanny.close_gracefully(reason="rollingtop: the run stopped")
        pid = nanny.pid
        if pid is not None:
            with contextlib.suppress(OSError):
                os.kill(pid, getattr(signal, "SIGKILL", signal.SIGTERM))


def atlas(
    spec: AtlasSpec,
    output: str | os.PathLike[str] | None = None,
    *,
    client: Client | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    chunk: int = DEFAULT_CHUNK,
    progress: Callable[[int, int], None] | None = None,
    scheduler_timeout: float = SCHEDULER_TIMEOUT,
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
    scheduler_timeout : float
        Seconds ``scheduler`` has to answer as a Dask scheduler (:class:`AtlasError` after).

    Returns
    -------
    xarray.Dataset
        One dimension per axis (in the spec's order), coordinates the axis values; the
        variables of :func:`classify_cells`.
    """
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        raise AtlasError(f"chunk = {short_repr(chunk)} must be an integer >= 1")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise AtlasError(f"workers = {short_repr(workers)} must be an integer >= 1")
    cores = os.cpu_count() or 1
    if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
        raise AtlasError(
            f"workers = {workers} is more than {MAX_WORKERS_PER_CORE} per core "
            f"({cores} cores) for the local cluster; use a scheduler to go "
            "wide"
        )
    if not (
        isinstance(scheduler_timeout, (int, float))
        and not isinstance(scheduler_timeout, bool)
        and 0.0 < scheduler_timeout <= MAX_SCHEDULER_TIMEOUT
    ):
        raise AtlasError(
            f"scheduler_timeout = {short_repr(scheduler_timeout)} must be a number "
            f"of seconds in (0, {MAX_SCHEDULER_TIMEOUT:g}]"
        )
    out_path = None if output is None else check_atlas_output(output)
    cells = spec.cells()
    names = tuple(spec.axes)
    starts = list(range(0, spec.size, chunk))
    digest = spec.digest(chunk)
    folder = None if out_path is None else _partial_folder(out_path)
    ranges = {k: (start, min(start + chunk, spec.size)) for k, start in enumerate(starts)}
    done = {} if folder is None else _load_partial(folder, digest, ranges, spec.kind)
    created = False
    if folder is not None and not folder.exists():
        folder.mkdir()
        created = True
        write_bytes_atomic(folder / "spec.json", json.dumps({"digest": digest}).encode(), now=True)
    try:
        connect = functools.partial(_client, client, workers, scheduler, float(scheduler_timeout))
        _compute(spec, cells, names, starts, chunk, done, folder, connect, progress)
    except BaseException:
        if created and folder is not None and not any(folder.glob("chunk-*.npz")):
            shutil.rmtree(folder, ignore_errors=True)  # nothing saved: leave no trace
        raise
    ds = _dataset(spec, done)
    if out_path is not None and folder is not None:
        try:
            _write(ds, out_path)
        except OSError as exc:  # the finished chunks stay: a rerun writes without computing
            why = exc.strerror or str(exc) or type(exc).__name__
            raise CellsKept(out_path, exc.errno, why, folder) from None
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
    connect: Callable[[], contextlib.AbstractContextManager[Client]],
    progress: Callable[[int, int], None] | None,
) -> None:
    """Submit the chunks not in ``done`` and collect them into it (saving each at once)."""
    finished = sum(min(chunk, spec.size - starts[k]) for k in done)
    if progress is not None:
        progress(finished, spec.size)
    todo = [k for k in range(len(starts)) if k not in done]
    if todo:
        with connect() as c:
            futures = {
                c.submit(
                    cells_function(spec.kind),
                    spec.fixed,
                    names,
                    cells[starts[k] : starts[k] + chunk],
                    pure=False,
                ): k
                for k in todo
            }
            try:
                save = (
                    None
                    if folder is None
                    else functools.partial(_save, folder, spec, starts, chunk)
                )
                _collect(futures, done, save, spec.size, finished, progress)
            except BaseException:
                c.cancel(list(futures))  # stop what is still queued before the cluster goes
                raise


def _save(
    folder: Path,
    spec: AtlasSpec,
    starts: list[int],
    chunk: int,
    k: int,
    result: dict[str, np.ndarray],
) -> None:
    """Save chunk ``k`` with its identity: its index, its cells and the spec's digest."""
    cells_k = (starts[k], min(starts[k] + chunk, spec.size))
    _save_chunk(folder, k, cells_k, spec.digest(chunk), result)


def _collect(
    futures: dict[Any, int],
    done: dict[int, dict[str, np.ndarray]],
    save: Callable[[int, dict[str, np.ndarray]], None] | None,
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
            raise AtlasError(
                f"a Dask task failed ({type(exc).__name__}: "
                f"{str(exc).splitlines()[0] if str(exc) else ''}); the chunks "
                "finished so far are kept: run again to resume"
            ) from None
        done[k] = result
        if save is not None:
            save(k, result)
        finished += len(result["status"])
        if progress is not None:
            progress(finished, total)


def cells_function(kind: str) -> Callable[..., dict[str, np.ndarray]]:
    """The task of a chunk of cells of an atlas of ``kind``: :func:`classify_cells` or
    :func:`~rollingtop.atlas._chaos.chaos_cells`."""
    if kind == "chaos":
        from rollingtop.atlas._chaos import chaos_cells

        return chaos_cells
    return classify_cells


def classify_in_process(spec: AtlasSpec) -> xr.Dataset:
    """The same Dataset computed in this process, without Dask (small atlases, tests)."""
    cells = cells_function(spec.kind)(spec.fixed, tuple(spec.axes), spec.cells())
    return _dataset(spec, {0: cells})
