"""Projection of a state onto the level set of the model's first integrals, after an accepted
step (``project_integrals`` of :func:`rollingtop.simulate`; issue 26).

**What moves.** Only the velocity ``u = (v, w)``: the attitude, the position and the carried
direction stay as the step left them (the constraint projection has already made the frame
orthonormal). Every claimed integral is of degree at most two in ``u`` at a fixed attitude
(:mod:`rollingtop._compiled._integrals`), so the correction is a small linear problem plus,
for the energy, a quadratic equation, solved to round-off in one pass.

**The metric** is the body's kinetic energy, ``|du|^2_M = m |dv|^2 + (I dw, dw)``: the
correction is the velocity change of least kinetic energy, the impulse-like change that
respects the body's mass and inertia, and the result does not depend on the units of length or
time (a Euclidean metric on ``(v, w)`` would weigh metres against radians). It is the metric of
the constraint projection too (:func:`.dynamics.project`).

**The construction.** The rows of the velocity constraints ``J u = 0`` and the gradients of the
linear integrals are made orthonormal in the dual metric ``M^-1`` (modified Gram-Schmidt); a row
that lies in the span of the earlier ones to round-off (dependent integrals, as the area and
Lagrange's integrals on the vertical) is dropped. The minimum-norm ``du`` that zeroes the
constraint residuals and the linear integrals' deviations from their initial values is then
``M^-1 sum_k beta_k q_k``. The energy (and ``slip_nu``) is corrected along the direction of its
gradient orthogonal to those rows, so the linear integrals and the constraints are not touched:
along ``d = M^-1 g_perp`` the energy is ``E + q (l + l^2 / 2)`` with ``q = (g_perp, M^-1
g_perp)``, and ``l`` solves that quadratic exactly. Each pass re-solves the linear part first,
so round-off that an energy step leaks into the other rows is taken back.

**The attitude, where the velocity cannot.** Near a turning point of ``gamma3`` (the other
integrals fix every velocity component but ``w_tau``, which is small there), the energy has no
root along the velocity direction, or only one far away (``w_tau`` scaled many times over). The
energy is then corrected by tilting the body about ``gamma x e3`` (the axis that changes
``gamma3``) by the angle ``phi`` that zeroes ``E(P(tilt(y, phi))) - E0``, ``P`` the linear
part: a secant step on a central difference. Of the two, the smaller relative change is taken
(``|l| sqrt(q) / |u|_M`` against ``|phi|``), so the correction never depends on how accurate
the step was. Only where neither exists (a steady motion whose level is one point, the pole
itself for the tilt) is the energy left for the next steps (``counts[PROJ_DEFERRED]`` of the
stepper).

**Round-off is not amplified.** A nearly dependent row (the integrals near the vertical,
where Jellett's and the area integral tend to Lagrange's) would turn the round-off of its
residual into a velocity change ``1 / sqrt(left)`` times larger. Where its part orthogonal to
the earlier rows is below :data:`ILL_CONDITIONED` of its size and its residual below the
round-off of its integral's value, ``ROUNDOFF * sqrt(q_k) |u|_M`` (the integral's natural size
at this velocity), the residual is set to zero: the row still keeps the correction off its
direction. A well-conditioned row's round-off is corrected (else it would be left to wander
up to that bound).

**The attitude, for a dependent linear integral.** Within a tilt of about ``1e-4`` of the
vertical the area integral's and Jellett's rows are Lagrange's to round-off and dropped: the
velocity cannot hold them, and a motion through the vertical (the sleeping top of the meridian
model started with ``v_tau``) left them off their values by the step's error (``8e-6`` at
``rtol = 1e-4``), as far as the orbit then misses the pole. After the linear part, such an
integral still off by more than :data:`SETTLED` units of round-off is corrected by turning the
body about the axis perpendicular to ``gamma`` along which it falls fastest (a secant step on
central differences, each trial with the linear part solved again, its ill-conditioned integral
rows dropped in every trial alike); a slope within the differences' round-off
(:data:`RESOLVED`) is no direction, and a turn that does not lower the residual is not taken.

``F6`` carries ``-M3 a3 theta``, with the signed ``theta`` of the carried direction: its value
jumps by ``2 pi M3 a3`` where ``atan2`` wraps (a passage of the north pole in a pole case), so
its deviation is taken modulo that.
"""

