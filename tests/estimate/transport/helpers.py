"""Brute-force EMD by vertex enumeration, road-like grids and tiny instances for the transport
tests."""

from __future__ import annotations

import itertools
import math

import networkx as nx
import numpy as np
import scipy.sparse as sp

RTOL = 1e-9
BACKENDS = ["network", "lp"]


def vertex_minimum(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """min c·x over {a x = b, x ≥ 0} by enumerating every basic feasible solution."""
    rank = np.linalg.matrix_rank(a)
    best = math.inf
    for cols in itertools.combinations(range(a.shape[1]), rank):
        sub = a[:, cols]
        if np.linalg.matrix_rank(sub) < rank:
            continue
        x = np.linalg.lstsq(sub, b, rcond=None)[0]
        if np.allclose(sub @ x, b, atol=1e-12) and (x >= -1e-12).all():
            best = min(best, float(c[list(cols)] @ x))
    return best


def brute_emd(p: np.ndarray, q: np.ndarray, cost: np.ndarray, partial: bool) -> float:
    """EMD from the vertices of the transport polytope (4.4)–(4.7), slacks for partial."""
    m, n = cost.shape
    rows = np.kron(np.eye(m), np.ones((1, n)))
    cols = np.kron(np.ones((1, m)), np.eye(n))
    if not partial:
        p, q = p / p.sum(), q / q.sum()
        return vertex_minimum(np.vstack([rows, cols]), np.r_[p, q], cost.ravel())
    total = float(min(p.sum(), q.sum()))
    a = np.block([[rows, np.eye(m), np.zeros((m, n))],
                  [cols, np.zeros((n, m)), np.eye(n)],
                  [np.ones((1, m * n)), np.zeros((1, m + n))]])
    c = np.r_[cost.ravel(), np.zeros(m + n)]
    return vertex_minimum(a, np.r_[p, q, total], c) / total


def grid(side: int, rng: np.random.Generator, directed: bool = False) -> sp.csr_array:
    """A road-like grid with edge lengths 5–15 m (both directions stored)."""
    graph = nx.grid_2d_graph(side, side)
    adj = sp.coo_array(nx.to_scipy_sparse_array(graph, format="coo", dtype=float))
    upper = adj.row < adj.col
    i, j = adj.row[upper], adj.col[upper]
    ell = rng.uniform(5.0, 15.0, i.size)
    back = rng.uniform(5.0, 15.0, i.size) if directed else ell
    n = side * side
    return sp.csr_array((np.r_[ell, back], (np.r_[i, j], np.r_[j, i])), shape=(n, n))


TINY = [
    (np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([[0.0, 1.0], [1.0, 0.0]]), 0.0),
    (np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([[1.0, 0.0], [0.0, 1.0]]), 0.0),
    (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([[0.0, 3.0], [3.0, 0.0]]), 3.0),
    (np.array([0.3, 0.7]), np.array([0.2, 0.5, 0.3]), np.array([[1.0, 2.0, 3.0],
                                                               [4.0, 1.0, 2.0]]), None),
    (np.array([2.0, 1.0, 1.0]), np.array([1.0, 3.0]), np.array([[1.0, 1.0], [0.0, 5.0],
                                                               [2.0, 2.0]]), None),
]
