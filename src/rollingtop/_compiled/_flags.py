"""The stop flag that parallel compiled loops poll (ensembles, sections, chaos maps).

A long compiled loop runs in a worker thread without the GIL; the calling thread raises the flag
on Ctrl-C, SIGTERM or an error, and every trajectory looks at it each :data:`STOP_POLL_STEPS`
accepted steps.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

from numba import types
from numba.extending import intrinsic

from rollingtop._types import IntArray

__all__ = ["STOP_POLL_STEPS", "read_flag"]

#: Accepted steps of a trajectory between two looks at the stop flag (about a millisecond).
STOP_POLL_STEPS = 1000


@intrinsic
def _read_flag_intrinsic(typingctx: Any, flag: types.Type) -> Any:
    """``flag[0]`` of an int64 array, by an atomic (relaxed) load: another thread sets it while
    a compiled loop runs, and a plain load could be hoisted out of that loop by the compiler.

    The arguments are numba's typing context and the argument's numba type; the result is the
    signature and the code generator (``None``: not an int64 array)."""
    if not (isinstance(flag, types.Array) and flag.dtype == types.int64):
        return None

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        array = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.load_atomic(array.data, "monotonic", 8)

    return types.int64(flag), codegen


#: What :func:`_read_flag_intrinsic` is in compiled code. numba's stubs type an intrinsic's call
#: with its typing function's parameters (the typing context included) and as never returning.
read_flag = cast(Callable[[IntArray], int], _read_flag_intrinsic)
