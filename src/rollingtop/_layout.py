"""Layout of the state vector shared by every compiled kernel.

``y = (v[3], w[3], alpha[3], beta[3], gamma[3], X, Y, psi_nu)``, shape (18,): body-frame CoM
velocity and angular velocity, the fixed frame's unit vectors seen in the body frame, the
horizontal CoM position in the fixed frame (``docs/model.md``, "Body and frames"), and ``psi_nu``,
the azimuth in the fixed frame of the meridian constraint's direction ``nu``.

``psi_nu`` equals the axis azimuth ``psi = atan2(beta3, alpha3)`` (unwrapped) away from the
poles. In a pole case of the meridian model it is *carried* through the pole, where ``psi`` is
undefined, and after a pole passage it differs from ``psi`` by ``pi`` (the paper's ``tau, n``
and ``nu`` change sign there): see :mod:`rollingtop.contact.meridian`. A model may keep a
velocity of its own in that slot instead (:attr:`rollingtop.contact.ContactModel.slot_name`; the
``shell-rotor`` pair: the shell's spin relative to the rotor). Parameters travel as the vector
``p = (R, m, g, a3, I1, I2, I3, shell_mass, shell_inertia, c0, c1, c2, c3)``: the body's nine
(:attr:`rollingtop.SphericalTop.params`, whose four last slots are 0) and four slots of the
contact model's own parameters (:meth:`rollingtop.contact.ContactModel.params`; a 0 slot is the
model's default, so a body's ``params`` alone runs every model as it is registered).
"""

V = slice(0, 3)
W = slice(3, 6)
ALPHA = slice(6, 9)
BETA = slice(9, 12)
GAMMA = slice(12, 15)
POSITION = slice(15, 17)
PSI_NU = 17
N_STATE = 18


def state_components(slot_name: str = "psi_nu") -> list[str]:
    """Names of the 18 state components, the last as the model calls it
    (:attr:`rollingtop.contact.ContactModel.slot_name`)."""
    names = [f"{k}{i}" for k in ("v", "omega", "alpha", "beta", "gamma") for i in (1, 2, 3)]
    return [*names, "X", "Y", slot_name]


#: Entries of ``p`` that describe the body.
N_BODY_PARAMS = 9
#: Offset and number of the contact model's own parameters in ``p`` (0: the model's default).
CONTACT_PARAMS, N_CONTACT_PARAMS = 9, 4
#: Length of the parameter vector ``p`` (:attr:`rollingtop.SphericalTop.params`).
N_PARAMS = N_BODY_PARAMS + N_CONTACT_PARAMS
#: ``p`` of the body the kernels are compiled (warmed up) with: the paper's body in a light
#: shell, every entry read by some kernel (the ``shell-rotor`` kernel reads the shell's two; a
#: shorter vector made it read past the end, at random a non-finite value).
WARMUP_PARAMS = (1.0, 1.0, 1.0, 0.1, 0.3, 0.3, 0.5, 0.2, 0.15, 0.0, 0.0, 0.0, 0.0)
#: Largest number of constraint rows a contact model may impose (rubber rolling: 4).
MAX_ROWS = 4
