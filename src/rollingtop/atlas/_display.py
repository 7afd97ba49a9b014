"""The atlas in a notebook: ``ds.rollingtop``, an xarray accessor on the Dataset of
:func:`~rollingtop.atlas.atlas` (registered when :mod:`rollingtop.atlas` is imported), with
an HTML view (the axes, the fixed values, the cells by status, the counts of the classified
cells) and :meth:`AtlasAccessor.plot`."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from rollingtop._html import block, table
from rollingtop.atlas._spec import STATUS, AtlasError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["COUNTED", "AtlasAccessor"]

#: The variables whose values :meth:`AtlasAccessor.counts` counts over the classified cells.
COUNTED = ("n_steady", "n_centres", "n_saddles", "n_folds")
#: The same for a chaos atlas (:mod:`rollingtop.atlas._chaos`).
CHAOS_COUNTED = ("n_finished", "n_vertical", "n_failed", "n_periodic", "n_attracting")


class AtlasAccessor:
    """``ds.rollingtop`` of an atlas ``ds``: :meth:`counts`, :meth:`plot` and, in a notebook,
    a summary table. Any other Dataset is refused in one line (an :class:`AtlasError`)."""

    def __init__(self, ds: xr.Dataset) -> None:
        if "status" not in ds.data_vars or "fixed_json" not in ds.attrs:
            raise AtlasError(
                "ds.rollingtop: the Dataset is not an atlas of rollingtop.atlas "
                "(no status variable or fixed_json attribute)"
            )
        self._ds = ds

    @property
    def axes(self) -> list[str]:
        """The atlas's axes, in the order of the spec's ``[axes]``."""
        return [str(d) for d in self._ds["status"].dims]

    @property
    def fixed(self) -> dict[str, float]:
        """The values held fixed: the spec's body and level (or state) values, less the axes'
        keys and the model (named by the Dataset's ``models`` attribute)."""
        fixed: dict[str, float] = json.loads(self._ds.attrs["fixed_json"])
        return {k: v for k, v in fixed.items() if k not in self.axes and k != "model"}

    def status_counts(self) -> dict[str, int]:
        """How many cells have each status (:data:`rollingtop.atlas.STATUS`, by name)."""
        values, n = np.unique(self._ds["status"].values, return_counts=True)
        return {STATUS.get(int(v), str(int(v))): int(c) for v, c in zip(values, n, strict=True)}

    def counts(self) -> dict[str, dict[int, int]]:
        """For each of :data:`COUNTED` (:data:`CHAOS_COUNTED` for a chaos atlas): how many
        classified cells (``status == 0``) have each value (``rollingtop atlas``' summary)."""
        classified = self._ds["status"].values == 0
        out = {}
        counted = CHAOS_COUNTED if self._ds.attrs.get("kind") == "chaos" else COUNTED
        for name in counted:
            values, n = np.unique(self._ds[name].values[classified], return_counts=True)
            out[name] = {int(v): int(c) for v, c in zip(values, n, strict=True)}
        return out

    def _repr_html_(self) -> str:
        ds = self._ds
        axes = []
        for d in self.axes:
            values = ds[d].values
            numeric = values.dtype.kind in "iuf"
            first, last = (
                (float(values[0]), float(values[-1]))
                if numeric
                else (str(values[0]), str(values[-1]))
            )
            axes.append([d, len(values), first, last])
        cells = [[name, n] for name, n in self.status_counts().items()]
        counted = [[name, value, n] for name, c in self.counts().items() for value, n in c.items()]
        size = " x ".join(str(ds.sizes[d]) for d in self.axes)
        sections = [
            ("axes", table(["axis", "values", "from", "to"], axes)),
            ("fixed", table(list(self.fixed), [list(self.fixed.values())])),
            ("cells", table(["status", "cells"], cells)),
            ("classified cells", table(["variable", "value", "cells"], counted)),
        ]
        return block(
            "rollingtop atlas (ds.rollingtop)",
            f"{int(ds['status'].size)} cells ({size}), models: {ds.attrs.get('models')}",
            sections,
        )

    def plot(
        self,
        ax: Axes | None = None,
        variable: str = "n_steady",
        *,
        x: str | None = None,
        y: str | None = None,
        **where: Any,
    ) -> Axes:
        """Draw ``variable`` over the axes ``x`` and ``y`` (default: the last two numeric axes),
        the others held at ``where`` (default: the middle value, the first model), on ``ax``
        (default: a new figure's) and return ``ax``
        (:func:`rollingtop.plot.atlas.draw_atlas`)."""
        from rollingtop.plot.atlas import draw_atlas

        return draw_atlas(ax, self._ds, variable, x=x, y=y, **where)


# ds.rollingtop on every Dataset (xarray's register_dataset_accessor is not annotated)
xr.register_dataset_accessor("rollingtop")(AtlasAccessor)  # type: ignore[no-untyped-call]
