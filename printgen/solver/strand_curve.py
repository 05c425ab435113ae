"""The force-extension curve of one curved strand between two junctions, from mechanics.

A printed strand follows an in-plane wave between two junctions a chord L apart,
y(x) = a sin(n pi x / L) (amplitude a, n half-waves). Pulled along its chord it first unbends
(bending-dominated, soft), then, its excess path length taken up, stretches as a straight
strand (axial, stiff): a stiffening law whose knee strain is about the excess path length
S / L - 1 (S the wave's arc length).

Model: a planar large-deflection beam, corotational Euler-Bernoulli elements (Crisfield's
two-node element: rigid-body motion exact, small strains in each element's own frame; error
O(h^2) in the element length h). Section: a rectangle of in-plane width b (the bead's width
across its path, in the plane of the net: the dimension that bends, I = t b^3 / 12) and
out-of-plane thickness t; axial strain and curvature integrated over the width by
Gauss-Legendre fibres, so that the material's own law (piecewise-linear stress-strain) acts
in bending as in stretching; a linear modulus is the simple case (then EA = E b t and
EI = E t b^3 / 12 exactly). Compression mirrors tension (the fibres on the inside of a bend
are compressed; a printed polymer's compressive law is taken as its tensile one).

Ends: both junctions hold the strand's end clamped in rotation and across the chord (a printed
junction is rigid; by the symmetry of a net stretched alike, a junction neither turns nor moves
sideways relative to the strand's chord); one end is pulled along the chord, the reading is
the chord force against the nominal chord strain e = (chord - L) / L.

Shallow-wave closed form (the check of the initial stiffness). By Castigliano, a shallow
strand under chord force P carries the bending moment M(x) = P (y(x) - l(x)), where the
clamped ends' reactions (a moment and a transverse force) make l(x) the least-squares line
through y on [0, L] (they minimise the complementary energy, Menabrea). With the axial part
L / EA (slopes small), the chord compliance is

    1 / k0 = L / EA + (1 / EI) integral_0^L (y - l)^2 dx = L / EA + a^2 L c_n / EI,

c_n = 1/2 - 4 / (n pi)^2 for odd n (l the mean 2 a / (n pi)) and c_n = 1/2 - 12 / (n pi)^2
for even n (l the line of slope -12 a / (n pi L) through the midpoint: the wave is odd about
it). `shallow_stiffness` gives it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix, csc_matrix
from scipy.sparse.linalg import spsolve

from .laws import Law
from .result import SolverError

ELEMENTS_PER_HALF_WAVE = 24  # default mesh: the curve converges as h^2, within 0.5 % here
ALONG_POINTS = 3  # Gauss points along an element (curvature is linear: 2 would be exact for
# a linear material; 3 for the kinks of a piecewise-linear one)
WIDTH_FIBRES = 8  # Gauss-Legendre fibres across the width (exact for a linear material)
NEWTON_TOL = 1e-10  # out-of-balance force / (EA scale): equilibrium to round-off
NEWTON_STEPS = 40  # Newton iterations per strain step at most
STRAIGHT_FRACTION = 0.9  # straightened: the tangent is within 10 % of its largest
STEP_STRAIN = 0.01  # largest chord-strain step between two equilibria (the path is followed)


@dataclass(frozen=True)
class Strand:
    """One curved strand (SI): chord L between junctions (m), wave amplitude a (m), number of
    half-waves n between the junctions, in-plane width b (m, bends), out-of-plane thickness
    t (m), and the material's stress law (a `Law` of stress in Pa per unit strain)."""

    chord: float
    amplitude: float
    half_waves: int
    width: float
    thickness: float
    stress: Law

    def __post_init__(self) -> None:
        for name in ("chord", "width", "thickness"):
            if not getattr(self, name) > 0:
                raise ValueError(f"strand {name} must be > 0, got {getattr(self, name)!r}")
        if self.amplitude < 0 or self.half_waves < 1:
            raise ValueError(f"wave needs amplitude >= 0 and half_waves >= 1, got "
                             f"{self.amplitude!r}, {self.half_waves!r}")

    @property
    def modulus(self) -> float:
        """Initial (small-strain) modulus of the stress law, Pa."""
        return float(self.stress.slopes[0])

    @property
    def ea(self) -> float:
        return self.modulus * self.width * self.thickness

    @property
    def ei(self) -> float:
        """In-plane bending stiffness E t b^3 / 12 (the width b bends), N m^2."""
        return self.modulus * self.thickness * self.width**3 / 12

    def shape(self, x: np.ndarray) -> np.ndarray:
        return self.amplitude * np.sin(self.half_waves * math.pi * x / self.chord)

    def excess(self) -> float:
        """Excess path length S / L - 1 of the wave (S its arc length)."""
        k = self.half_waves * math.pi / self.chord
        x, w = np.polynomial.legendre.leggauss(64)  # 64 points per half-wave: smooth integrand
        xs = (x + 1) / 2 * (self.chord / self.half_waves)
        slope = self.amplitude * k * np.cos(k * xs)
        return float(np.sum(w * np.sqrt(1 + slope**2)) / 2 - 1)


