"""The parameter atlas (:mod:`rollingtop.atlas`) as a picture: one of its cell variables over two
of its axes (a map) or one (a step curve), the other axes held at one value each."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.ticker import MaxNLocator

from rollingtop._errors import RollingTopError
from rollingtop.plot._axes import axes_for

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["atlas_slice", "draw_atlas"]


def _numeric(ds: xr.Dataset, dim: str) -> bool:
    return ds[dim].dtype.kind in "iuf"


def atlas_slice(
    ds: xr.Dataset,
    variable: str = "n_steady",
    x: str | None = None,
    y: str | None = None,
    where: Mapping[str, Any] | None = None,
) -> tuple[xr.DataArray, dict[str, Any]]:
    """The cells of ``variable`` to draw, with NaN where a cell was not classified (``status !=
    0``), and the value each other axis is held at.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas (:func:`rollingtop.atlas.atlas`).
    variable : str
        A cell variable (``n_steady, n_centres, n_saddles, n_folds``; per centre:
        ``rotation_centre, centre_gamma3``, the centre ``where["centre"]``, default the first).
    x, y : str, optional
        The axes drawn (``y`` omitted: a curve over ``x``). Default: the last two numeric axes
        not held by ``where``, in the order of the spec's ``[axes]``.
    where : mapping, optional
        The value of each other axis (nearest on a numeric axis). Default: the middle value of
        a numeric axis, the first of the others (``model``).

    Returns
    -------
    (xarray.DataArray, dict)
        The cells, dimensions ``(y, x)`` or ``(x,)``, and ``{axis: value}`` of the held axes.
    """
    where = dict(where or {})
    da = ds[variable]
    status = ds["status"]
    if "centre" in da.dims:
        da = da.isel(centre=int(where.pop("centre", 0)))
    dims = [str(d) for d in da.dims]
    unknown = [k for k in [*where, x, y] if k is not None and k not in dims]
    if unknown:
        names = ", ".join(map(repr, unknown))
        raise RollingTopError(f"{names}: not an axis of the atlas (its axes: {', '.join(dims)})")
    if x is None:
        free = [d for d in dims if d not in where and d != y and _numeric(ds, d)]
        if not free:
            raise RollingTopError(f"no numeric axis left to draw {variable} over: give x")
        x, y = (free[-2], free[-1]) if len(free) >= 2 and y is None else (free[-1], y)
    drawn = [d for d in (x, y) if d is not None]
    held: dict[str, Any] = {}
    for d in dims:
        if d in drawn:
            continue
        if d in where:
            value = where[d]
        else:
            values = ds[d].values
            value = values[len(values) // 2] if _numeric(ds, d) else values[0]
        method = "nearest" if _numeric(ds, d) else None
        da, status = da.sel({d: value}, method=method), status.sel({d: value}, method=method)
        held[d] = da[d].item()
    da = da.where(status == 0).transpose(*drawn[::-1])
    return da, held


def _ticks(ax: Axes, axis: str, ds: xr.DataArray, dim: str) -> Any:
    """The coordinate of ``dim`` to draw against: its values, or positions with the names as
    tick labels (``model``)."""
    values = ds[dim].values
    if values.dtype.kind in "iuf":
        return values
    positions = np.arange(len(values))
    getattr(ax, f"set_{axis}ticks")(positions, [str(v) for v in values])
    return positions


def draw_atlas(
    ax: Axes | None,
    ds: xr.Dataset,
    variable: str = "n_steady",
    *,
    x: str | None = None,
    y: str | None = None,
    **where: Any,
) -> Axes:
    """Draw ``variable`` of the atlas ``ds`` over the axes ``x`` and ``y`` (a map with a colour
    bar; a count in discrete colours) or over ``x`` alone (a step curve), the other axes held at
    ``where`` (:func:`atlas_slice`, which says the defaults); cells not classified are left
    blank. Returns ``ax`` (``None``: a new figure's)."""
    da, held = atlas_slice(ds, variable, x, y, where)
    ax = axes_for(ax, (6.4, 5.0))
    description = str(ds[variable].attrs.get("description", variable)).split(";")[0]
    values = np.asarray(da.values, dtype=float)
    if da.ndim == 1:
        (xd,) = (str(d) for d in da.dims)
        ax.step(_ticks(ax, "x", da, xd), values, where="mid", color="black")
        if ds[variable].dtype.kind in "iu":
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel(xd)
        ax.set_ylabel(variable)
    else:
        yd, xd = (str(d) for d in da.dims)
        integer = ds[variable].dtype.kind in "iu"
        finite = values[np.isfinite(values)]
        lo, hi = (int(finite.min()), int(finite.max())) if finite.size else (0, 1)
        steps = [colormaps["viridis"](k / max(hi - lo, 1)) for k in range(hi - lo + 1)]
        cmap: Any = ListedColormap(steps) if integer else "viridis"
        vmin, vmax = (lo - 0.5, hi + 0.5) if integer else (None, None)
        mesh = ax.pcolormesh(
            _ticks(ax, "x", da, xd),
            _ticks(ax, "y", da, yd),
            np.ma.masked_invalid(values),
            cmap=cmap,
            shading="nearest",
            vmin=vmin,
            vmax=vmax,
        )
        bar = ax.figure.colorbar(mesh, ax=ax, label=variable)
        if integer:
            bar.set_ticks(range(lo, hi + 1))
        ax.set_xlabel(xd)
        ax.set_ylabel(yd)
    fixed = ", ".join(
        f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in held.items()
    )
    ax.set_title(f"{description}" + (f"\nat {fixed}" if fixed else ""), fontsize=9)
    return ax
