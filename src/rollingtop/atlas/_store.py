"""Storage of the parameter atlas (:mod:`rollingtop.atlas`): the partial folder of finished
chunks that lets an interrupted run resume, the Dataset of the finished atlas, and its atomic
write (NetCDF, or a Zarr store renamed into place)."""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._errors import RollingTopError, short_path
from rollingtop.atlas._cells import ATLAS_MODELS, FIELDS, MAX_CENTRES
from rollingtop.atlas._spec import AtlasError, AtlasSpec
from rollingtop.io import WriteFailed, check_output_path, netcdf_bytes, write_bytes_atomic

if TYPE_CHECKING:
    import xarray as xr


#: Largest chunk along each dimension of a Zarr store.
ZARR_CHUNK = 64
SUFFIXES = (".nc", ".zarr")
#: The variables of a chunk with one row of :data:`MAX_CENTRES` per cell.
CENTRE_FIELDS = ("rotation_centre", "centre_gamma3")


def _partial_folder(output: Path) -> Path:
    return output.with_name(output.name + ".partial")


class CellsKept(WriteFailed):
    """The finished atlas could not be written (exit status 1); its cells stay in the partial
    folder ``kept``, so that a rerun writes them without computing them again."""

    def __init__(self, path: Path, errno: int | None, reason: str, kept: Path) -> None:
        super().__init__(path, errno, reason)
        self.kept = str(kept)

    def __str__(self) -> str:
        return (
            f"cannot write {short_path(self.filename)}: {self.strerror}; the finished cells "
            f"are kept in {short_path(self.kept)}: run again to write them"
        )


class AtlasResumeWarning(UserWarning):
    """Damaged or foreign chunk files in an atlas's ``.partial`` folder, recomputed."""


def _chunk_fits(part: Mapping[str, np.ndarray], n: int, kind: str = "reduction") -> bool:
    """Whether a loaded chunk has the variables, shapes and kinds of :func:`classify_cells`'
    output (``kind`` ``chaos``: :func:`~rollingtop.atlas._chaos.chaos_cells`') for ``n`` cells
    (a foreign or truncated file does not)."""
    if kind == "chaos":
        from rollingtop.atlas._chaos import CHAOS_FIELDS

        return set(part) == set(CHAOS_FIELDS) and all(
            part[k].shape == (n,) and part[k].dtype.kind == c for k, c in CHAOS_FIELDS.items()
        )
    if set(part) != {*FIELDS, *CENTRE_FIELDS}:
        return False
    flat = all(part[k].shape == (n,) and part[k].dtype.kind == "i" for k in FIELDS)
    return flat and all(
        part[k].shape == (n, MAX_CENTRES) and part[k].dtype.kind == "f" for k in CENTRE_FIELDS
    )


#: The variables of a saved chunk that say which chunk it is: ``[index, first cell, end]``
#: and the digest of the spec (and chunk size) it was computed for.
IDENTITY, DIGEST = "chunk_identity", "chunk_digest"


def _chunk_is(part: dict[str, np.ndarray], k: int, cells: tuple[int, int], digest: str) -> bool:
    """Whether a loaded chunk says it is chunk ``k`` of cells ``cells`` of the spec of
    ``digest`` (the two identity variables are removed from ``part``)."""
    identity, saved = part.pop(IDENTITY, None), part.pop(DIGEST, None)
    if identity is None or saved is None or identity.shape != (3,) or saved.shape != ():
        return False
    return [int(x) for x in identity] == [k, *cells] and str(saved) == digest


def _load_partial(
    folder: Path, digest: str, ranges: Mapping[int, tuple[int, int]], kind: str = "reduction"
) -> dict[int, dict[str, np.ndarray]]:
    """Chunks saved by an earlier run of the same spec (``{}`` if none); ``ranges``: the cells
    ``[start, end)`` of each chunk. A file that does not load, that is not the chunk its name
    says (its index, cells and spec digest: a file copied over another), or that does not hold
    what its chunk should, is removed and its chunk computed again, with one
    :class:`AtlasResumeWarning`."""
    if not folder.exists():
        return {}
    try:
        saved = json.loads((folder / "spec.json").read_text())
    except (OSError, ValueError):
        saved = {}
    if not isinstance(saved, dict) or saved.get("digest") != digest:
        raise AtlasError(
            f"{folder} holds an interrupted atlas of another spec (or chunk size); "
            "remove it to start over"
        )
    done = {}
    bad = []
    for f in sorted(folder.glob("chunk-*.npz")):
        part = None
        # any failure to read counts as damage: zipfile, zlib, numpy's format and a truncated
        # file each raise their own type
        with contextlib.suppress(Exception):
            k = int(f.stem.split("-")[1])
            with np.load(f, allow_pickle=False) as z:
                part = {key: z[key] for key in z.files}
        if (
            part is None
            or k not in ranges
            or not _chunk_is(part, k, ranges[k], digest)
            or not _chunk_fits(part, ranges[k][1] - ranges[k][0], kind)
        ):
            bad.append(f.name)
            with contextlib.suppress(OSError):
                f.unlink()
            continue
        done[k] = part
    if bad:
        warnings.warn(
            AtlasResumeWarning(
                f"{len(bad)} damaged or foreign chunk file(s) in {folder} (first {bad[0]}): "
                "computed again"
            ),
            stacklevel=3,
        )
    return done


