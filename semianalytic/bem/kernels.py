"""Ring kernels of the axisymmetric Laplace problem (Part I, section 1.4, eqs. (20)-(23)).

A source ring of radius r1 at axial position x1 acts on a target (x, r).  With

    d^2 = (x - x1)^2 + (r - r1)^2,   D = (x - x1)^2 + (r + r1)^2,
    a = (x - x1)^2 + r^2 + r1^2,     m = 4 r r1 / D,   1 - m = d^2 / D,

the azimuthal integrals of the free-space Green function G = 1/(4 pi R) and of its
derivatives reduce to the complete elliptic integrals K(m), E(m) (the paper's a, b = 2 r r1
and m = 2b/(a + b); errata items 1 and 1a).  The parameter 1 - m is formed directly from
the geometry (numerical notes) and K is evaluated with ``ellipkm1``.

Every kernel here includes the ring circumference factor r1 (it is the integral over the
ring per unit meridian arc length); multiply by the arc-length element ds1.

Near the singular point the kernels are split as ``K = regular + L Q`` with
L = -ln(1 - m)/2, using K(m) = K_reg + L (2/pi) K(1 - m) and
E(m) = E_reg + L (2/pi) (K(1 - m) - E(1 - m)) (numerical notes).  ``Q`` is returned
so that quadrature can integrate the logarithm exactly.  K(1 - m) and E(1 - m) are taken
as their power series in 1 - m truncated after ``SPLIT_TERMS`` terms: the remainder
multiplies L by (1 - m)^SPLIT_TERMS, which is smooth, while the full K(1 - m) would put a
spurious singularity on the axis (where 1 - m -> 1) into both parts of the split.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ellipe, ellipk, ellipkm1

_TWO_OVER_PI = 2.0 / math.pi


def _geometry(x, r, x1, r1):
    dx = x - x1
    d2 = dx * dx + (r - r1) ** 2
    D = dx * dx + (r + r1) ** 2
    return dx, d2, D


def single_double(x, r, x1, r1, nx1, nr1):
    """Single-layer and double-layer ring kernels.

    S = integral over the ring of G r1 dtheta = r1 K(m) / (pi sqrt(D)),
    Dl = integral of dG/dn1 r1 dtheta with n1 = (nx1, nr1) the normal at the source
       = [E(m) (r1 (x - y).n1 + nr1 d^2/2) / d^2 - nr1 K(m)/2] / (pi sqrt(D)).
    The second form has no 1/r factor, so targets on the axis are fine.
    """
    dx, d2, D = _geometry(x, r, x1, r1)
    m1 = d2 / D
    K = ellipkm1(m1)
    E = ellipe(1.0 - m1)
    inv = 1.0 / (math.pi * np.sqrt(D))
    bracket = r1 * (dx * nx1 + (r - r1) * nr1) + 0.5 * nr1 * d2
    S = r1 * K * inv
    Dl = (E * bracket / d2 - 0.5 * nr1 * K) * inv
    return S, Dl


SPLIT_TERMS = 10
_C2 = np.array([(math.comb(2 * n, n) / 4**n) ** 2 for n in range(SPLIT_TERMS)])
_K_SERIES = (math.pi / 2) * _C2  # K(q) = (pi/2) sum c_n^2 q^n
_KME_Q_SERIES = (math.pi / 2) * _C2 * np.array([2 * n / (2 * n - 1) for n in range(SPLIT_TERMS)])  # K - E


def _horner(x, coef):
    """sum coef[n] x^n."""
    out = np.full_like(x, coef[-1])
    for c in coef[-2::-1]:
        out *= x
        out += c
    return out


def single_double_split(x, r, x1, r1, nx1, nr1):
    """As :func:`single_double`, plus the coefficients QS, QD of L = -ln(1 - m)/2."""
    dx, d2, D = _geometry(x, r, x1, r1)
    m1 = d2 / D
    K = ellipkm1(m1)
    E = ellipe(1.0 - m1)
    Kc = _horner(m1, _K_SERIES)  # K(1 - m), truncated
    KcmEc = _horner(m1, _KME_Q_SERIES)  # K(1 - m) - E(1 - m), truncated
    inv = 1.0 / (math.pi * np.sqrt(D))
    bracket_over_d2 = (r1 * (dx * nx1 + (r - r1) * nr1) + 0.5 * nr1 * d2) / d2
    S = r1 * K * inv
    Dl = (E * bracket_over_d2 - 0.5 * nr1 * K) * inv
    QS = r1 * _TWO_OVER_PI * Kc * inv
    QD = _TWO_OVER_PI * (KcmEc * bracket_over_d2 - 0.5 * nr1 * Kc) * inv
    return S, Dl, QS, QD


# Series of (K(m) - E(m))/m = (pi/2) sum_n c_n^2 2n/(2n - 1) m^(n-1), c_n = (2n)!/(4^n n!^2)
_KME_SERIES = np.array(
    [
        (math.pi / 2) * (math.comb(2 * n, n) / 4**n) ** 2 * (2 * n) / (2 * n - 1)
        for n in range(1, 14)
    ]
)


def k_minus_e_over_m(m):
    """(K(m) - E(m))/m without cancellation for small m (series below m = 0.05)."""
    m = np.asarray(m, dtype=float)
    small = m < 0.05
    out = np.empty_like(m)
    out[small] = _horner(m[small], _KME_SERIES)
    mb = m[~small]
    out[~small] = (ellipk(mb) - ellipe(mb)) / mb
    return out


def gradient_kernels(x, r, x1, r1):
    """Gradients at the target (x, r) of the single layer and of a vortex ring.

    Returns (Sx, Sr, Wx, Wr):

    - (Sx, Sr) = grad of S (:func:`single_double`): Part I, eq. (23) up to the factor -u and
      the density, in the cancellation-free form
      Sr = -(r1/(pi sqrt D)) [(r - r1) E/d^2 + (K - E)/(2 r)];
    - (Wx, Wr) = grad of the double layer of a density with unit arc-length derivative:
      grad W[phi] = integral grad G x (n x grad_s phi) dS, which for an axisymmetric
      density is an azimuthal vortex sheet of strength dphi/ds (Stokes' theorem on the
      closed surface), so that only 1/R^2 kernels appear.
    """
    dx, d2, D = _geometry(x, r, x1, r1)
    m1 = d2 / D
    m = 4.0 * r * r1 / D
    K = ellipkm1(m1)
    E = ellipe(1.0 - m1)
    h = k_minus_e_over_m(m)  # (K - E)/m
    sD = np.sqrt(D)
    E_d2 = E / d2
    Sx = -dx * r1 * E_d2 / (math.pi * sD)
    Sr = -(r1 / (math.pi * sD)) * ((r - r1) * E_d2 + h * 2.0 * r1 / D)
    KmE = h * m
    Wx = -(1.0 / (2 * math.pi * sD)) * (2.0 * r1 * (r - r1) * E_d2 - KmE)
    Wr = (dx / (2 * math.pi * sD)) * (2.0 * r1 * E_d2 - h * 4.0 * r1 / D)
    return Sx, Sr, Wx, Wr
