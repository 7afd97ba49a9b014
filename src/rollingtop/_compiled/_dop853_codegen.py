"""Writes :mod:`rollingtop._compiled._dop853_stages` from the tableau (run as a module).

Why generated code: a stage ``y + h sum_j A[s, j] K[j]`` written as a loop over ``j`` with a
run-time stage index ``s`` costs about four times the arithmetic (short loops of run-time
length, one per component); with the stage index and the coefficients spelled out, each stage is
one loop over the components whose body LLVM vectorises, with zero coefficients left out. The
source is committed so that numba's compile cache can find it; a test checks that it matches
this generator and the tableau.

    python -m rollingtop._compiled._dop853_codegen
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from rollingtop._compiled._dop853_tableau import E3, E5, N_STAGES_EXTENDED, A

TARGET = Path(__file__).with_name("_dop853_stages.py")
LINE_LENGTH = 100

HEADER = '''"""DOP853 stages and error estimates, coefficients spelled out (GENERATED: do not edit).

Written by ``python -m rollingtop._compiled._dop853_codegen`` from
:mod:`rollingtop._compiled._dop853_tableau`; see that generator for why.
"""

from __future__ import annotations

from rollingtop._jit import kernel
from rollingtop._types import FloatArray


@kernel
def stage(K: FloatArray, s: int, y: FloatArray, h: float, ytmp: FloatArray) -> None:
    """``ytmp = y + h * sum_{j<s} A[s, j] K[j]`` for stage ``s`` in ``1 .. 15``.

    Parameters
    ----------
    K : ndarray, shape (16, n)
        Stage derivatives; rows ``0 .. s-1`` are read.
    s : int
        Stage index (the 13th-16th stages, ``s = 12 .. 15``, serve the dense output).
    y : ndarray, shape (n,)
        State at the start of the step.
    h : float
        Step size.
    ytmp : ndarray, shape (n,)
        Output.
    """
    n = y.shape[0]
'''


ERROR_FUNCTION = '''

@kernel
def scaled_errors(
    K: FloatArray,
    y: FloatArray,
    ynew: FloatArray,
    rtol: float,
    atol: float,
    err5: FloatArray,
    err3: FloatArray,
) -> None:
    """``sum_j E[j] K[j]`` (the 5th- and 3rd-order error estimates over the step size) divided
    by the scale ``atol + max(|y|, |ynew|) rtol``, component by component.

    Parameters
    ----------
    K : ndarray, shape (16, n)
        Stage derivatives; rows ``0 .. 11`` are read.
    y, ynew : ndarray, shape (n,)
        State at the start and at the end of the step.
    rtol, atol : float
        Tolerances.
    err5, err3 : ndarray, shape (n,)
        Output.
    """
    for i in range(y.shape[0]):
        sc = atol + max(abs(y[i]), abs(ynew[i])) * rtol
'''


def _combination(coefficients: Iterable[float], lhs: str, head: str, tail: str) -> list[str]:
    """``lhs = head(c0 * K[0, i] + ...)tail`` with zero terms left out, laid out as
    ``ruff format`` would lay it out."""
    parts: list[str] = []
    for j, c in enumerate(coefficients):
        c = float(c)
        if c == 0.0:
            continue
        sign = ("- " if c < 0 else "+ ") if parts else ("-" if c < 0 else "")
        parts.append(f"{sign}{abs(c)!r} * K[{j}, i]")
    one_line = f"{lhs} = {head}{' '.join(parts)}){tail}"
    if len(one_line) <= LINE_LENGTH:
        return [one_line]
    indent = " " * (len(lhs) - len(lhs.lstrip()) + 4)
    return [f"{lhs} = {head}", *(indent + part for part in parts), f"{indent[:-4]}){tail}"]


def render() -> str:
    """Source of the generated module."""
    lines = [HEADER.rstrip("\n")]
    for s in range(1, N_STAGES_EXTENDED):
        keyword = "if" if s == 1 else "elif"
        lines.append(f"    {keyword} s == {s}:")
        lines.append("        for i in range(n):")
        lines += _combination(A[s, :s], "            ytmp[i]", "y[i] + h * (", "")
    lines += ERROR_FUNCTION.rstrip("\n").split("\n")
    lines += _combination(E5, "        err5[i]", "(", " / sc")
    lines += _combination(E3, "        err3[i]", "(", " / sc")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    TARGET.write_text(render())
    print(f"wrote {TARGET}")
