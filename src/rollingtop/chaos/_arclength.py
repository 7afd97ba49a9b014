"""Pseudo-arclength continuation of the fixed points of a family of maps with integrals held
(issue 38, item 3): the numerical core of :mod:`rollingtop.chaos.continuation`, written for any
family (:class:`FamilyMap`), so the tests run it on textbook maps too.

**The system.** A fixed point of ``P_lam^K`` on the level ``I(x) = I_0(lam)`` of ``m`` integrals
(``I(P(x)) = I(x)``) solves, with one *unfolding parameter* ``beta_j`` per integral (Munoz-Almaraz,
Freire, Galan, Doedel & Vanderbauwhede, *Physica D* 181, 1-38, 2003),

    ``H(x, beta, lam) = (P^K(x) - x + G(x)^T beta,  I(x) - I_0(lam)) = 0``,

``G`` the integrals' gradients (``m x n``). Without ``beta`` the ``n`` equations ``P^K(x) = x``
hold ``m`` redundant ones (``G (P^K(x) - x) = 0`` to first order, since ``I`` is kept) and the
fixed point is not a regular zero; with it the ``n + m`` equations in ``n + m + 1`` unknowns
have a regular curve of zeros, and ``beta = 0`` on it (``G G^T beta = 0``): its size after the
corrector is the round-off of the computation, reported along the branch.

**The continuation.** Each point ``u = (x, beta, lam)`` comes with the unit tangent ``t`` of the
curve (the null vector of ``DH``, oriented as the previous one); the next is predicted at
``u + ds t`` and corrected by Newton's method on ``H = 0`` with ``t . (u - u_pred) = 0``;
``ds`` halves where the corrector fails or jumps (:data:`MAX_CORRECTION`) and grows by
:data:`GROW` after each accepted point. ``DH`` is central differences (the map in one batch
of ``2 n + 1`` points and two more for ``lam``).

**Bifurcations** are sign changes of the multipliers' test functions between two points where
each is clear of the differences' noise (:data:`TEST_NOISE`; the points need not be neighbours)
(``mu`` the eigenvalues of ``DP^K`` on the level's tangent plane, the null space of ``G``):
``prod (mu_i - 1)`` (a *fold*: a real multiplier through +1), ``prod (mu_i + 1)`` (a *period
doubling*: through -1) and ``prod_{i<j} (mu_i mu_j - 1)`` where a complex pair is on the circle's
either side (a *Neimark-Sacker* point: the pair through modulus 1), and turns of the curve in
``lam`` (the tangent's ``lam`` component changes sign: a fold, whose multiplier +1 may come as a
complex pair meeting at +1). Each is located by regula falsi on its test function along the
chord between the two points (:func:`_locate`), or reported unconverged with its bracket.
At a period doubling the branch of the orbit with twice the returns starts along the eigenvector
of the multiplier -1 (:func:`switch_to_doubled`).

This is written here rather than taken from a library: the continuation packages of Python
(PyDSTool's PyCont, pde2path's ports) continue equilibria and periodic orbits of plain ODEs
given as right-hand sides; the map here is a Poincare map of a constrained, symmetry-reduced
flow with integrals held, which none of them takes (the issue names BifurcationKit.jl and
AUTO-07p for the same reason).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from rollingtop._types import FloatArray
from rollingtop.chaos._multipliers import level_bases

__all__ = [
    "BranchPoint",
    "Detected",
    "FamilyMap",
    "RawBranch",
    "continue_branch",
    "correct",
    "switch_to_doubled",
    "unfolding",
]

#: Relative step of the central differences of the map (in ``x`` and ``lam``).
FD_STEP = 1e-6
#: The corrector has converged when ``max |H|`` is below this...
NEWTON_TOL = 1e-10
#: ... or, where it stalls at the map's round-off, its best iterate counts below this.
ACCEPT_TOL = 1e-8
#: Newton's iterations per correction at most.
NEWTON_ITERATIONS = 8
#: Growth of ``ds`` after each accepted point (up to ``ds_max``).
GROW = 1.4
#: Secant steps at most to locate a bifurcation.
LOCATE_ITERATIONS = 12
#: A located bifurcation's test function is this small relative to its values at the two
#: points it lies between...
LOCATE_TOL = 1e-7
#: ... or its bracket this narrow relative to the two points' distance (the test function's
#: own noise, the differences', may stay above the first).
LOCATE_WIDTH = 1e-7
#: A correction is refused (the step halved) where it moves the point more than this times the
#: step from the prediction, or turns the tangent by more than ``acos(MIN_COS)``: the corrector
#: would have jumped to another branch (seen near a sharp turn of a branch).
MAX_CORRECTION = 0.5
#: See :data:`MAX_CORRECTION`.
MIN_COS = 0.9
#: A test function's sign change counts only where it is at least this large at both points:
#: on a branch of elliptic orbits (a reversible system's symmetric ones) the Neimark-Sacker
#: test is 0 up to the differences' error all along, and its noise changes sign.
TEST_NOISE = 1e-5
#: The kinds of bifurcation, with the test function's name.
KINDS = ("fold", "period-doubling", "neimark-sacker")


class FamilyMap(Protocol):
    """A family of maps ``P_lam`` of ``R^n`` with ``m`` integrals (possibly none)."""

    n: int
    m: int

    def iterate(self, X: FloatArray, lam: float, K: int) -> tuple[FloatArray, FloatArray]:
        """``(P^K(X), T)``: shape (k, n), and the return times (k,) (NaN rows: failed)."""
        ...

    def integrals(self, X: FloatArray, lam: float) -> FloatArray:
        """The integrals at ``X`` (k, n): shape (k, m)."""
        ...

    def target(self, lam: float) -> FloatArray:
        """The level ``I_0(lam)``, shape (m,)."""
        ...


@dataclass(frozen=True)
class BranchPoint:
    """A corrected point of a branch: ``x`` (n,), ``beta`` (m,), ``lam``, the period, the
    multipliers on the level (complex, largest modulus first) and the Jacobian pieces."""

    x: FloatArray
    beta: FloatArray
    lam: float
    period: float
    multipliers: NDArray[np.complex128]
    DP: FloatArray
    T: FloatArray
    tangent: FloatArray
    residual: float

    @property
    def u(self) -> FloatArray:
        return np.concatenate([self.x, self.beta, [self.lam]])


@dataclass(frozen=True)
class Detected:
    """A located bifurcation: its kind (:data:`KINDS`), the point, the index of the branch
    point after it, the parameters of the two branch points it lies between, and whether its
    location converged (else ``point`` is the one of the two with the smaller test value)."""

    kind: str
    point: BranchPoint
    index: int
    bracket: tuple[float, float]
    converged: bool = True


@dataclass
class RawBranch:
    """The points of one continuation, its bifurcations, and why it stopped."""

    returns: int
    points: list[BranchPoint] = field(default_factory=list)
    detected: list[Detected] = field(default_factory=list)
    stopped: str = ""


def _step(fm: FamilyMap) -> float:
    """The family's difference step (its ``fd_step``, e.g. larger for a map computed by an
    integration at a tolerance), default :data:`FD_STEP`."""
    return float(getattr(fm, "fd_step", FD_STEP))


def _evaluate(
    fm: FamilyMap, u: FloatArray, K: int
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float] | None:
    """``(H, DH, DP, G, period)`` at ``u``; ``None`` where the map fails there."""
    n, m = fm.n, fm.m
    x, beta, lam = u[:n], u[n : n + m], float(u[-1])
    h = _step(fm) * np.maximum(1.0, np.abs(x))
    X = np.vstack([x, x + np.diag(h), x - np.diag(h)])
    out, times = fm.iterate(X, lam, K)
    lam_step = getattr(fm, "lam_step", None)
    hl = float(lam_step(lam)) if lam_step is not None else _step(fm) * max(1.0, abs(lam))
    out_l = np.vstack([fm.iterate(x[None], lam + s * hl, K)[0] for s in (1.0, -1.0)])
    if not (np.all(np.isfinite(out)) and np.all(np.isfinite(out_l))):
        return None
    DP = (out[1 : n + 1] - out[n + 1 :]).T / (2 * h)
    dP = (out_l[0] - out_l[1]) / (2 * hl)
    if m:
        V = fm.integrals(X, lam)
        G = ((V[1 : n + 1] - V[n + 1 :]) / (2 * h[:, None])).T
        V_l = np.vstack([fm.integrals(x[None], lam + s * hl) for s in (1.0, -1.0)])
        dI = (V_l[0] - V_l[1]) / (2 * hl) - (fm.target(lam + hl) - fm.target(lam - hl)) / (2 * hl)
        H = np.concatenate([out[0] - x + G.T @ beta, V[0] - fm.target(lam)])
    else:
        G = np.zeros((0, n))
        dI = np.zeros(0)
        H = out[0] - x
    DH = np.zeros((n + m, n + m + 1))
    DH[:n, :n] = DP - np.eye(n)
    DH[:n, n : n + m] = G.T
    DH[:n, -1] = dP
    DH[n:, :n] = G
    DH[n:, -1] = dI
    return H, DH, DP, G, float(times[0])


def _null(DH: FloatArray, previous: FloatArray) -> FloatArray:
    """The unit null vector of ``DH`` with a positive product with ``previous``."""
    t: FloatArray = np.linalg.svd(DH)[2][-1]
    return t if float(t @ previous) >= 0.0 else -t


def _multipliers(DP: FloatArray, G: FloatArray) -> tuple[NDArray[np.complex128], FloatArray]:
    T = level_bases(G)[0]
    mu = np.linalg.eigvals(T.T @ DP @ T).astype(np.complex128)
    return mu[np.lexsort((mu.imag, -np.abs(mu)))], T


def correct(
    fm: FamilyMap, u_pred: FloatArray, t: FloatArray, K: int, base: FloatArray | None = None
) -> BranchPoint | None:
    """Newton's method on ``H(u) = 0``, ``t . (u - base) = t . (u_pred - base)`` from ``u_pred``
    (``base`` default ``u_pred``: the hyperplane through the prediction normal to ``t``)."""
    base = u_pred if base is None else base
    level = float(t @ (u_pred - base))
    u = u_pred.copy()
    best: tuple[float, BranchPoint] | None = None
    for _ in range(NEWTON_ITERATIONS):
        ev = _evaluate(fm, u, K)
        if ev is None:
            break
        H, DH, DP, G, period = ev
        size = float(np.max(np.abs(H)))
        if best is None or size < best[0]:
            mu, T = _multipliers(DP, G)
            tangent = _null(DH, t)
            best = (
                size,
                BranchPoint(
                    u[: fm.n].copy(),
                    u[fm.n : -1].copy(),
                    float(u[-1]),
                    period,
                    mu,
                    DP,
                    T,
                    tangent,
                    size,
                ),
            )
        if size < NEWTON_TOL:
            break
        A = np.vstack([DH, t])
        b = -np.concatenate([H, [float(t @ (u - base)) - level]])
        try:
            u = u + np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(u)):
            break
    if best is None or best[0] >= ACCEPT_TOL:
        return None
    return best[1]


def tests(mu: NDArray[np.complex128]) -> dict[str, float]:
    """The test functions of :data:`KINDS` at multipliers ``mu``."""
    ns = 1.0
    for i in range(mu.size):
        for j in range(i + 1, mu.size):
            ns *= float((mu[i] * mu[j] - 1.0).real)
    return {
        "fold": float(np.prod(mu - 1.0).real),
        "period-doubling": float(np.prod(mu + 1.0).real),
        "neimark-sacker": ns,
    }


def _is_pair_crossing(a: BranchPoint, b: BranchPoint) -> bool:
    """A Neimark-Sacker test's sign change is a complex pair's (not two real multipliers'
    product passing 1, a neutral saddle)."""
    return bool(np.any(np.abs(a.multipliers.imag) > 1e-9)) and bool(
        np.any(np.abs(b.multipliers.imag) > 1e-9)
    )


def _value(kind: str, p: BranchPoint) -> float:
    """Test ``kind`` at ``p``: :func:`tests`' for the multipliers, and for a ``turn`` (a fold
    found by the curve turning back in ``lam``) the tangent's ``lam`` component."""
    return float(p.tangent[-1]) if kind == "turn" else tests(p.multipliers)[kind]


