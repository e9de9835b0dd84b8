#!/usr/bin/python3
"""Lubkin's problem (1951) solved independently of knee_contact: two
elastically similar bodies in Hertz contact (radius a, pressure
p(r) = p0 sqrt(1 - r^2/a^2)) twisted against each other by a relative
rotation beta about the contact's axis, Coulomb friction mu. By symmetry
the tangential traction is circumferential, q(r), and the normal pressure
stays Hertz's (similar materials). The contact sticks in a disc r < c and
slips circumferentially in c < r < a, where q = mu p.

An axisymmetric boundary-element solve on the half-space: the surface's
circumferential displacement under a circumferential traction q(s) is
(Cerruti's point-force solution integrated round each ring; Poisson's
ratio drops out, torsion being pure shear)

  u(r) = 1 / (2 pi G) int_0^a q(s) s k(r, s) ds,
  k(r, s) = int_0^2pi cos(phi) / sqrt(r^2 + s^2 - 2 r s cos(phi)) dphi
          = 4 / (r + s) ((2 - m) K(m) - 2 E(m)) / m,  m = 4 r s / (r + s)^2,

with the complete elliptic integrals K and E (by the arithmetic-geometric
mean here: numpy only). q is constant on each of n rings (graded towards
r = a), the displacement taken at the rings' middles; k's logarithmic
singularity at s = r is integrated by Gauss-Legendre on each side of r
with s - r = L x^2. Sticking rings satisfy 2 u(r) = beta r (the relative
displacement of the two bodies is the rigid twist), slipping ones
q = mu p(r) with the slip beta r - 2 u(r) in q's direction: an active set
decides which (it settles in about 8 steps). The moment is
M = 2 pi int q r^2 dr; beta is found by bisection for M = f M_slip,
M_slip = (3 pi / 16) mu P a = pi^2 mu p0 a^3 / 8.

Checks of the solve itself (run with --check): with every ring sticking
(mu = infinity) it reproduces Mindlin's torsional stiffness of two bodies,
M = 8 G a^3 beta / 3 (q = 3 M r / (4 pi a^3 sqrt(a^2 - r^2))): measured
2.9e-4, 7.3e-5, 1.8e-5 and 4.4e-6 relative at n = 50, 100, 200, 400
(second order); the rings' full-slip moment is pi^2 / 8's to 5e-6 at
n = 400. Stick radius c / a at n = 200 and 400: 0.8136 and 0.8136 (M = 0.5
M_slip), 0.4955 and 0.4955 (0.9), 0.3387 and 0.3387 (0.97).
Usage: lubkin.py --check
"""
import math
import sys

import numpy as np

_X, _W = np.polynomial.legendre.leggauss(24)
_X, _W = (_X + 1) / 2, _W / 2


def _ellipke(m):
    """K(m), E(m) by the arithmetic-geometric mean (parameter m = k^2)."""
    a, b, s, power = np.ones_like(m), np.sqrt(1 - m), 0.5 * m, 1.0
    for _ in range(30):
        a, b, c = (a + b) / 2, np.sqrt(a * b), (a - b) / 2
        power *= 2
        s = s + power / 2 * c * c
    K = math.pi / (2 * a)
    return K, K * (1 - s)


def kernel(r, s):
    """k(r, s) above; m rounded below 1 where r = s to the last bit."""
    m = np.minimum(4 * r * s / (r + s) ** 2, 1 - 1e-16)
    K, E = _ellipke(m)
    return 4 / (r + s) * ((2 - m) * K - 2 * E) / m


class Rings:
    """n rings on [0, a] and one half-space's influence matrix A:
    u(middle_i) = sum_j A_ij q_j."""

    def __init__(self, a, G, n):
        self.edges = a * np.sin(np.linspace(0, math.pi / 2, n + 1))
        self.middle = (self.edges[:-1] + self.edges[1:]) / 2
        self.moment = 2 * math.pi * (self.edges[1:] ** 3 -
                                     self.edges[:-1] ** 3) / 3
        lo, hi = self.edges[:-1][:, None], self.edges[1:][:, None]
        x, w = _X[None, :], _W[None, :]
        self.A = np.zeros((n, n))
        for i, r in enumerate(self.middle):
            # Each ring's part below r and above r, graded towards r.
            below0, below1 = np.minimum(lo, r), np.minimum(hi, r)
            above0, above1 = np.maximum(lo, r), np.maximum(hi, r)
            s = below1 - (below1 - below0) * x * x
            row = np.sum(w * 2 * (below1 - below0) * x * s * kernel(r, s),
                         axis=1)
            s = above0 + (above1 - above0) * x * x
            row += np.sum(w * 2 * (above1 - above0) * x * s * kernel(r, s),
                          axis=1)
            self.A[i, :] = row / (2 * math.pi * G)

    def state(self, beta, bound):
        """q on the rings and their slip flags for the twist beta, q at
        most bound = mu p (per ring)."""
        slip = np.zeros(len(self.middle), bool)
        for _ in range(200):
            q = np.where(slip, bound, 0.0)
            stick = ~slip
            if stick.any():
                rhs = (beta * self.middle[stick] -
                       2 * self.A[np.ix_(stick, slip)] @ bound[slip])
                q[stick] = np.linalg.solve(2 * self.A[np.ix_(stick, stick)],
                                           rhs)
            moved = beta * self.middle - 2 * self.A @ q
            new = slip.copy()
            new[stick & (q > bound)] = True
            new[slip & (moved < 0)] = False
            if (new == slip).all():
                return q, slip
            slip = new
        raise RuntimeError("the rings' active set did not settle")


def lubkin(fractions, a, mu_p0, G, n=200):
    """For each M / M_slip in fractions: the stick radius c (the outer
    edge of the last sticking ring), the rings' middles and their q."""
    rings = Rings(a, G, n)
    bound = mu_p0 * np.sqrt(1 - (rings.middle / a) ** 2)
    m_slip = rings.moment @ bound
    results = []
    for f in fractions:
        lo, hi = 0.0, mu_p0 / G
        while rings.moment @ rings.state(hi, bound)[0] < f * m_slip:
            hi *= 2
        for _ in range(50):
            beta = (lo + hi) / 2
            if rings.moment @ rings.state(beta, bound)[0] > f * m_slip:
                hi = beta
            else:
                lo = beta
        q, slip = rings.state(hi, bound)
        stick = np.flatnonzero(~slip)
        if len(stick) and (stick != np.arange(len(stick))).any():
            raise RuntimeError("the sticking rings are not a disc")
        c = rings.edges[1:][stick].max() if len(stick) else 0.0
        results.append((c, rings.middle, q))
    return results


def check():
    failures = 0
    for n, tolerance in ((50, 1e-3), (200, 1e-4)):
        rings = Rings(1.0, 1.0, n)
        q = np.linalg.solve(2 * rings.A, rings.middle)
        error = abs(rings.moment @ q / (8 / 3) - 1)
        print("n = %d: Mindlin's stiffness, relative error %.2e <= %.0e"
              % (n, error, tolerance))
        failures += error > tolerance
    return failures


if __name__ == "__main__":
    if sys.argv[1:] != ["--check"]:
        print(__doc__)
        sys.exit(2)
    sys.exit(1 if check() else 0)
