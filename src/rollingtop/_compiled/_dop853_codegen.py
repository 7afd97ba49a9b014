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
#: :data:`_dop853_stages.LAST_STEP_STAGE` (written into it).
LAST_STEP_STAGE = 12

HEADER = '''"""DOP853 stages and error estimates, coefficients spelled out (GENERATED: do not edit).

Written by ``python -m rollingtop._compiled._dop853_codegen`` from
:mod:`rollingtop._compiled._dop853_tableau`; see that generator for why.
"""

from __future__ import annotations

from rollingtop._jit import kernel
from rollingtop._types import FloatArray

#: The last stage of a step (the new point, first same as last); the later ones serve the dense
#: output.
LAST_STEP_STAGE = 12


@kernel
def stage(K: FloatArray, s: int, y: FloatArray, h: float, ytmp: FloatArray) -> None:
    """``ytmp = y + h * sum_{j<s} A[s, j] K[j]`` for stage ``s`` in ``1 .. 15``: :func:`step_stage`
    or :func:`dense_stage` (the compiled callers call those: each links only the code of its
    own stages).

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
    if s <= LAST_STEP_STAGE:
        step_stage(K, s, y, h, ytmp)
    else:
        dense_stage(K, s, y, h, ytmp)
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


STAGE_FUNCTION = '''

@kernel
def {name}(K: FloatArray, s: int, y: FloatArray, h: float, ytmp: FloatArray) -> None:
    """:func:`stage` for ``s`` in ``{first} .. {last}`` ({what})."""
    n = y.shape[0]
'''


def _stages(name: str, first: int, last: int, what: str) -> list[str]:
    """A stage function of the stages ``first .. last`` (another ``s`` writes nothing)."""
    lines = STAGE_FUNCTION.format(name=name, first=first, last=last, what=what).rstrip("\n")
    out = lines.split("\n")
    for s in range(first, last + 1):
        keyword = "if" if s == first else "elif"
        out.append(f"    {keyword} s == {s}:")
        out.append("        for i in range(n):")
        out += _combination(A[s, :s], "            ytmp[i]", "y[i] + h * (", "")
    return out


def render() -> str:
    """Source of the generated module."""
    lines = [HEADER.rstrip("\n")]
    lines += _stages("step_stage", 1, LAST_STEP_STAGE, "a step's stages and its new point")
    lines += _stages(
        "dense_stage", LAST_STEP_STAGE + 1, N_STAGES_EXTENDED - 1, "the dense output's stages"
    )
    lines += ERROR_FUNCTION.rstrip("\n").split("\n")
    lines += _combination(E5, "        err5[i]", "(", " / sc")
    lines += _combination(E3, "        err3[i]", "(", " / sc")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    TARGET.write_text(render())
    print(f"wrote {TARGET}")