def _locate(
    fm: FamilyMap, a: BranchPoint, b: BranchPoint, kind: str, K: int
) -> tuple[BranchPoint, bool]:
    """The point between ``a`` and ``b`` where test ``kind`` vanishes, and whether the search
    converged there: regula falsi (Illinois) in the distance ``s`` along the chord from ``a``
    to ``b``, each trial corrected in the hyperplane normal to the chord at ``s``. A trial is
    refused (the search ends) where its correction moves it more than ``MAX_CORRECTION`` times
    the chord's length, its tangent turns away from the chord, or its ``lam`` leaves the
    bracket: it would be on another branch (a reversible system's symmetric orbits cross its
    orbits). Where the search does not converge, the end with the smaller test value is
    returned, not converged."""
    chord = b.u - a.u
    length = float(np.linalg.norm(chord))
    d = chord / length
    lo, hi = (0.0, _value(kind, a)), (length, _value(kind, b))
    scale = max(abs(lo[1]), abs(hi[1]))
    lam_lo, lam_hi = sorted((a.lam, b.lam))
    slack = 1e-9 * max(1.0, abs(lam_lo), abs(lam_hi))
    nearer = a if abs(lo[1]) < abs(hi[1]) else b
    side = 0
    turn = kind == "turn"  # a fold's lam lies beyond both points' and its tangent turns
    for _ in range(LOCATE_ITERATIONS):
        if hi[1] == lo[1]:
            break
        s = lo[0] - lo[1] * (hi[0] - lo[0]) / (hi[1] - lo[1])
        guess = a.u + s * d
        p = correct(fm, guess, d, K)
        if (
            p is None
            or float(np.linalg.norm(p.u - guess)) > MAX_CORRECTION * length
            or abs(float(p.tangent @ d)) < (0.5 if turn else MIN_COS)
            or not (turn or lam_lo - slack <= p.lam <= lam_hi + slack)
        ):
            break
        value = _value(kind, p)
        if abs(value) < LOCATE_TOL * scale or hi[0] - lo[0] < LOCATE_WIDTH * length:
            return p, True
        # keep the bracket; where one end stays twice in a row, halve its value (Illinois)
        if (value > 0) == (lo[1] > 0):
            lo = (s, value)
            if side == 1:
                hi = (hi[0], hi[1] / 2)
            side = 1
        else:
            hi = (s, value)
            if side == -1:
                lo = (lo[0], lo[1] / 2)
            side = -1
    return nearer, False