def _save_chunk(
    folder: Path, k: int, cells: tuple[int, int], digest: str, result: Mapping[str, np.ndarray]
) -> None:
    """Save chunk ``k`` (cells ``[start, end)`` of the spec of ``digest``) with its identity."""
    buf = io.BytesIO()
    identity = {IDENTITY: np.array([k, *cells], dtype=np.int64), DIGEST: np.array(digest)}
    np.savez(buf, **result, **identity)  # type: ignore[arg-type]
    # now: a chunk is kept for a resumed run even when this one fails
    write_bytes_atomic(folder / f"chunk-{k:06d}.npz", buf.getvalue(), now=True)


def _dataset(spec: AtlasSpec, parts: Mapping[int, Mapping[str, np.ndarray]]) -> xr.Dataset:
    import xarray as xr

    dims = tuple(spec.axes)
    merged = {
        key: np.concatenate([parts[k][key] for k in sorted(parts)]) for key in parts[min(parts)]
    }
    data_vars = {}
    docs = {
        "status": "0 classified, 1 inadmissible body, 2 pole level, 3 level too large or not "
        "classifiable, "
        "4 state refused by the model",
        "n_steady": "steady motions (critical points of U in (-1, 1)); -1: not classified",
        "n_centres": "steady motions that are centres (U'' > 0)",
        "n_saddles": "steady motions that are saddles (U'' < 0)",
        "n_folds": "folds of the (C2, h) bifurcation diagram of (M3, C1) (the meridian "
        "model's; -1 for the others)",
        "rotation_centre": "rotation number psi'/omega at each centre (in order of gamma3)",
        "centre_gamma3": "gamma3 of each centre",
    }
    if spec.kind == "chaos":
        from rollingtop.atlas._chaos import CHAOS_DOCS

        docs = CHAOS_DOCS
    for key, values in merged.items():
        if values.ndim == 1:
            data_vars[key] = (dims, values.reshape(spec.shape), {"description": docs[key]})
        else:
            data_vars[key] = (
                (*dims, "centre"),
                values.reshape((*spec.shape, values.shape[1])),
                {"description": docs[key]},
            )
    attrs = {
        "fixed_json": json.dumps(spec.fixed),
        "axes": " ".join(dims),
        "models": " ".join(spec.models),
        "kind": spec.kind,
        "description": "rollingtop atlas: classification of the reduced motions over body "
        "parameters and integrals or models (issues 14, 24)"
        if spec.kind == "reduction"
        else "rollingtop atlas: chaos indicators, phase-volume rate and periodic orbits over "
        "body parameters and the constraint angle (issue 39)",
    }
    coords: dict[str, Any] = dict(spec.axes)
    if "model" in coords:  # indices into ATLAS_MODELS: the names
        coords["model"] = np.array([ATLAS_MODELS[int(i)] for i in coords["model"]], dtype=str)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _write(ds: xr.Dataset, output: Path) -> None:
    """The finished atlas, atomically: NetCDF through a temporary file, Zarr through a
    temporary store renamed into place."""
    if output.suffix.lower() == ".nc":
        # now: the chunks are removed next, so the atlas must be in place (a failure after
        # this point cannot refuse the run that computed it)
        write_bytes_atomic(output, netcdf_bytes(ds), now=True)
        return
    tmp = output.with_name(f".{output.name}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        # stored in chunks of at most ZARR_CHUNK along each dimension (dask arrays)
        chunked = ds.chunk({dim: min(int(n), ZARR_CHUNK) for dim, n in ds.sizes.items()})
        with warnings.catch_warnings():  # zarr 3: consolidated metadata is an extension
            warnings.filterwarnings("ignore", message=".*[Cc]onsolidated metadata.*")
            chunked.to_zarr(tmp, mode="w")
        old = output.with_name(f".{output.name}.old{os.getpid()}")
        if output.exists():
            os.replace(output, old)  # a folder cannot be renamed onto a folder
            try:
                os.replace(tmp, output)
            except OSError:
                os.replace(old, output)  # put the previous store back
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, output)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def check_atlas_output(output: str | os.PathLike[str]) -> Path:
    """The output path, checked before any work (``.nc`` or ``.zarr``; a ``.zarr`` store may
    exist and is replaced)."""
    path = Path(output)
    if path.suffix.lower() == ".zarr" and path.is_dir():
        if not any((path / name).exists() for name in ("zarr.json", ".zgroup", ".zattrs")):
            raise AtlasError(
                f"cannot write {short_path(path)}: a folder that is not a Zarr store is in the way"
            )
        return path
    try:
        return check_output_path(path, SUFFIXES)
    except RollingTopError as exc:
        raise AtlasError(str(exc)) from None