from __future__ import annotations

import math

from rollingtop._compiled._integrals import ENERGY, F6, LINEAR, integral_value, velocity_gradient
from rollingtop._compiled._template._dispatch import rows as constraint_rows
from rollingtop._jit import kernel
from rollingtop._types import FloatArray, IntArray, Workspace

__all__ = ["project_integrals"]

#: A row whose part orthogonal to the earlier rows is below this fraction of its size (in the
#: dual metric) is dependent on them: dropped.
DEPENDENT = 1e-4
#: A residual below this many units of round-off of its integral's natural size is round-off:
#: not corrected where its row is ill-conditioned (module docstring).
ROUNDOFF = 16.0 * 2.220446049250313e-16
#: A row whose part orthogonal to the earlier ones is below this fraction of its size is
#: ill-conditioned: a correction along it is its residual amplified.
ILL_CONDITIONED = 0.1
#: A velocity correction beyond this fraction of the velocity's size is refused (the attitude is
#: used, or the integral left for later).
MAX_CHANGE = 0.5
#: A velocity correction below this relative size is taken without trying the attitude.
SMALL_CHANGE = 1e-8
#: Passes (each: the linear part, then one step per nonlinear integral).
NEWTON_ITERATIONS = 8
#: After the last pass, a nonlinear residual within this many :data:`ROUNDOFF` s is on the level.
SETTLED = 4.0
#: An attitude slope of a linear integral below this many of its central difference's
#: round-off is no direction (:func:`_attitude_step`).
RESOLVED = 1e3
#: A turn of the attitude (:func:`_attitude_step`) is taken where it leaves at most this
#: fraction of the residual it corrects.
DECREASE = 0.5
#: Step of the central difference in the tilt angle (radians).
TILT_STEP = 1e-5
#: Below this ``|gamma x e3|`` (the pole) there is no tilt axis.
MIN_TILT_SINE = 1e-6
#: Rows of the work array ``pw`` (:func:`project_integrals`) before the two states of the tilt:
#: orthonormal rows (columns 0-5) with their right-hand sides (column 6), a gradient, and the
#: metric with the deferral flag.
WORK_ROWS = 16
#: Shape of ``pw``: :data:`WORK_ROWS` and two full states (the tilt's source and trial).
WORK_SHAPE = (WORK_ROWS + 2, 18)


@kernel
def _orthogonalise(pw: FloatArray, n_rows: int, row: int, minv: FloatArray) -> float:
    """Make ``pw[row, 0:6]`` orthogonal (dual metric ``diag(minv)``) to the orthonormal rows
    ``pw[0:n_rows, 0:6]``, updating its right-hand side ``pw[row, 6]`` alike; returns the squared
    size of what is left relative to the row's own (1 for a row orthogonal to the others)."""
    size0 = 0.0
    for k in range(6):
        size0 += pw[row, k] * pw[row, k] * minv[k]
    if not size0 > 0.0:
        return 0.0
    for j in range(n_rows):
        a = 0.0
        for k in range(6):
            a += pw[row, k] * pw[j, k] * minv[k]
        for k in range(7):
            pw[row, k] -= a * pw[j, k]
    size = 0.0
    for k in range(6):
        size += pw[row, k] * pw[row, k] * minv[k]
    return size / size0


@kernel
def _velocity_size(y: FloatArray, minv: FloatArray) -> float:
    """``|u|_M``, the velocity's size in the kinetic-energy metric."""
    usize = 0.0
    for k in range(6):
        usize += y[k] * y[k] / minv[k]
    return math.sqrt(usize)


@kernel
def _natural(ic: int, p: FloatArray, usize: float, minv: FloatArray) -> float:
    """The natural size of the nonlinear integral ``ic`` at the velocity size ``usize``: the
    energy's, the kinetic energy and the potential's range ``m g (R + |a3|)``; ``slip_nu``'s, a
    speed, ``|u|_M / sqrt(m)``."""
    if ic == ENERGY:
        return float(0.5 * usize * usize + p[1] * p[2] * (p[0] + abs(p[3])))
    return float(usize * math.sqrt(minv[0]))