def _detect(
    fm: FamilyMap, branch: RawBranch, clear: dict[str, BranchPoint], new: BranchPoint, K: int
) -> None:
    """Append to ``branch`` the bifurcations between the last point where each test was clear
    of the noise (``clear``, updated) and ``new``. A turn of the curve in ``lam`` is a fold
    (its multiplier +1 may come as a complex pair meeting at +1, where the multipliers' fold test
    touches 0 without changing sign): a Neimark-Sacker sign change across a turn is that pair,
    not a Neimark-Sacker point, and is not reported."""
    before = branch.points[-1]
    found: list[tuple[str, BranchPoint]] = []
    if before.tangent[-1] * new.tangent[-1] < 0:  # oriented alike by the continuation
        found.append(("turn", before))
    for kind in KINDS:
        value = _value(kind, new)
        if abs(value) < TEST_NOISE:
            continue
        old = clear.get(kind)
        clear[kind] = new
        if old is None or (_value(kind, old) > 0) == (value > 0):
            continue
        if kind == "neimark-sacker" and (found or not _is_pair_crossing(old, new)):
            continue
        if kind == "fold" and found:  # the same fold, seen by both tests
            continue
        found.append((kind, old))
    for kind, a in found:
        located, converged = _locate(fm, a, new, kind, K)
        name = "fold" if kind == "turn" else kind
        branch.detected.append(
            Detected(name, located, len(branch.points), (a.lam, new.lam), converged)
        )