def shallow_stiffness(s: Strand) -> float:
    """Initial chord stiffness k0 (N/m) of a shallow wave by the closed form above."""
    n = s.half_waves
    c = 0.5 - (4.0 if n % 2 else 12.0) / (n * math.pi) ** 2
    return 1.0 / (s.chord / s.ea + s.amplitude**2 * s.chord * c / s.ei)


@dataclass(frozen=True)
class StrandCurve:
    """A strand's solved chord force (N) and tangent stiffness (N per unit strain) at chord
    strains (k,), with the initial slope (at zero), the elements used and the Newton
    iterations spent.

    Its bilinear summary: the strand counts as straightened at the first point whose tangent
    reaches STRAIGHT_FRACTION of its largest (beyond it a linear material's tangent only creeps
    toward E A L / S as the clamped ends' bent layers shrink, and a softening material's
    falls): `straight_slope` is the tangent there; `intercept`, the strain where the line of
    that tangent through that point reaches zero force (for a linear material, near where a
    straight strand of the wave's arc length would start to stretch: it tends to the excess
    path length as the strand straightens); `knee`, where that line meets the initial one
    (the knee of the bilinear law of the two slopes)."""

    strand: Strand
    strains: np.ndarray
    forces: np.ndarray
    tangents: np.ndarray
    initial_slope: float
    elements: int
    newton_iterations: int

    @property
    def final_slope(self) -> float:
        return float(self.tangents[-1])

    @property
    def straightened(self) -> int:
        """Index of the first solved point whose tangent reaches STRAIGHT_FRACTION of the
        largest."""
        return int(np.argmax(self.tangents >= STRAIGHT_FRACTION * np.max(self.tangents)))

    @property
    def straight_slope(self) -> float:
        return float(self.tangents[self.straightened])

    @property
    def intercept(self) -> float:
        i = self.straightened
        return float(self.strains[i] - self.forces[i] / self.tangents[i])

    @property
    def knee(self) -> float:
        return self.intercept / (1.0 - self.initial_slope / self.straight_slope)

    def law(self) -> Law:
        """The curve as a tension-only piecewise-linear strand law (force per chord strain):
        through every solved point, straight on beyond the last at its last tangent."""
        e, f = self.strains, self.forces
        secants = np.diff(np.concatenate([[0.0], f])) / np.diff(np.concatenate([[0.0], e]))
        return Law(tuple(float(k) for k in e[:-1]),
                   tuple(float(s) for s in secants[:-1]) + (float(secants[-1]),))


