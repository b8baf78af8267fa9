"""Quadrature on reference panels [-1, 1] for the axisymmetric BEM.

Unknowns live at the p Gauss-Legendre points of each panel (Nystrom-type collocation);
the density on a panel is the Lagrange interpolant through them, so smooth integrals
converge at order 2p and the surface potential at about order p + 1 on graded meshes.

Three kinds of rules:

- the panel's own Gauss rule, for well-separated (target, panel) pairs;
- *self* rules for a target node u_i on its own panel (built in :mod:`.solve` from
  :func:`gauss_log`): the panel is split at u_i and the innermost piece on each side gets a
  Gauss-Legendre rule (for the smooth part of the kernel) and a Gauss rule for the weight
  -ln(s) (for the part multiplying -ln|u - u_i|), so the logarithmic singularity of the
  ring kernels is integrated exactly in form;
- *near* rules: dyadic composite Gauss rules graded towards the point of the panel nearest
  to the target, for nearly singular pairs.

All rules are built once per order and cached.
"""

from __future__ import annotations

import functools

import numpy as np


@functools.cache
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1]."""
    u, w = np.polynomial.legendre.leggauss(n)
    u.setflags(write=False)
    w.setflags(write=False)
    return u, w


def barycentric_weights(nodes: np.ndarray) -> np.ndarray:
    diff = nodes[:, None] - nodes[None, :]
    np.fill_diagonal(diff, 1.0)
    out: np.ndarray = 1.0 / np.prod(diff, axis=1)
    return out


def lagrange_matrix(nodes: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Matrix L with L[q, k] = l_k(points[q]) for the Lagrange basis through ``nodes``."""
    points = np.asarray(points, dtype=float)
    bw = barycentric_weights(nodes)
    diff = points[..., None] - nodes
    exact = diff == 0.0
    diff = np.where(exact, 1.0, diff)
    terms = bw / diff
    L = terms / terms.sum(axis=-1, keepdims=True)
    hit = exact.any(axis=-1)
    if np.any(hit):
        L[hit] = exact[hit].astype(float)
    out: np.ndarray = L
    return out


@functools.cache
def differentiation_matrix(p: int) -> np.ndarray:
    """D[i, k] = l_k'(u_i) at the p Gauss nodes (spectral differentiation)."""
    u, _ = gauss_legendre(p)
    bw = barycentric_weights(u)
    diff = u[:, None] - u[None, :]
    np.fill_diagonal(diff, 1.0)
    D = (bw[None, :] / bw[:, None]) / diff
    np.fill_diagonal(D, 0.0)
    np.fill_diagonal(D, -D.sum(axis=1))
    D.setflags(write=False)
    out: np.ndarray = D
    return out


@functools.cache
def gauss_log(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rule for the weight -ln(s) on [0, 1] (exact for polynomials of degree 2n-1).

    Built by the discretised Stieltjes procedure on a dyadically graded composite
    Gauss-Legendre discretisation of the measure (accurate to round-off), then Golub-Welsch.
    """
    g, gw = gauss_legendre(40)
    s_parts, w_parts = [], []
    a = 1.0
    for _ in range(60):  # [2^-60, 1] in dyadic pieces, the rest below round-off
        lo = 0.5 * a
        s = lo + (a - lo) * (g + 1) / 2
        s_parts.append(s)
        w_parts.append(0.5 * (a - lo) * gw * -np.log(s))
        a = lo
    s = np.concatenate(s_parts)
    w = np.concatenate(w_parts)
    # Stieltjes: three-term recurrence of the orthogonal polynomials of the measure
    alpha = np.zeros(n)
    beta = np.zeros(n)
    p_prev = np.zeros_like(s)
    p_cur = np.ones_like(s)
    norm_prev = 1.0
    for k in range(n):
        norm = np.sum(w * p_cur**2)
        alpha[k] = np.sum(w * s * p_cur**2) / norm
        beta[k] = norm / norm_prev if k > 0 else norm
        p_next = (s - alpha[k]) * p_cur - (beta[k] if k > 0 else 0.0) * p_prev
        p_prev, p_cur, norm_prev = p_cur, p_next, norm
    J = np.diag(alpha) + np.diag(np.sqrt(beta[1:]), 1) + np.diag(np.sqrt(beta[1:]), -1)
    nodes, vecs = np.linalg.eigh(J)
    weights = beta[0] * vecs[0] ** 2
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


@functools.cache
def dyadic_rule(levels: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss rule on [0, 1] graded dyadically towards 0.

    Pieces [0, 2^-L], [2^-L, 2^-L+1], ..., [1/2, 1], each with n Gauss-Legendre points:
    a point at distance >= 2^-L from 0 is at least one piece length away from every piece.
    """
    g, gw = gauss_legendre(n)
    edges = np.concatenate([[0.0], 2.0 ** -np.arange(levels, -1, -1)])
    a, b = edges[:-1, None], edges[1:, None]
    s = (a + (b - a) * (g + 1) / 2).ravel()
    w = (0.5 * (b - a) * gw).ravel()
    s.setflags(write=False)
    w.setflags(write=False)
    return s, w