def continue_branch(
    fm: FamilyMap,
    start: BranchPoint,
    K: int,
    bounds: tuple[float, float],
    *,
    orient: FloatArray,
    ds: float,
    ds_max: float,
    max_points: int,
    keep: Callable[[BranchPoint], str] | None = None,
) -> RawBranch:
    """Continue from ``start`` (a corrected point) while ``lam`` stays in ``bounds`` (a point
    beyond them ends the branch and is not kept).

    ``orient``: the first step's direction has a positive product with it (``(0, ..., 0, 1)``:
    towards growing ``lam``). ``keep``: a check of each new point, returning a reason to stop
    (``""``: go on).
    """
    t = start.tangent if float(start.tangent @ orient) >= 0 else -start.tangent
    start = replace(start, tangent=t)
    branch = RawBranch(K, [start])
    clear = {k: start for k in KINDS if abs(_value(k, start)) >= TEST_NOISE}
    lo, hi = min(bounds), max(bounds)
    step = ds
    while len(branch.points) < max_points:
        point = branch.points[-1]
        pred = point.u + step * t
        nxt = correct(fm, pred, t, K)
        if nxt is not None and (
            float(np.linalg.norm(nxt.u - pred)) > MAX_CORRECTION * step
            or abs(float(nxt.tangent @ t)) < MIN_COS
        ):
            nxt = None
        if nxt is None:
            step /= 2
            if step < ds * 1e-4:
                branch.stopped = "the corrector failed to converge"
                return branch
            continue
        reason = keep(nxt) if keep is not None else ""
        if reason:
            branch.stopped = reason
            return branch
        if not lo <= nxt.lam <= hi:
            branch.stopped = "the parameter left its range"
            return branch
        t = nxt.tangent if float(nxt.tangent @ t) >= 0 else -nxt.tangent
        nxt = replace(nxt, tangent=t)
        _detect(fm, branch, clear, nxt, K)
        branch.points.append(nxt)
        step = min(ds_max, step * GROW)
    branch.stopped = f"{max_points} points"
    return branch


def unfolding(points: list[BranchPoint]) -> float:
    """The largest ``|beta|`` along a branch (0 in exact arithmetic)."""
    return max((float(np.max(np.abs(p.beta), initial=0.0)) for p in points), default=0.0)


def switch_to_doubled(fm: FamilyMap, at: BranchPoint, K: int, size: float) -> BranchPoint | None:
    """The first point of the branch with ``2 K`` returns that a period doubling at ``at``
    starts: from ``x + size v`` (``v`` the eigenvector of the multiplier -1) in the hyperplane
    normal to ``v``; ``None`` where the corrector returns to the ``K``-branch or fails."""
    mu_all, vecs = np.linalg.eig(at.T.T @ at.DP @ at.T)
    k = int(np.argmin(np.abs(mu_all + 1.0)))
    v = at.T @ vecs[:, k].real
    v /= np.linalg.norm(v)
    m = fm.m
    direction = np.concatenate([v, np.zeros(m + 1)])
    u0 = at.u + size * direction
    p = correct(fm, u0, direction, 2 * K)
    if p is None:
        return None
    back, _ = fm.iterate(p.x[None], p.lam, K)
    if not float(np.max(np.abs(back[0] - p.x))) > size * 1e-2:  # the K-branch itself
        return None
    return p
