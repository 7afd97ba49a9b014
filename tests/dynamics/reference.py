"""A plain NumPy implementation of the equations of motion, written from docs/model.md for the
tests.

It does not import the package. It solves the full linear system of docs/model.md, "Dynamics", for
the unknowns ``(v', w', lambda_1..k)`` with ``numpy.linalg.solve`` (the package eliminates the
accelerations and factorises the multiplier block instead), and differentiates the constraints
in the vector form ``d/dt (vp, d) = (v' + w' x r + w x r', d) + (vp, d') = 0`` with
``nu = (e3 - gamma3 gamma)/sqrt(1 - gamma3^2)`` written exactly as in the paper (eq. 2.6).
"""

import numpy as np

E3 = np.array([0.0, 0.0, 1.0])


def directions(model, alpha, beta, gamma, w):
    """Constraint directions ``d_k`` and their time derivatives ``d_k'`` along the motion."""
    gdot = np.cross(gamma, w)
    dirs = [(gamma, gdot)]
    if model == "meridian":
        g3, g3dot = gamma[2], gdot[2]
        s = np.sqrt(1.0 - g3**2)
        sdot = -g3 * g3dot / s
        p = E3 - g3 * gamma
        pdot = -g3dot * gamma - g3 * gdot
        dirs.append((p / s, pdot / s - p * sdot / s**2))
    elif model == "parallel":
        # no slip across the axis: tau = e3 x gamma / s (the companion paper), away from the pole
        g3, g3dot = gamma[2], gdot[2]
        s = np.sqrt(1.0 - g3**2)
        sdot = -g3 * g3dot / s
        p = np.cross(E3, gamma)
        pdot = np.cross(E3, gdot)
        dirs.append((p / s, pdot / s - p * sdot / s**2))
    elif model.startswith("oblique:"):
        # no slip along d = cos(phi) nu + sin(phi) tau (issue 39), away from the pole; the angle
        # follows the colon ("oblique:0.7"): the reference does not read the package's p
        phi = float(model.split(":", 1)[1])
        g3, g3dot = gamma[2], gdot[2]
        s = np.sqrt(1.0 - g3**2)
        sdot = -g3 * g3dot / s
        pn, pndot = E3 - g3 * gamma, -g3dot * gamma - g3 * gdot
        pt, ptdot = np.cross(E3, gamma), np.cross(E3, gdot)
        p = np.cos(phi) * pn + np.sin(phi) * pt
        pdot = np.cos(phi) * pndot + np.sin(phi) * ptdot
        dirs.append((p / s, pdot / s - p * sdot / s**2))
    elif model in ("rough", "rubber"):
        # vp = 0 as f1 plus (vp, alpha) = (vp, beta) = 0 (docs/model.md; the package uses body axes)
        dirs += [(alpha, np.cross(alpha, w)), (beta, np.cross(beta, w))]
    elif model != "smooth":
        raise ValueError(model)
    return dirs


def spin_directions(model, gamma, w):
    """Directions ``e`` of the constraints on the angular velocity alone, ``(w, e) = 0``, and
    their time derivatives ``e'``: rubber rolling's ``(w, gamma) = 0`` (docs/model.md), kept by
    a reaction torque ``mu e``."""
    if model == "rubber":
        return [(gamma, np.cross(gamma, w))]
    return []


def residuals(model, p, y):
    """Constraint residuals ``(vp, d_k)``: the contact point's velocity ``vp = v + w x r`` along
    each constraint direction (zero on the constraint manifold)."""
    R, a3 = p[0], p[3]
    v, w = y[0:3], y[3:6]
    alpha, beta, gamma = y[6:9], y[9:12], y[12:15]
    vp = v + np.cross(w, -R * gamma - np.array([0.0, 0.0, a3]))
    contact = [vp @ d for d, _ in directions(model, alpha, beta, gamma, w)]
    return np.array(contact + [w @ e for e, _ in spin_directions(model, gamma, w)])


def rhs(model, p, y):
    """``y'`` and the contact force ``F`` (body frame) for state ``y`` of the package's layout.

    Only the 17 physical components are used and returned (the package's 18th, the carried
    azimuth of ``nu``, is a device of its pole handling and stays constant here).
    """
    if model == "shell-rotor":
        return shell_rotor_rhs(p, y)
    R, m, g, a3, I1, I2, I3 = p[:7]
    Iv = np.array([I1, I2, I3])
    v, w = y[0:3], y[3:6]
    alpha, beta, gamma = y[6:9], y[9:12], y[12:15]
    r = -R * gamma - np.array([0.0, 0.0, a3])
    rdot = -R * np.cross(gamma, w)
    vp = v + np.cross(w, r)
    dirs = directions(model, alpha, beta, gamma, w)
    spins = spin_directions(model, gamma, w)
    k = len(dirs) + len(spins)
    M = np.zeros((6 + k, 6 + k))
    b = np.zeros(6 + k)
    M[0:3, 0:3] = m * np.eye(3)
    M[3:6, 3:6] = np.diag(Iv)
    b[0:3] = m * np.cross(v, w) - m * g * gamma
    b[3:6] = np.cross(Iv * w, w)
    for i, (d, ddot) in enumerate(dirs):
        M[0:3, 6 + i] = -d
        M[3:6, 6 + i] = -np.cross(r, d)
        # (v', d) + (w' x r, d) = -(w x r', d) - (vp, d');  (w' x r, d) = (w', r x d)
        M[6 + i, 0:3] = d
        M[6 + i, 3:6] = np.cross(r, d)
        b[6 + i] = -np.cross(w, rdot) @ d - vp @ ddot
    for i, (e, edot) in enumerate(spins, start=len(dirs)):
        # a reaction torque mu e, no force; d/dt (w, e) = (w', e) + (w, e') = 0
        M[3:6, 6 + i] = -e
        M[6 + i, 3:6] = e
        b[6 + i] = -w @ edot
    sol = np.linalg.solve(M, b)
    lam = sol[6 : 6 + len(dirs)]
    force = sum(l * d for l, (d, _) in zip(lam, dirs, strict=True))
    dy = np.zeros(len(y))
    dy[0:6] = sol[0:6]
    dy[6:9] = np.cross(alpha, w)
    dy[9:12] = np.cross(beta, w)
    dy[12:15] = np.cross(gamma, w)
    dy[15] = v @ alpha
    dy[16] = v @ beta
    return dy, force