@kernel
def _linear(
    code: int,
    p: FloatArray,
    y: FloatArray,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
    minv: FloatArray,
    kept: float = DEPENDENT * DEPENDENT,
) -> int:
    """The constraints and the linear integrals: one exact minimum-norm correction of the
    velocity of ``y`` (in place); the orthonormal rows stay in ``pw[0:n_rows]``. An integral's
    row is kept where more than ``kept`` of its squared size is orthogonal to the earlier rows
    (a constraint's where more than ``DEPENDENT ** 2``). Returns ``n_rows``."""
    J, bias, dirs = ws[0], ws[1], ws[2]
    n_int = icodes.shape[0]
    usize = _velocity_size(y, minv)
    nc = constraint_rows(code, p, y, J, bias, dirs)
    n_rows = 0
    for i in range(nc + n_int):
        if n_rows >= WORK_ROWS - 3:
            break
        if i < nc:
            res = 0.0
            for k in range(6):
                pw[n_rows, k] = J[i, k]
                res += J[i, k] * y[k]
        else:
            ic = icodes[i - nc]
            if not LINEAR[ic]:
                continue
            velocity_gradient(ic, p, y, pw[n_rows])
            res = _residual(ic, p, y, targets[i - nc])
        natural = 0.0  # the row's integral at most, at this velocity (Cauchy-Schwarz)
        for k in range(6):
            natural += pw[n_rows, k] * pw[n_rows, k] * minv[k]
        natural = math.sqrt(natural) * usize
        pw[n_rows, 6] = -res
        left = _orthogonalise(pw, n_rows, n_rows, minv)
        if left > (DEPENDENT * DEPENDENT if i < nc else kept):
            noise = abs(pw[n_rows, 6]) <= ROUNDOFF * natural
            if noise and left < ILL_CONDITIONED * ILL_CONDITIONED:
                pw[n_rows, 6] = 0.0  # round-off that 1 / sqrt(left) would amplify: not corrected
            size = 0.0
            for k in range(6):
                size += pw[n_rows, k] * pw[n_rows, k] * minv[k]
            size = math.sqrt(size)
            for k in range(7):
                pw[n_rows, k] /= size
            n_rows += 1
    for k in range(6):
        s = 0.0
        for j in range(n_rows):
            s += pw[j, 6] * pw[j, k]
        y[k] += minv[k] * s
    return n_rows


@kernel
def _rotate(y: FloatArray, src: FloatArray, ax: float, ay: float, az: float, phi: float) -> None:
    """``y`` = ``src`` with the body turned by ``phi`` about the unit axis ``a = (ax, ay, az)``
    of the body frame (the fixed axes ``alpha, beta, gamma`` seen in the body frame turned by
    ``-phi``, exactly: Rodrigues)."""
    for k in range(18):
        y[k] = src[k]
    c, sn = math.cos(phi), math.sin(phi)
    for base in (6, 9, 12):
        x0, x1, x2 = src[base], src[base + 1], src[base + 2]
        dot = ax * x0 + ay * x1 + az * x2
        # rotation by -phi about a: x c - (a x x) sn + a (a.x)(1 - c)
        cx0, cx1, cx2 = ay * x2 - az * x1, az * x0 - ax * x2, ax * x1 - ay * x0
        y[base] = x0 * c - cx0 * sn + ax * dot * (1.0 - c)
        y[base + 1] = x1 * c - cx1 * sn + ay * dot * (1.0 - c)
        y[base + 2] = x2 * c - cx2 * sn + az * dot * (1.0 - c)


@kernel
def _tilt(y: FloatArray, src: FloatArray, phi: float) -> bool:
    """``y`` = ``src`` with the body tilted by ``phi`` about ``gamma x e3`` (the axis that
    changes ``gamma3``); ``False`` at the pole, where there is no such axis."""
    ax, ay = src[13], -src[12]  # gamma x e3 = (gamma2, -gamma1, 0)
    s = math.hypot(ax, ay)
    if s < MIN_TILT_SINE:
        for k in range(18):
            y[k] = src[k]
        return False
    _rotate(y, src, ax / s, ay / s, 0.0, phi)
    return True


