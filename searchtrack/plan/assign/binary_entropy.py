"""``E[h_b(π)]`` of one binary measurement of a Poisson RFS, with a bounded error (paper 003 §2.5).

Given the targets ``X`` the measurement reports nothing with probability
``π(X) = e^{−λ_c} Π_{x∈X} a(x)``, ``a = 1 − p_d``. Write ``π = e^{−L}`` with
``L = λ_c + Σ_i N_i b_i``, ``b_i = −log(1 − p_d(x_i))`` and ``N_i ~ Poisson(w_i)`` independent;
its Laplace transform is closed: ``M(s) = E π^s = exp(−s λ_c + Σ_i w_i (e^{−s b_i} − 1))``.

* ``E[−π log π] = e^{−λ_c} G (λ_c − Σ_i w_i a_i log a_i)``, ``G = exp(−Σ_i w_i p_d(x_i))``
  (the Mecke formula).
* ``E[−(1 − π) log(1 − π)] = Σ_{k≥1} φ(k)`` with ``φ(s) = (M(s) − M(s + 1)) / s``, from
  ``−log(1 − π) = Σ_k π^k / k``. ``φ`` is completely monotone on ``s > 0`` (a product of the
  Laplace transforms ``1/s`` and ``E[e^{−sL}(1 − e^{−L})]``), so it is positive, decreasing and
  convex with ``φ''`` decreasing.

The series converges slowly where targets are nearly invisible (``b_i ≪ 1``): it needs about
``1 / b`` terms. So the sum is split at ``a``: the head ``Σ_{k<a} φ(k)`` term by term, the tail by
the Euler–Maclaurin formula ``Σ_{k≥a} φ(k) = ∫_a^∞ φ + φ(a)/2 − φ'(a)/12 + R`` with ``φ'`` in
closed form; for a completely monotone ``φ`` the remainder lies between 0 and the first omitted
term ``φ'''(a)/720``, and ``φ'''(a) ≥ φ(a) − 3φ(a−1) + 3φ(a−2) − φ(a−3)`` (``φ''''`` ≥ 0), so
``a`` doubles until that bound is below the tolerance. The integral is taken
in ``u = log s`` by Gauss–Legendre panels, its quadrature error estimated by a second rule of
lower order, and cut at ``S`` where ``∫_S^∞ φ ≤ (M(S) − M(∞)) / S``. Where the plain tail bound
``Σ_{k≥a} φ(k) ≤ (M(a) − M(∞)) / a`` is already below the tolerance the integral is skipped.
Every part's error is added into :attr:`Bounded.error`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from searchtrack.core.types import FloatArray

#: Absolute error aimed at for one measurement's ``E[h_b(π)]`` (nats).
TOLERANCE = 1e-12
_HEAD_START = 16
_HEAD_MAX = 4096
_PANEL_U = 0.25
_PANELS_MAX = 320
_NODES_HI, _W_HI = np.polynomial.legendre.leggauss(12)
_NODES_LO, _W_LO = np.polynomial.legendre.leggauss(7)


class Bounded(NamedTuple):
    """A value and a bound on its absolute error."""

    value: float
    error: float


class _Transform:
    """``M(s) = E π^s`` of one measurement row (particles with ``p_d > 0``)."""

    def __init__(self, pd_row: FloatArray, weights: FloatArray, clutter_rate: float) -> None:
        keep = pd_row > 0.0
        pd = pd_row[keep]
        self.w = weights[keep]
        with np.errstate(divide="ignore"):
            self.b = -np.log1p(-pd)  # +inf where p_d = 1
        self.lam = clutter_rate
        self.pd = pd
        self.total = float(np.sum(self.w))

    def _sums(self, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``Σ_i w_i e^{−s b_i}`` and ``Σ_i w_i e^{−s b_i} (e^{−b_i} − 1)`` at ``(K,)`` points."""
        e_sum = np.zeros(s.shape[0])
        d_sum = np.zeros(s.shape[0])
        chunk = max(1, (1 << 20) // max(1, s.shape[0]))
        for lo in range(0, self.b.shape[0], chunk):
            b = self.b[lo:lo + chunk]
            decay = np.exp(-np.outer(s, b))
            w = self.w[lo:lo + chunk]
            e_sum += decay @ w
            d_sum += decay @ (w * np.expm1(-b))
        return e_sum, d_sum

    def drop(self, s: FloatArray) -> FloatArray:
        """``M(s) − M(s + 1) = M(s) (1 − e^{−λ_c + Σ_i w_i e^{−s b_i}(e^{−b_i} − 1)})`` at
        ``(K,)`` points ``s ≥ 1``, without cancellation."""
        e_sum, d_sum = self._sums(s)
        log_m = -s * self.lam + e_sum - self.total
        out: FloatArray = np.exp(log_m) * -np.expm1(d_sum - self.lam)
        return out

    def drop_slope(self, s: float) -> float:
        """``d/ds (M(s) − M(s + 1)) = ψ'(s) (M(s) − M(s+1)) + (ψ'(s) − ψ'(s+1)) M(s+1)`` with
        ``ψ = log M``, ``ψ'(s) = −λ_c − Σ_i w_i b_i e^{−s b_i}``."""
        finite = np.isfinite(self.b)
        b = self.b[finite]
        w = self.w[finite]
        wbe = w * b * np.exp(-s * b)
        d_psi = -self.lam - float(np.sum(wbe))
        step = float(np.sum(wbe * np.expm1(-b)))  # ψ'(s) − ψ'(s + 1)
        e_sum, d_sum = self._sums(np.array([s]))
        m_s = math.exp(-s * self.lam + float(e_sum[0]) - self.total)
        drop = m_s * -math.expm1(float(d_sum[0]) - self.lam)
        return d_psi * drop + step * (m_s - drop)

    def excess(self, s: FloatArray) -> FloatArray:
        """``M(s) − M(∞)`` at ``(K,)`` points (``M(∞) = e^{−Σ w_i}`` without clutter, else 0)."""
        e_sum, _ = self._sums(s)
        out: FloatArray
        if self.lam == 0.0:
            out = math.exp(-self.total) * np.expm1(e_sum)
        else:
            out = np.exp(-s * self.lam + e_sum - self.total)
        return out

    def pi_log_pi(self) -> float:
        """``E[−π log π]`` by the Mecke formula."""
        a = 1.0 - self.pd
        finite = np.isfinite(self.b)
        a_log_a = np.where(finite, -a * np.where(finite, self.b, 0.0), 0.0)
        g = math.exp(-float(np.sum(self.w * self.pd)))
        return math.exp(-self.lam) * g * (self.lam - float(np.sum(self.w * a_log_a)))


def _phi(transform: _Transform, s: FloatArray) -> FloatArray:
    """``φ(s) = (M(s) − M(s + 1)) / s``, the difference formed without cancellation."""
    out: FloatArray = transform.drop(s) / s
    return out


def _tail_integral(transform: _Transform, a: float, tol: float) -> Bounded:
    """``∫_a^∞ φ(s) ds`` in ``u = log(s / a)`` by Gauss–Legendre panels up to the first panel
    end ``S`` with ``(M(S) − M(∞)) / S`` below a tenth of ``tol``."""
    ends = a * np.exp(_PANEL_U * np.arange(1, _PANELS_MAX + 1))
    rest = transform.excess(ends) / ends
    below = np.flatnonzero(rest < 0.1 * tol)
    panels = int(below[0]) + 1 if below.size else _PANELS_MAX
    half = 0.5 * _PANEL_U
    centres = _PANEL_U * np.arange(panels) + half
    u = np.concatenate([(centres[:, None] + half * _NODES_HI).ravel(),
                        (centres[:, None] + half * _NODES_LO).ravel()])
    s = a * np.exp(u)
    vals = _phi(transform, s) * s  # ds = s du
    n_hi = panels * _NODES_HI.size
    hi = half * (vals[:n_hi].reshape(panels, -1) @ _W_HI)
    lo = half * (vals[n_hi:].reshape(panels, -1) @ _W_LO)
    return Bounded(float(np.sum(hi)), float(np.sum(np.abs(hi - lo)) + rest[panels - 1]))


def conditional_entropy_bounded(pd_row: FloatArray, weights: FloatArray,
                                clutter_rate: float = 0.0, tol: float = TOLERANCE) -> Bounded:
    """``E_X[h_b(π(X))]`` (nats) of one binary measurement and a bound on its error."""
    transform = _Transform(np.asarray(pd_row, dtype=np.float64),
                           np.asarray(weights, dtype=np.float64), float(clutter_rate))
    if transform.w.size == 0 and transform.lam == 0.0:
        return Bounded(0.0, 0.0)
    first = transform.pi_log_pi()
    a = _HEAD_START
    while True:
        phi = _phi(transform, np.arange(1.0, a + 1.0))  # φ(1) … φ(a)
        head = float(np.sum(phi[:-1]))
        plain = float(transform.excess(np.array([float(a)]))[0]) / a
        if plain <= tol:
            # Σ_{k≥a} φ(k) ∈ [0, plain]: take the middle.
            return Bounded(first + head + 0.5 * plain, 0.5 * plain)
        # Euler–Maclaurin remainder after the φ' term: between φ'''(a)/720 and 0, and
        # φ'''(a) is at least the backward third difference (φ'''' ≥ 0).
        third = float(phi[-1] - 3.0 * phi[-2] + 3.0 * phi[-3] - phi[-4])
        remainder = max(0.0, -third) / 720.0
        if remainder <= 0.5 * tol or a >= _HEAD_MAX:
            break
        a *= 2
    integral = _tail_integral(transform, float(a), tol)
    slope = (transform.drop_slope(float(a)) - float(phi[-1])) / a  # φ'(a) = (D' − φ) / a
    value = first + head + integral.value + 0.5 * float(phi[-1]) - slope / 12.0 - 0.5 * remainder
    return Bounded(value, 0.5 * remainder + integral.error)
