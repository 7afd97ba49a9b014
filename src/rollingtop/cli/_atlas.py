"""``rollingtop atlas``: the classification over a grid of body parameters and integrals, on
Dask."""

from __future__ import annotations

import json
import time
from typing import Any

import click
import numpy as np

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import json_option

__all__ = ["atlas"]


@click.command()
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option(
    "-o",
    "--output",
    type=click.Path(),
    required=True,
    help="ATLAS.nc or ATLAS.zarr (written when complete; resumable).",
)
@click.option(
    "--workers",
    type=int,
    default=None,
    help="Worker processes of the embedded local cluster (default: cores).",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Run on an existing Dask cluster (tcp://host:port).",
)
@click.option(
    "--scheduler-timeout",
    type=float,
    default=10.0,
    show_default=True,
    metavar="SECONDS",
    help="Seconds the --scheduler has to answer as a Dask scheduler.",
)
@click.option(
    "--chunk", type=int, default=None, help="Cells per task (default 200; 1 for a chaos atlas)."
)
@json_option
def atlas(
    spec: str,
    output: str,
    workers: int | None,
    scheduler: str | None,
    scheduler_timeout: float,
    chunk: int | None,
    as_json: bool,
) -> None:
    """Classify every cell of SPEC's grid: a scenario file whose [axes] table sets the axes
    (body keys a3, I1, I3, R, m, g and level keys M3, C1, C2; each a list or {start, stop,
    num}). An interrupted run resumes where it stopped (OUTPUT.partial/)."""
    from rollingtop.atlas import (
        DEFAULT_CHUNK,
        MAX_SCHEDULER_TIMEOUT,
        atlas,
        check_atlas_output,
        load_atlas_spec,
    )

    if workers is not None and workers < 1:
        raise BadInput(f"--workers {workers}: must be >= 1")
    if chunk is not None and chunk < 1:
        raise BadInput(f"--chunk {chunk}: must be >= 1")
    if not 0.0 < scheduler_timeout <= MAX_SCHEDULER_TIMEOUT:  # also NaN
        raise BadInput(
            f"--scheduler-timeout {scheduler_timeout:g}: must be in "
            f"(0, {MAX_SCHEDULER_TIMEOUT:g}] seconds"
        )
    check_atlas_output(output)
    atlas_spec = load_atlas_spec(spec)
    start = time.perf_counter()
    with _output.counting("cells", atlas_spec.size) as progress:
        ds = _output.with_warnings_reported(
            lambda: atlas(
                atlas_spec,
                output,
                workers=workers,
                scheduler=scheduler,
                chunk=chunk or (1 if atlas_spec.kind == "chaos" else DEFAULT_CHUNK),
                progress=progress,
                scheduler_timeout=scheduler_timeout,
            )
        )
    wall = time.perf_counter() - start
    classified = ds["status"].values == 0
    counts: dict[str, dict[str, int]] = {}
    counted = (
        ("n_finished", "n_vertical", "n_failed", "n_periodic", "n_attracting")
        if atlas_spec.kind == "chaos"
        else ("n_steady", "n_centres", "n_saddles", "n_folds")
    )
    for name in counted:
        uniq, cnt = np.unique(ds[name].values[classified], return_counts=True)
        counts[name] = {str(int(u)): int(c) for u, c in zip(uniq, cnt, strict=True)}
    dims = {str(k): int(v) for k, v in ds.sizes.items() if k != "centre"}
    summary: dict[str, Any] = {
        "output": output,
        "dims": dims,
        "cells": atlas_spec.size,
        "classified": int(classified.sum()),
        "counts": counts,
        "wall_s": wall,
    }
    if atlas_spec.kind == "chaos":  # the indicators' ranges over the computed cells
        summary["ranges"] = {
            name: [float(np.nanmin(v)), float(np.nanmax(v))] if np.any(np.isfinite(v)) else None
            for name in ("megno", "lyapunov", "volume_rate")
            for v in [ds[name].values[classified]]
        }
    if as_json:
        click.echo(json.dumps(summary))
        return
    console = _output.console()
    shape = " x ".join(f"{k} {v}" for k, v in dims.items())
    console.print(
        f"{atlas_spec.size} cells ({shape}), {summary['classified']} classified, in {wall:.1f} s"
    )
    for name, c in counts.items():
        console.print(f"  {name}: " + ", ".join(f"{k}: {v} cells" for k, v in c.items()))
    for name, r in summary.get("ranges", {}).items():
        console.print(f"  {name}: " + ("none" if r is None else f"{r[0]:.4g} .. {r[1]:.4g}"))
    click.echo(f"wrote {output}")
