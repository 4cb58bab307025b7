"""The textbook Gaussian-process posterior, the reference the GP tests compare against."""

from __future__ import annotations

import numpy as np

from searchtrack.models.gp_regression import GPHyper


def exact_gp(x: np.ndarray, y: np.ndarray, h: GPHyper,
             xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The textbook GP posterior (R&W eqs. 2.25–2.26) by dense linear algebra."""
    k = h.kernel(x, x) + h.sigma_n**2 * np.eye(x.shape[0])
    ks = h.kernel(xs, x)
    mean = ks @ np.linalg.solve(k, y)
    var = h.sigma_f**2 - np.sum(ks * np.linalg.solve(k, ks.T).T, axis=1)
    return mean, var