@kernel
def _residual(ic: int, p: FloatArray, y: FloatArray, target: float) -> float:
    """The integral ``ic``'s deviation from ``target`` at ``y``; ``F6``'s modulo the jump of its
    ``theta`` (module docstring)."""
    res = integral_value(ic, p, y) - target
    if ic == F6:
        period = 2.0 * math.pi * abs(p[3] * p[6] * y[5])
        if period > 0.0:
            res -= period * math.floor(res / period + 0.5)
    return float(res)


@kernel
def _tilted_energy(
    code: int,
    p: FloatArray,
    y: FloatArray,
    src: FloatArray,
    phi: float,
    ic: int,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
    minv: FloatArray,
) -> float:
    """The integral ``ic`` after the tilt by ``phi`` and the linear part (into ``y``)."""
    _tilt(y, src, phi)
    _linear(code, p, y, icodes, targets, pw, ws, minv)
    return integral_value(ic, p, y)


@kernel
def _linear_natural(
    i: int, p: FloatArray, y: FloatArray, grad: FloatArray, minv: FloatArray, icodes: IntArray
) -> float:
    """The natural size of the linear integral ``icodes[i]`` at ``y``: its largest value at this
    velocity size (Cauchy-Schwarz in the metric, as :func:`_linear` measures a row)."""
    velocity_gradient(icodes[i], p, y, grad)
    size = 0.0
    for k in range(6):
        size += grad[k] * grad[k] * minv[k]
    return math.sqrt(size) * _velocity_size(y, minv)


@kernel
def _turned_residual(
    code: int,
    p: FloatArray,
    y: FloatArray,
    src: FloatArray,
    axis: FloatArray,
    phi: float,
    i: int,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
    minv: FloatArray,
) -> float:
    """The residual of the integral ``icodes[i]`` after turning ``src`` by ``phi`` about
    ``axis`` and the linear part (into ``y``), every ill-conditioned integral's row dropped:
    the rows kept do not change between the trials of one step (a row kept in one and dropped
    in the other would make their difference no slope)."""
    _rotate(y, src, axis[0], axis[1], axis[2], phi)
    _linear(code, p, y, icodes, targets, pw, ws, minv, ILL_CONDITIONED * ILL_CONDITIONED)
    return _residual(icodes[i], p, y, targets[i])