def strand_curve(s: Strand, strains: np.ndarray,
                 elements_per_half_wave: int = ELEMENTS_PER_HALF_WAVE) -> StrandCurve:
    """Solve the strand pulled along its chord to each of `strains` (increasing, > 0) in
    turn, each from the last equilibrium; SolverError when an equilibrium is not found."""
    strains = np.asarray(strains, float)
    if strains.ndim != 1 or len(strains) == 0 or np.any(np.diff(strains) <= 0) or strains[0] <= 0:
        raise ValueError(f"strains must increase from above 0, got {strains}")
    m = elements_per_half_wave * s.half_waves
    x0 = np.linspace(0.0, s.chord, m + 1)
    beam = _Beam(np.column_stack([x0, s.shape(x0)]), s)
    d = np.zeros(3 * (m + 1))
    free = np.ones(3 * (m + 1), bool)
    free[[0, 1, 2, 3 * m, 3 * m + 1, 3 * m + 2]] = False  # both ends clamped, one end pulled
    pull = 3 * m
    _, k = beam.forces(d)
    initial = _condensed_stiffness(k, free, pull) * s.chord
    forces, tangents, iterations, last = [], [], 0, 0.0
    for target in strains:
        steps = max(1, math.ceil((target - last) / STEP_STRAIN - 1e-9))
        for e in last + (target - last) * np.arange(1, steps + 1) / steps:
            d = _predict(k, d, free, pull, e * s.chord)
            d, f, k, its = _equilibrium(beam, d, free, s)
            iterations += its
        last = target
        forces.append(f[pull])
        tangents.append(_condensed_stiffness(k, free, pull) * s.chord)
    return StrandCurve(s, strains, np.array(forces), np.array(tangents), float(initial), m,
                       iterations)


def _equilibrium(beam: _Beam, d: np.ndarray, free: np.ndarray,
                 s: Strand) -> tuple[np.ndarray, np.ndarray, csc_matrix, int]:
    """Newton on the free dofs with the prescribed ones held: (d, internal forces, stiffness,
    iterations)."""
    scale = s.ea
    for it in range(1, NEWTON_STEPS + 1):
        f, k = beam.forces(d)
        r = f[free]
        if np.max(np.abs(r)) <= NEWTON_TOL * scale:
            return d, f, k, it
        step = spsolve(k[free][:, free], -r)
        d = d.copy()
        d[free] += step
    raise SolverError(f"curved strand ({s.amplitude:.3g} m amplitude, {s.half_waves} "
                      f"half-waves over a {s.chord:.3g} m chord) not in equilibrium after "
                      f"{NEWTON_STEPS} Newton iterations at chord strain "
                      f"{d[3 * (len(d) // 3 - 1)] / s.chord:.4g}: its path cannot be followed "
                      f"in steps of {STEP_STRAIN:g}; check the material law")


def _predict(k: csc_matrix, d: np.ndarray, free: np.ndarray, pull: int,
             target: float) -> np.ndarray:
    """d with the pulled dof at `target` and the free dofs moved as the tangent `k` says
    (a step of the pulled end alone would stretch its last element only, far from
    equilibrium on a fine mesh)."""
    out = d.copy()
    delta = target - d[pull]
    out[free] -= spsolve(k[free][:, free], k[free][:, [pull]].toarray().ravel() * delta)
    out[pull] = target
    return out


def _condensed_stiffness(k: csc_matrix, free: np.ndarray, pull: int) -> float:
    """Tangent chord stiffness dF/du of the pulled dof, the free dofs in equilibrium (N/m)."""
    kfp = k[free][:, [pull]].toarray().ravel()
    return float(k[pull, pull] - kfp @ spsolve(k[free][:, free], kfp))


