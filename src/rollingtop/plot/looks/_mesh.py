"""Shaded quadrilateral meshes for the device looks: primitives in a local frame, and one
depth-sorted :class:`~mpl_toolkits.mplot3d.art3d.Poly3DCollection` lit by a fixed light.

mplot3d has no z-buffer: it paints the faces of one collection from back to front, so every
solid of a look goes into one :class:`ShadedMesh` (separate collections would be ordered as
wholes). Faces facing away from the camera are dropped (they are hidden on closed surfaces, and
half the faces cost half the time; exact under the stage's orthographic projection);
translucent faces are kept from both sides. Shading:
ambient plus Lambert plus a Blinn-Phong highlight, the light's direction given like
:class:`matplotlib.colors.LightSource` (azimuth and altitude, degrees) relative to the camera.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from matplotlib.colors import LightSource, to_rgba
from mpl_toolkits.mplot3d import Axes3D
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from rollingtop._types import FloatArray

__all__ = ["Faces", "ShadedMesh", "revolve", "rgba", "view_vector"]


def rgba(colour: str | tuple[float, float, float, float], n: int) -> FloatArray:
    """``n`` copies of ``colour`` as RGBA rows."""
    return np.tile(np.array(to_rgba(colour), dtype=np.float64), (n, 1))


def view_vector(elev: float, azim: float) -> FloatArray:
    """Unit vector from the scene towards mplot3d's camera at ``elev, azim`` (degrees)."""
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def revolve(x: FloatArray, r: FloatArray, n_phi: int, phase: float = 0.0) -> FloatArray:
    """Quads of the surface of revolution of the profile ``(x[j], r[j])`` about the local
    ``x`` axis, shape (n_phi * (len(x) - 1), 4, 3), ordered counter-clockwise seen from outside
    when ``x`` increases; ``phase`` turns it about the axis."""
    phi = phase + 2 * np.pi * np.arange(n_phi + 1) / n_phi
    px = np.broadcast_to(x[None, :], (n_phi + 1, len(x)))
    pts = np.stack([px, np.cos(phi)[:, None] * r, np.sin(phi)[:, None] * r], -1)  # (phi, x, 3)
    quads = np.stack([pts[:-1, :-1], pts[1:, :-1], pts[1:, 1:], pts[:-1, 1:]], 2)
    return quads.reshape(-1, 4, 3)


@dataclass
class Faces:
    """Quads (m, 4, 3) in the fixed frame with their colours (m, 4); ``two_sided`` faces
    (translucent ones) are kept when they face away from the camera."""

    quads: FloatArray
    colours: FloatArray
    two_sided: bool = False
    shininess: float = 40.0
    gloss: float = 0.35


@dataclass
class ShadedMesh:
    """One collection for every solid face of a look, re-lit and re-sorted every frame."""

    ax: Axes3D
    elev: float
    azim: float
    light: tuple[float, float] = (315.0, 45.0)
    ambient: float = 0.32
    collection: Poly3DCollection = field(init=False)

    def __post_init__(self) -> None:
        self.collection = Poly3DCollection(np.zeros((0, 4, 3)), linewidths=0.25, zorder=2)
        self.ax.add_collection3d(self.collection, autolim=False)
        eye = view_vector(self.elev, self.azim)
        # the light's azimuth and altitude are taken in the camera's frame (right, up, eye)
        right = np.cross([0.0, 0.0, 1.0], eye)
        right /= np.linalg.norm(right)
        up = np.cross(eye, right)
        d = LightSource(*self.light).direction  # (east, north, up) of the light
        self.eye = eye
        self.to_light = d[0] * right + d[2] * eye + d[1] * up
        self.to_light /= np.linalg.norm(self.to_light)
        half = self.to_light + eye
        self.half = half / np.linalg.norm(half)

    def shade(self, faces: Faces) -> tuple[FloatArray, FloatArray]:
        """Kept quads and their lit colours."""
        q = faces.quads
        n = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
        norm = np.linalg.norm(n, axis=1)
        n = n / np.where(norm > 0, norm, 1.0)[:, None]
        facing = n @ self.eye
        keep = facing > -1e-9 if not faces.two_sided else np.ones(len(q), bool)
        n = np.where((facing < 0)[:, None] & faces.two_sided, -n, n)[keep]
        diffuse = np.clip(n @ self.to_light, 0.0, 1.0)
        spec = faces.gloss * np.clip(n @ self.half, 0.0, 1.0) ** faces.shininess
        c = faces.colours[keep].copy()
        c[:, :3] = np.clip(
            c[:, :3] * (self.ambient + (1 - self.ambient) * diffuse)[:, None] + spec[:, None],
            0.0,
            1.0,
        )
        return q[keep], c

    def update(self, parts: list[Faces]) -> None:
        """Replace the collection's faces by ``parts``, lit and culled."""
        shaded = [self.shade(p) for p in parts]
        quads = np.concatenate([s[0] for s in shaded]) if shaded else np.zeros((0, 4, 3))
        colours = np.concatenate([s[1] for s in shaded]) if shaded else np.zeros((0, 4))
        self.collection.set_verts(quads)
        self.collection.set_facecolor(colours)
        edge = colours.copy()
        edge[:, 3] = np.minimum(edge[:, 3], 0.6 * edge[:, 3] + 0.1)
        self.collection.set_edgecolor(edge)
