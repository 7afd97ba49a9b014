"""Writes :mod:`rollingtop.integrate._dop853_stages` from the tableau (run as a module).

Why generated code: a stage ``y + h sum_j A[s, j] K[j]`` written as a loop over ``j`` with a
run-time stage index ``s`` costs about four times the arithmetic (short loops of run-time
length, one per component); with the stage index and the coefficients spelled out, each stage is
one loop over the components whose body LLVM vectorises, with zero coefficients left out. The
source is committed so that numba's compile cache can find it; a test checks that it matches
this generator and the tableau.

    python -m rollingtop.integrate._dop853_codegen
"""

from pathlib import Path

from rollingtop.integrate._dop853_tableau import N_STAGES_EXTENDED, A

TARGET = Path(__file__).with_name("_dop853_stages.py")
LINE_LENGTH = 100

HEADER = '''"""DOP853 stages with their coefficients spelled out (GENERATED: do not edit).

Written by ``python -m rollingtop.integrate._dop853_codegen`` from
:mod:`rollingtop.integrate._dop853_tableau`; see that generator for why.
"""

from numba import njit


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def stage(K, s, y, h, ytmp):
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


def render() -> str:
    """Source of the generated module."""
    lines = [HEADER.rstrip("\n")]
    for s in range(1, N_STAGES_EXTENDED):
        terms = [(float(A[s, j]), j) for j in range(s) if A[s, j] != 0.0]
        keyword = "if" if s == 1 else "elif"
        lines.append(f"    {keyword} s == {s}:")
        lines.append("        for i in range(n):")
        parts = []
        for k, (a, j) in enumerate(terms):
            sign = ("- " if a < 0 else "+ ") if k else ("-" if a < 0 else "")
            parts.append(f"{sign}{abs(a)!r} * K[{j}, i]")
        one_line = f"            ytmp[i] = y[i] + h * ({' '.join(parts)})"
        if len(one_line) <= LINE_LENGTH:  # the layout ``ruff format`` would choose
            lines.append(one_line)
        else:
            lines.append("            ytmp[i] = y[i] + h * (")
            lines.extend(f"                {part}" for part in parts)
            lines.append("            )")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    TARGET.write_text(render())
    print(f"wrote {TARGET}")