@kernel
def _attitude_step(
    code: int,
    p: FloatArray,
    y: FloatArray,
    natural: float,
    i: int,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
    minv: FloatArray,
) -> bool:
    """Correct the residual of the linear integral ``icodes[i]`` (natural size ``natural``),
    whose row the linear part dropped (near the vertical, the area integral's and Jellett's
    rows tend to Lagrange's), by turning the body: about the axis perpendicular to ``gamma``
    along which the residual (after the linear part) falls fastest, by a secant step on
    central differences. ``y`` is changed only if the residual falls to :data:`DECREASE` of
    its value; returns whether it did. ``pw``'s rows are the trials' afterwards (the caller
    solves the linear part again) and ``pw[WORK_ROWS]`` the state before the turn."""
    src, trial, axis = pw[WORK_ROWS], pw[WORK_ROWS + 1], pw[WORK_ROWS - 3]
    for k in range(18):
        src[k] = y[k]
    g0, g1, g2 = y[12], y[13], y[14]
    # two unit axes perpendicular to gamma: gamma x e_k (e_k the body axis least along gamma)
    # and gamma x that
    k0 = 0
    if abs(g1) < abs(g0):
        k0 = 1
    if abs(g2) < abs(g0) and abs(g2) < abs(g1):
        k0 = 2
    b0, b1, b2 = (0.0, g2, -g1) if k0 == 0 else ((-g2, 0.0, g0) if k0 == 1 else (g1, -g0, 0.0))
    size = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    b0, b1, b2 = b0 / size, b1 / size, b2 / size
    c0, c1, c2 = g1 * b2 - g2 * b1, g2 * b0 - g0 * b2, g0 * b1 - g1 * b0
    slopes = pw[WORK_ROWS - 3, 3:5]
    for j in range(2):
        if j == 0:
            axis[0], axis[1], axis[2] = b0, b1, b2
        else:
            axis[0], axis[1], axis[2] = c0, c1, c2
        up = _turned_residual(
            code, p, trial, src, axis, TILT_STEP, i, icodes, targets, pw, ws, minv
        )
        down = _turned_residual(
            code, p, trial, src, axis, -TILT_STEP, i, icodes, targets, pw, ws, minv
        )
        slopes[j] = (up - down) / (2.0 * TILT_STEP)
    norm2 = slopes[0] * slopes[0] + slopes[1] * slopes[1]
    # a slope within the difference's round-off is no direction (an integral the linear part
    # holds whatever the attitude, its residual that part's round-off)
    resolved = RESOLVED * ROUNDOFF * natural / TILT_STEP
    if not (norm2 > resolved * resolved and math.isfinite(norm2)):
        return False
    # the residual the trials are measured from: the state unturned, with their rows
    base = _turned_residual(code, p, trial, src, axis, 0.0, i, icodes, targets, pw, ws, minv)
    # the least turn that zeroes the linearised residual: phi = -base slopes / |slopes|^2
    f0, f1 = -base * slopes[0] / norm2, -base * slopes[1] / norm2
    phi = math.hypot(f0, f1)
    if phi > MAX_CHANGE:
        return False
    axis[0] = (f0 * b0 + f1 * c0) / phi
    axis[1] = (f0 * b1 + f1 * c1) / phi
    axis[2] = (f0 * b2 + f1 * c2) / phi
    after = _turned_residual(code, p, trial, src, axis, phi, i, icodes, targets, pw, ws, minv)
    if not abs(after) <= DECREASE * abs(base):  # a step that does not clearly help: none
        return False
    for k in range(18):
        y[k] = trial[k]
    return True


