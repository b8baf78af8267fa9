"""Size effect: the energy of interaction of mesolayers near free surfaces; Part III, eqs. (17)-(28).

A nanoplate of l densely packed {111} atomic planes is a stack of j structural units (pairs of
planes c/12 apart) separated by the weak gaps c/4 apart (Part III, Fig. 3); l = 2j or 2j + 1.
A free surface carries the energy Phi_s / 2, half the interaction with the missing
neighbour.  Its share is spread over the mesolayers by repeated halving, eqs. (18)-(20),
and for two surfaces by eq. (21) (printed as "(2.5)"):

    Phi_i = Phi_0 + Phi_1 / 2^(i+1) + Phi_2 / 2^(j+2-i) + (Phi_1 + Phi_2) / (j 2^(j+1)),  i = 1..j.

The last term makes the surface shares add up exactly: sum_i (Phi_i - Phi_0) = (Phi_1 + Phi_2)/2.
Even l: both surfaces end on a full unit, Phi_1 = Phi_2 = Phi_0 (the surface energy is half the
interlayer energy; Tables 4-5 need exactly this).  Odd l: Phi_2 = Phi_0 and Phi_1 differs
(errata item 21: the paper gives no value).  We take Phi_1 = r Phi_0 with r =
``odd_surface_ratio``: the lone outer plane lost its c/12 partner, whose interaction the paper
calls "almost an order" larger, with a strength "five times higher"; default r = 5.

Lateral surfaces of a bar with an m x n basis (Part III, Fig. 4) multiply every Phi_k by the
basis factor, eqs. (24)/(27) (parallelogram, sides m a and n b) or (25)/(28) (rectangle of
equal area); eq. (26) is then eq. (21) with Phi_k -> Phi_k*.

All energies are negative numbers (bound); a factor Phi_i/Phi_0 > 1 means stronger binding.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

Basis = Literal["parallelogram", "rectangle", "none"]
BASES = ("parallelogram", "rectangle", "none")
DEFAULT_ODD_SURFACE_RATIO = 5.0


def _check_int(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}; got {value!r}")
    return int(value)


def mesolayer_count(l: int) -> int:
    """j of l = 2j or l = 2j + 1 (Part III, text after eq. (21)); l >= 2."""
    return _check_int("l", l, 2) // 2


def semi_infinite_energy(i: int, phi0: float, phi1: float) -> float:
    """Phi_i = Phi_0 + Phi_1 / 2^(i+1) for mesolayer i below one free surface of energy
    Phi_1/2; Part III, eqs. (18)-(20)."""
    i = _check_int("i", i, 1)
    return phi0 + phi1 / 2.0 ** (i + 1)


def plate_energy(i: int, j: int, phi0: float, phi1: float, phi2: float) -> float:
    """Phi_i of mesolayer i (1..j) between two free surfaces of energies Phi_1/2 and Phi_2/2;
    Part III, eq. (21) (and eq. (26) with starred energies)."""
    j = _check_int("j", j, 1)
    i = _check_int("i", i, 1)
    if i > j:
        raise ValueError(f"mesolayer i = {i} exceeds the number of mesolayers j = {j}")
    return phi0 + phi1 / 2.0 ** (i + 1) + phi2 / 2.0 ** (j + 2 - i) + (phi1 + phi2) / (j * 2.0 ** (j + 1))


def surface_energies(l: int, phi0: float, odd_surface_ratio: float = DEFAULT_ODD_SURFACE_RATIO) -> tuple[int, float, float]:
    """(j, Phi_1, Phi_2) for l atomic planes (Part III, text after eq. (21)):
    l = 2j: Phi_1 = Phi_2 = Phi_0;  l = 2j + 1: Phi_2 = Phi_0, Phi_1 = r Phi_0 (r assumed)."""
    j = mesolayer_count(l)
    if not (math.isfinite(odd_surface_ratio) and odd_surface_ratio > 0):
        raise ValueError(f"odd_surface_ratio must be positive; got {odd_surface_ratio!r}")
    if l % 2 == 0:
        return j, phi0, phi0
    return j, odd_surface_ratio * phi0, phi0


def lateral_average(m: int, n: int, phi0: float, phi_b: float) -> float:
    """Phi = (N_1 Phi_0 + N_2 Phi_B)/(N_1 + N_2), N_1 = (n-2)(m-2) inner atoms, N_2 = 2(m+n-2)
    edge atoms of an m x n basic plane; Part III, eqs. (22)-(23)."""
    m, n = _check_int("m", m, 2), _check_int("n", n, 2)
    N1 = (n - 2) * (m - 2)
    N2 = 2 * (m + n - 2)
    return (N1 * phi0 + N2 * phi_b) / (N1 + N2)


def basis_factor(m: int | None, n: int | None, basis: Basis) -> float:
    """Phi*/Phi for a bar with an m x n basic plane: Part III, eq. (24)/(27) (parallelogram)
    1 + (1/m + 1/n)/3 - 8/(9 m n), eq. (25)/(28) (rectangle) 1 + (1/m + 1/n)/3 + 5/(3 m n);
    1 for basis "none" (a plate unbounded in x, y: m, n -> infinity)."""
    if basis == "none":
        if m is not None or n is not None:
            raise ValueError("basis 'none' (a plate unbounded in x, y) takes no m, n")
        return 1.0
    if basis not in BASES:
        raise ValueError(f"basis must be one of {BASES}; got {basis!r}")
    m, n = _check_int("m", m, 2), _check_int("n", n, 2)
    edge = (1.0 / m + 1.0 / n) / 3.0
    if basis == "parallelogram":
        return 1.0 + edge - 8.0 / (9.0 * m * n)
    return 1.0 + edge + 5.0 / (3.0 * m * n)


def bar_energy(phi0: float, *, i: int | None, l: int | None, m: int | None = None, n: int | None = None,
               basis: Basis = "none", odd_surface_ratio: float = DEFAULT_ODD_SURFACE_RATIO) -> float:
    """Phi_i of mesolayer i in a bar of l atomic planes with an m x n basis; Part III,
    eqs. (26)-(28).  l = None: unbounded along the axis (infinite nanobar, only eq. (24)/(25));
    basis "none": a nanoplate (only eq. (21))."""
    s = basis_factor(m, n, basis)
    if l is None:
        if i is not None:
            raise ValueError("an unbounded bar (l = None) has no mesolayer index i")
        return s * phi0
    j, phi1, phi2 = surface_energies(l, phi0, odd_surface_ratio)
    return plate_energy(i, j, s * phi0, s * phi1, s * phi2)


def strength_factor(*, i: int | None, l: int | None, m: int | None = None, n: int | None = None,
                    basis: Basis = "none", odd_surface_ratio: float = DEFAULT_ODD_SURFACE_RATIO) -> float:
    """Phi_i / Phi_0: the factor by which the mesolayer's curve Phi(d), and so its theoretical
    strength from eq. (29), exceeds the bulk one (Part III, eqs. (26)-(29))."""
    return bar_energy(-1.0, i=i, l=l, m=m, n=n, basis=basis, odd_surface_ratio=odd_surface_ratio) / -1.0


def profile(l: int, m: int | None = None, n: int | None = None, basis: Basis = "none",
            odd_surface_ratio: float = DEFAULT_ODD_SURFACE_RATIO) -> tuple[np.ndarray, np.ndarray]:
    """(i, Phi_i/Phi_0) for all mesolayers i = 1..j of a bar or plate of l planes (Fig. 5)."""
    j = mesolayer_count(l)
    i = np.arange(1, j + 1)
    f = np.array([strength_factor(i=int(k), l=l, m=m, n=n, basis=basis, odd_surface_ratio=odd_surface_ratio) for k in i])
    return i, f


def centre_index(l: int) -> int:
    """The middle mesolayer of a plate of l planes, i = ceil(j/2) (for even j, i and
    j + 1 - i = j/2 + 1 are mirror images under eq. (21))."""
    j = mesolayer_count(l)
    return (j + 1) // 2

