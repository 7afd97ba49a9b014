"""What every result with an xarray form shares: writing it as NetCDF-4, atomically."""

from __future__ import annotations

import os
from abc import ABC, abstractmethod
from pathlib import Path
from typing import TYPE_CHECKING

from rollingtop.io import check_output_path, netcdf_bytes, write_bytes_atomic

if TYPE_CHECKING:
    import xarray as xr

#: Units of the variables of :meth:`rollingtop.Trajectory.to_xarray` (its attributes).
TRAJECTORY_UNITS = {
    "t": "T",
    "v": "L T-1",
    "omega": "T-1",
    "alpha": "1",
    "beta": "1",
    "gamma": "1",
    "position": "L",
    "contact_point": "L",
    "normal_force": "M L T-2",
    "tangential_force": "M L T-2",
    "constraint_residual": "L T-1",
    "orthonormality_error": "1",
    "energy": "M L2 T-2",
    "lagrange": "M L2 T-1",
    "jellett": "M L3 T-1",
    "area": "M L2 T-1",
    "F6": "M L3 T-1",
    "momentum_x": "M L T-1",
    "momentum_y": "M L T-1",
    "routh": "M L2 T-1",
    "rubber_spin": "M L2 T-1",
}


class NetCDFOutput(ABC):
    """Mixin: :meth:`to_netcdf` from the class's ``to_xarray()``."""

    @abstractmethod
    def to_xarray(self) -> xr.Dataset:
        """The result as an :class:`xarray.Dataset`."""

    def to_netcdf(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`to_xarray` as NetCDF-4 (engine ``h5netcdf``), atomically: the file
        appears complete or not at all (:func:`rollingtop.io.write_bytes_atomic`)."""
        out = check_output_path(path, (".nc",))
        return write_bytes_atomic(out, netcdf_bytes(self.to_xarray()))
