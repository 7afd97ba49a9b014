"""Layout of the state vector shared by every compiled kernel.

``y = (v[3], w[3], alpha[3], beta[3], gamma[3], X, Y)``, shape (17,): body-frame CoM velocity
and angular velocity, the fixed frame's unit vectors seen in the body frame, and the horizontal
CoM position in the fixed frame (``MODEL.md``, "Body and frames"). Parameters travel as the
vector ``p = (R, m, g, a3, I1, I2, I3)`` (:attr:`rollingtop.SphericalTop.params`).
"""

V = slice(0, 3)
W = slice(3, 6)
ALPHA = slice(6, 9)
BETA = slice(9, 12)
GAMMA = slice(12, 15)
POSITION = slice(15, 17)
N_STATE = 17
#: Largest number of constraint rows a contact model may impose (rubber rolling: 4).
MAX_ROWS = 4