class _Beam:
    """Corotational Euler-Bernoulli elements through `nodes` (rest shape, stress-free), three
    dofs per node (u, v, rotation)."""

    def __init__(self, nodes: np.ndarray, s: Strand) -> None:
        self.x0 = nodes
        d0 = nodes[1:] - nodes[:-1]
        self.l0 = np.hypot(d0[:, 0], d0[:, 1])
        self.beta0 = np.arctan2(d0[:, 1], d0[:, 0])
        self.xi, self.w_xi = _gauss01(ALONG_POINTS)
        z, wz = np.polynomial.legendre.leggauss(WIDTH_FIBRES)
        self.z = z * s.width / 2  # fibre positions across the width (m)
        self.dA = wz * s.width / 2 * s.thickness  # fibre areas (m^2)
        self.stress = s.stress
        m = len(self.l0)
        self.dofs = 3 * np.arange(m)[:, None] + np.arange(6)  # (m, 6) global dofs of each

    def forces(self, d: np.ndarray) -> tuple[np.ndarray, csc_matrix]:
        """(internal force vector, tangent stiffness) at the displacements d."""
        u = d.reshape(-1, 3)
        x = self.x0 + u[:, :2]
        dx = x[1:] - x[:-1]
        length = np.hypot(dx[:, 0], dx[:, 1])
        c, sn = dx[:, 0] / length, dx[:, 1] / length
        beta = np.arctan2(sn * np.cos(self.beta0) - c * np.sin(self.beta0),
                          c * np.cos(self.beta0) + sn * np.sin(self.beta0))  # beta - beta0
        t1, t2 = u[:-1, 2] - beta, u[1:, 2] - beta
        ul = (length**2 - self.l0**2) / (length + self.l0)
        fl, kl = self._local(ul, t1, t2)
        zero = np.zeros_like(c)
        r = np.column_stack([-c, -sn, zero, c, sn, zero])
        zz = np.column_stack([sn, -c, zero, -sn, c, zero])
        b = np.zeros((len(c), 3, 6))
        b[:, 0] = r
        b[:, 1] = -zz / length[:, None]
        b[:, 2] = -zz / length[:, None]
        b[:, 1, 2] += 1.0
        b[:, 2, 5] += 1.0
        fg = np.einsum("eij,ei->ej", b, fl)
        kg = np.einsum("eij,eik,ekl->ejl", b, kl, b)
        kg += fl[:, 0, None, None] * np.einsum("ei,ej->eij", zz, zz) / length[:, None, None]
        rz = np.einsum("ei,ej->eij", r, zz)
        kg += ((fl[:, 1] + fl[:, 2]) / length**2)[:, None, None] * (rz + rz.transpose(0, 2, 1))
        n = 3 * len(self.x0)
        f = np.zeros(n)
        np.add.at(f, self.dofs, fg)
        rows = np.broadcast_to(self.dofs[:, :, None], kg.shape).ravel()
        cols = np.broadcast_to(self.dofs[:, None, :], kg.shape).ravel()
        return f, coo_matrix((kg.ravel(), (rows, cols)), shape=(n, n)).tocsc()

    def _local(self, ul: np.ndarray, t1: np.ndarray,
               t2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Local forces (N, M1, M2) and their stiffness (m, 3, 3) from the fibres at the Gauss
        points: axial strain ul / l0, curvature (6 xi - 4) t1 / l0 + (6 xi - 2) t2 / l0."""
        l0 = self.l0
        bk1 = (6 * self.xi - 4)[None, :] / l0[:, None]  # (m, g)
        bk2 = (6 * self.xi - 2)[None, :] / l0[:, None]
        ea = ul / l0
        kappa = bk1 * t1[:, None] + bk2 * t2[:, None]
        eps = ea[:, None, None] - self.z[None, None, :] * kappa[:, :, None]  # (m, g, f)
        sig, et = _mirrored(self.stress, eps)
        n_sec = sig @ self.dA  # (m, g)
        m_sec = -(sig * self.z) @ self.dA
        d_nn = et @ self.dA
        d_nm = -(et * self.z) @ self.dA
        d_mm = (et * self.z**2) @ self.dA
        w = self.w_xi[None, :] * l0[:, None]  # (m, g) integration weights along
        # rows of B (generalised strains per local dof): axial [1/l0, 0, 0], bending
        # [0, bk1, bk2]; local forces B^T (N, M), stiffness B^T D B, integrated along
        ba = np.zeros((*bk1.shape, 3))
        ba[..., 0] = 1 / l0[:, None]
        bm = np.stack([np.zeros_like(bk1), bk1, bk2], axis=-1)
        fl = np.einsum("eg,egi->ei", w * n_sec, ba) + np.einsum("eg,egi->ei", w * m_sec, bm)
        kl = (np.einsum("eg,egi,egj->eij", w * d_nn, ba, ba)
              + np.einsum("eg,egi,egj->eij", w * d_nm, ba, bm)
              + np.einsum("eg,egi,egj->eij", w * d_nm, bm, ba)
              + np.einsum("eg,egi,egj->eij", w * d_mm, bm, bm))
        return fl, kl


def _mirrored(stress: Law, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stress and tangent modulus of a tension law mirrored into compression."""
    sig, et = stress.force_and_tangent(np.abs(eps))
    et = np.where(eps == 0, float(stress.slopes[0]), et)
    return np.sign(eps) * sig, et


def _gauss01(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2
