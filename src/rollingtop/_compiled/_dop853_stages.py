"""DOP853 stages and error estimates, coefficients spelled out (GENERATED: do not edit).

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


@kernel
def step_stage(K: FloatArray, s: int, y: FloatArray, h: float, ytmp: FloatArray) -> None:
    """:func:`stage` for ``s`` in ``1 .. 12`` (a step's stages and its new point)."""
    n = y.shape[0]
    if s == 1:
        for i in range(n):
            ytmp[i] = y[i] + h * (0.05260015195876773 * K[0, i])
    elif s == 2:
        for i in range(n):
            ytmp[i] = y[i] + h * (0.0197250569845379 * K[0, i] + 0.0591751709536137 * K[1, i])
    elif s == 3:
        for i in range(n):
            ytmp[i] = y[i] + h * (0.02958758547680685 * K[0, i] + 0.08876275643042054 * K[2, i])
    elif s == 4:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.2413651341592667 * K[0, i]
                - 0.8845494793282861 * K[2, i]
                + 0.924834003261792 * K[3, i]
            )
    elif s == 5:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.037037037037037035 * K[0, i]
                + 0.17082860872947386 * K[3, i]
                + 0.12546768756682242 * K[4, i]
            )
    elif s == 6:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.037109375 * K[0, i]
                + 0.17025221101954405 * K[3, i]
                + 0.06021653898045596 * K[4, i]
                - 0.017578125 * K[5, i]
            )
    elif s == 7:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.03709200011850479 * K[0, i]
                + 0.17038392571223998 * K[3, i]
                + 0.10726203044637328 * K[4, i]
                - 0.015319437748624402 * K[5, i]
                + 0.008273789163814023 * K[6, i]
            )
    elif s == 8:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.6241109587160757 * K[0, i]
                - 3.3608926294469414 * K[3, i]
                - 0.868219346841726 * K[4, i]
                + 27.59209969944671 * K[5, i]
                + 20.154067550477894 * K[6, i]
                - 43.48988418106996 * K[7, i]
            )
    elif s == 9:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.47766253643826434 * K[0, i]
                - 2.4881146199716677 * K[3, i]
                - 0.590290826836843 * K[4, i]
                + 21.230051448181193 * K[5, i]
                + 15.279233632882423 * K[6, i]
                - 33.28821096898486 * K[7, i]
                - 0.020331201708508627 * K[8, i]
            )
    elif s == 10:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                -0.9371424300859873 * K[0, i]
                + 5.186372428844064 * K[3, i]
                + 1.0914373489967295 * K[4, i]
                - 8.149787010746927 * K[5, i]
                - 18.52006565999696 * K[6, i]
                + 22.739487099350505 * K[7, i]
                + 2.4936055526796523 * K[8, i]
                - 3.0467644718982196 * K[9, i]
            )
    elif s == 11:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                2.273310147516538 * K[0, i]
                - 10.53449546673725 * K[3, i]
                - 2.0008720582248625 * K[4, i]
                - 17.9589318631188 * K[5, i]
                + 27.94888452941996 * K[6, i]
                - 2.8589982771350235 * K[7, i]
                - 8.87285693353063 * K[8, i]
                + 12.360567175794303 * K[9, i]
                + 0.6433927460157636 * K[10, i]
            )
    elif s == 12:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.054293734116568765 * K[0, i]
                + 4.450312892752409 * K[5, i]
                + 1.8915178993145003 * K[6, i]
                - 5.801203960010585 * K[7, i]
                + 0.3111643669578199 * K[8, i]
                - 0.1521609496625161 * K[9, i]
                + 0.20136540080403034 * K[10, i]
                + 0.04471061572777259 * K[11, i]
            )


@kernel
def dense_stage(K: FloatArray, s: int, y: FloatArray, h: float, ytmp: FloatArray) -> None:
    """:func:`stage` for ``s`` in ``13 .. 15`` (the dense output's stages)."""
    n = y.shape[0]
    if s == 13:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.056167502283047954 * K[0, i]
                + 0.25350021021662483 * K[6, i]
                - 0.2462390374708025 * K[7, i]
                - 0.12419142326381637 * K[8, i]
                + 0.15329179827876568 * K[9, i]
                + 0.00820105229563469 * K[10, i]
                + 0.007567897660545699 * K[11, i]
                - 0.008298 * K[12, i]
            )
    elif s == 14:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                0.03183464816350214 * K[0, i]
                + 0.028300909672366776 * K[5, i]
                + 0.053541988307438566 * K[6, i]
                - 0.05492374857139099 * K[7, i]
                - 0.00010834732869724932 * K[10, i]
                + 0.0003825710908356584 * K[11, i]
                - 0.00034046500868740456 * K[12, i]
                + 0.1413124436746325 * K[13, i]
            )
    elif s == 15:
        for i in range(n):
            ytmp[i] = y[i] + h * (
                -0.42889630158379194 * K[0, i]
                - 4.697621415361164 * K[5, i]
                + 7.683421196062599 * K[6, i]
                + 4.06898981839711 * K[7, i]
                + 0.3567271874552811 * K[8, i]
                - 0.0013990241651590145 * K[12, i]
                + 2.9475147891527724 * K[13, i]
                - 9.15095847217987 * K[14, i]
            )


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
        err5[i] = (
            0.01312004499419488 * K[0, i]
            - 1.2251564463762044 * K[5, i]
            - 0.4957589496572502 * K[6, i]
            + 1.6643771824549864 * K[7, i]
            - 0.35032884874997366 * K[8, i]
            + 0.3341791187130175 * K[9, i]
            + 0.08192320648511571 * K[10, i]
            - 0.022355307863886294 * K[11, i]
        ) / sc
        err3[i] = (
            -0.18980075407240762 * K[0, i]
            + 4.450312892752409 * K[5, i]
            + 1.8915178993145003 * K[6, i]
            - 5.801203960010585 * K[7, i]
            - 0.4226823213237919 * K[8, i]
            - 0.1521609496625161 * K[9, i]
            + 0.20136540080403034 * K[10, i]
            + 0.02265179219836082 * K[11, i]
        ) / sc
