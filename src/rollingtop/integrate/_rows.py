"""The arrays of the stepper's loop (``run_rows``):
the work arrays one call shares between its rows, and each row's own. Made here, with NumPy, by
the single run's driver and by the ensemble's chunks alike, so that both pass the loop the same
types (one compile)."""

from __future__ import annotations

from typing import Any, NamedTuple, TypedDict

import numpy as np

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled._kernel import workspace
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray, Workspace

__all__ = ["Rows", "loop_args", "work_arrays"]


class Work(TypedDict):
    """Work arrays of one run of the compiled loop (``run_rows``)."""

    K: FloatArray
    ynew: FloatArray
    ytmp: FloatArray
    y_old: FloatArray
    Fd: FloatArray
    ws: Workspace


def work_arrays() -> Work:
    """The work arrays of the stepper's loop (``run_rows``), shared by
    the rows of one call: the stages, three states, the dense output's coefficients and the
    kernels' workspace."""
    return Work(
        K=np.zeros((16, N_STATE)),
        ynew=np.zeros(N_STATE),
        ytmp=np.zeros(N_STATE),
        y_old=np.zeros(N_STATE),
        Fd=np.zeros((7, N_STATE)),
        ws=workspace(),
    )


class Rows(NamedTuple):
    """The per-row arrays of the stepper's loop (``run_rows``) for ``n``
    trajectories: states (advanced in place), derivatives, control, counters, reaction
    tracking and status; a row whose counters are 0 is started by the loop."""

    Y: FloatArray
    F: FloatArray
    CTRL: FloatArray
    COUNTS: IntArray
    TRACK: FloatArray
    STATUS: IntArray

    @classmethod
    def of(cls, states: FloatArray) -> Rows:
        """Rows starting from ``states`` (shape (n, 18), copied)."""
        n = states.shape[0]
        return cls(
            np.array(states, dtype=float, order="C"),
            np.zeros((n, N_STATE)),
            np.zeros((n, dop.N_CTRL)),
            np.zeros((n, dop.N_COUNTS), dtype=np.int64),
            np.zeros((n, dop.N_TRACK)),
            np.zeros(n, dtype=np.int64),
        )


def loop_args(
    codes: IntArray,
    P: FloatArray,
    row: Rows,
    t_eval: FloatArray,
    out: FloatArray,
    tolerances: tuple[float, float],
    events: tuple[IntArray, FloatArray, FloatArray],
    steps: tuple[int, int],
    w: Work,
    held: tuple[IntArray, FloatArray, FloatArray],
    stop: IntArray,
) -> tuple[Any, ...]:
    """The arguments of the stepper's loop (``run_rows``), in its order: the rows' codes,
    parameters and arrays, the sample times and samples ``out``, ``(rtol, atol)``, the events
    ``(ev_spec, ev_t, ev_y)``, ``(limit, poll)`` in accepted steps, the work arrays, the
    integrals held ``(icodes, targets, pw)`` and the stop flag."""
    return (
        codes,
        P,
        row.Y,
        row.F,
        row.CTRL,
        row.COUNTS,
        row.TRACK,
        t_eval,
        out,
        *tolerances,
        *events,
        *steps,
        w["K"],
        w["ynew"],
        w["ytmp"],
        w["y_old"],
        w["Fd"],
        w["ws"],
        *held,
        row.STATUS,
        stop,
    )