def _cross_matrix(a):
    """``[a]x``: ``[a]x b = a x b``."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def shell_rotor_rhs(p, y):
    """The shell-with-rotor pair by Newton-Euler for each body (not the package's Lagrangian
    formulation): ``y'`` (with the shell's relative spin ``delta = y[17]`` and its rate) and the
    contact force on the shell.

    Rotor (the body: mass ``m``, inertia ``I`` about its centre of mass ``C``) and shell (mass
    ``ms``, inertia ``Js`` about any diameter, centre ``O = C - a3 e3``), in the rotor's frame
    (angular velocity ``w``); the shell turns with ``Omega = w + delta e3``. Unknowns:
    ``v', w', delta'``, the contact force ``lambda`` at the contact point, the bearing force
    ``Fb`` of the shell on the rotor and its torque ``tau_b`` about ``C``, perpendicular to
    ``e3`` (frictionless bearing): 15 unknowns, 15 equations (the rotor's and the shell's
    momentum and angular momentum, the derivative of the rolling condition
    ``v - a3 w x e3 - R Omega x gamma = 0``).
    """
    R, m, g, a3, I1, I2, I3, ms, Js = p[:9]  # the body's (the contact slots follow)
    v, w, gamma, d = y[0:3], y[3:6], y[12:15], y[17]
    a = a3 * E3
    inertia = np.diag([I1, I2, I3])
    omega = w + d * E3
    vO = v - np.cross(w, a)
    A = np.zeros((15, 15))
    b = np.zeros(15)
    iv, iw, idl, il, iF, it = 0, 3, 6, 7, 10, 13
    e1, e2 = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    # rotor: m (v' + w x v) = -m g gamma + Fb;  I w' + w x I w = tau_b
    A[0:3, iv : iv + 3] = m * np.eye(3)
    A[0:3, iF : iF + 3] = -np.eye(3)
    b[0:3] = -m * np.cross(w, v) - m * g * gamma
    A[3:6, iw : iw + 3] = inertia
    A[3:6, it], A[3:6, it + 1] = -e1, -e2
    b[3:6] = -np.cross(w, inertia @ w)
    # shell: ms (vO' + w x vO) = -ms g gamma + lambda - Fb, vO' = v' - w' x a
    A[6:9, iv : iv + 3] = ms * np.eye(3)
    A[6:9, iw : iw + 3] = ms * _cross_matrix(a)
    A[6:9, il : il + 3] = -np.eye(3)
    A[6:9, iF : iF + 3] = np.eye(3)
    b[6:9] = -ms * np.cross(w, vO) - ms * g * gamma
    # shell about O: Js (Omega' + w x Omega) = (-R gamma) x lambda - tau_b - a x Fb
    A[9:12, iw : iw + 3] = Js * np.eye(3)
    A[9:12, idl] = Js * E3
    A[9:12, il : il + 3] = -_cross_matrix(-R * gamma)
    A[9:12, it], A[9:12, it + 1] = e1, e2
    A[9:12, iF : iF + 3] = _cross_matrix(a)
    b[9:12] = -Js * np.cross(w, omega)
    # rolling: v' - a3 w' x e3 - R Omega' x gamma - R Omega x gamma' = 0
    A[12:15, iv : iv + 3] = np.eye(3)
    A[12:15, iw : iw + 3] = a3 * _cross_matrix(E3) + R * _cross_matrix(gamma)
    A[12:15, idl] = R * np.cross(gamma, E3)
    b[12:15] = R * np.cross(omega, np.cross(gamma, w))
    x = np.linalg.solve(A, b)
    dy = np.zeros(len(y))
    dy[0:6] = x[0:6]
    dy[6:9] = np.cross(y[6:9], w)
    dy[9:12] = np.cross(y[9:12], w)
    dy[12:15] = np.cross(gamma, w)
    dy[15] = v @ y[6:9]
    dy[16] = v @ y[9:12]
    dy[17] = x[idl]
    shell_rotor_rhs.bearing_torque = x[it] * e1 + x[it + 1] * e2  # of the last call
    return dy, x[il : il + 3]


def reactions(model, p, y):
    """Normal force ``(F, gamma)`` and tangential force ``|F - (F, gamma) gamma|``."""
    _, F = rhs(model, p, y)
    gamma = y[12:15]
    N = F @ gamma
    return N, np.linalg.norm(F - N * gamma)