@kernel
def project_integrals(
    code: int,
    p: FloatArray,
    y: FloatArray,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
) -> int:
    """Move the state ``y`` (in place) onto the level set ``I_k(y) = targets[k]`` of the
    integrals ``icodes`` and the velocity constraints, in the kinetic-energy metric (module
    docstring). ``pw`` is a work array of shape :data:`WORK_SHAPE`.

    Returns the number of passes made (>= 1: each solves the linear part exactly, then steps
    each nonlinear integral), or ``-1`` when the corrected state is not finite;
    ``pw[WORK_ROWS - 1, 7]`` is 1 when a nonlinear integral was left for the next steps.
    """
    minv = pw[WORK_ROWS - 1, 0:6]
    minv[0] = minv[1] = minv[2] = 1.0 / p[1]
    minv[3], minv[4], minv[5] = 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    n_int = icodes.shape[0]
    grad = pw[WORK_ROWS - 2]
    passes = 0
    left = moved = False
    for _ in range(NEWTON_ITERATIONS):
        n_rows = _linear(code, p, y, icodes, targets, pw, ws, minv)
        passes += 1
        moved = False
        left = False
        for i in range(n_int):  # a linear integral whose row was dropped: the attitude
            if not LINEAR[icodes[i]]:
                continue
            res = _residual(icodes[i], p, y, targets[i])
            if abs(res) <= SETTLED * ROUNDOFF * abs(targets[i]):  # natural >= |value|
                continue
            natural = _linear_natural(i, p, y, grad, minv, icodes)
            if abs(res) <= SETTLED * ROUNDOFF * natural:
                continue
            if _attitude_step(code, p, y, natural, i, icodes, targets, pw, ws, minv):
                n_rows = _linear(code, p, y, icodes, targets, pw, ws, minv)
                if abs(_residual(icodes[i], p, y, targets[i])) < abs(res):
                    moved = True
                else:  # worse with this state's own rows: the turn is taken back
                    for k in range(18):
                        y[k] = pw[WORK_ROWS, k]
            n_rows = _linear(code, p, y, icodes, targets, pw, ws, minv)
        for i in range(n_int):
            ic = icodes[i]
            if LINEAR[ic]:
                continue
            usize = _velocity_size(y, minv)
            res = integral_value(ic, p, y) - targets[i]
            if abs(res) <= ROUNDOFF * _natural(ic, p, usize, minv):
                continue
            # the velocity step, along the gradient orthogonal to the rows
            velocity_gradient(ic, p, y, grad)
            for k in range(6):
                pw[n_rows, k] = grad[k]
            pw[n_rows, 6] = 0.0
            lam, change = 0.0, math.inf
            if _orthogonalise(pw, n_rows, n_rows, minv) > DEPENDENT * DEPENDENT:
                q = 0.0
                for k in range(6):
                    q += pw[n_rows, k] * pw[n_rows, k] * minv[k]
                if ic == ENERGY:  # quadratic along d: E + q (l + l^2 / 2) = target
                    disc = 1.0 - 2.0 * res / q
                    if disc >= 0.0:
                        lam = -2.0 * res / q / (1.0 + math.sqrt(disc))
                        change = abs(lam) * math.sqrt(q) / max(usize, 1e-300)
                else:  # Newton
                    lam = -res / q
                    change = abs(lam) * math.sqrt(q) / max(usize, 1e-300)
            phi, tilt = 0.0, math.inf
            if ic == ENERGY and not change <= SMALL_CHANGE:
                # the attitude: a secant step on the energy after a tilt (module docstring)
                src, trial = pw[WORK_ROWS], pw[WORK_ROWS + 1]
                for k in range(18):
                    src[k] = y[k]
                if _tilt(trial, src, 0.0) and _tilt(trial, src, TILT_STEP):
                    up = _tilted_energy(
                        code, p, trial, src, TILT_STEP, ic, icodes, targets, pw, ws, minv
                    )
                    down = _tilted_energy(
                        code, p, trial, src, -TILT_STEP, ic, icodes, targets, pw, ws, minv
                    )
                    slope = (up - down) / (2.0 * TILT_STEP)
                    if slope != 0.0 and math.isfinite(slope):
                        phi = -res / slope
                        # taken only if it brings the energy nearer (a small slope near a
                        # centre of U would jump the attitude the wrong way)
                        after = _tilted_energy(
                            code, p, trial, src, phi, ic, icodes, targets, pw, ws, minv
                        )
                        if abs(after - targets[i]) < abs(res):
                            tilt = abs(phi)
                # pw's rows were used by the trials: the rows of y again
                n_rows = _linear(code, p, y, icodes, targets, pw, ws, minv)
                if tilt < change and tilt <= MAX_CHANGE:
                    _tilt(trial, src, phi)
                    for k in range(18):
                        y[k] = trial[k]
                    moved = True
                    # back on the constraints, with the rows of the new attitude for the next
                    # integral of this pass
                    n_rows = _linear(code, p, y, icodes, targets, pw, ws, minv)
                    continue
                velocity_gradient(ic, p, y, grad)
                for k in range(6):
                    pw[n_rows, k] = grad[k]
                pw[n_rows, 6] = 0.0
                _orthogonalise(pw, n_rows, n_rows, minv)
            if change <= MAX_CHANGE:
                for k in range(6):
                    y[k] += lam * minv[k] * pw[n_rows, k]
                moved = True
                if n_rows < WORK_ROWS - 3:  # a row: the next integral's step leaves it alone
                    size = 0.0
                    for k in range(6):
                        size += pw[n_rows, k] * pw[n_rows, k] * minv[k]
                    size = math.sqrt(size)
                    for k in range(6):
                        pw[n_rows, k] /= size
                    n_rows += 1
            else:
                left = True
        if not moved:
            break
    if moved:  # not settled in NEWTON_ITERATIONS passes: the linear part of the last state,
        _linear(code, p, y, icodes, targets, pw, ws, minv)  # then is it on the level?
        usize = _velocity_size(y, minv)
        for i in range(n_int):
            ic = icodes[i]
            if LINEAR[ic]:
                continue
            res = integral_value(ic, p, y) - targets[i]
            if abs(res) > SETTLED * ROUNDOFF * _natural(ic, p, usize, minv):
                left = True
    pw[WORK_ROWS - 1, 7] = 1.0 if left else 0.0
    for k in range(18):
        if not math.isfinite(y[k]):
            return -1
    return passes
