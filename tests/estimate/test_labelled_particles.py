"""The labelled particle belief seam: the plain store and the radio filter are
LabelledParticleBeliefs, the old import paths name the same objects, and the pure steps read any
belief of the protocol."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import searchtrack.estimate as estimate
import searchtrack.estimate.radio as radio
import searchtrack.estimate.radio.particles as radio_particles
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import labelled_particles as seam
from searchtrack.estimate.belief import LabelledParticleBelief
from searchtrack.estimate.labelled_particles import LabelledParticles, resample, update


@dataclass(frozen=True)
class Columns:
    """A test-local belief: the same numbers as separate arrays, modes as ``int64``."""

    x: FloatArray
    mode: IntArray
    tau: FloatArray
    w: FloatArray
    r: FloatArray


def _store(seed: int = 0, n_labels: int = 3, n: int = 5) -> LabelledParticles:
    rng = np.random.default_rng(seed)
    w = rng.random((n_labels, n)) + 0.1
    return LabelledParticles(rng.normal(0.0, 50.0, (n_labels, n, 4)),
                             rng.integers(0, 2, (n_labels, n)).astype(np.int8),
                             rng.random((n_labels, n)), w / w.sum(axis=1, keepdims=True),
                             rng.uniform(0.05, 0.95, n_labels))


def _columns(b: LabelledParticles) -> Columns:
    return Columns(b.x.copy(), b.mode.astype(np.int64), b.tau.copy(), b.w.copy(), b.r.copy())


def test_old_paths_name_the_seam_objects() -> None:
    """``estimate.radio``, ``estimate.radio.particles`` and the ``estimate`` face hand out the
    seam module's store and steps."""
    for face in (radio, radio_particles):
        assert face.LabelledParticles is seam.LabelledParticles
        assert face.update is seam.update and face.resample is seam.resample
    assert radio_particles.N_MODES == seam.N_MODES
    assert estimate.LabelledParticles is seam.LabelledParticles


def test_the_store_and_the_filter_are_labelled_particle_beliefs() -> None:
    """The store fits the protocol; so does the TBD-LMB filter, whose arrays are its state's."""
    from searchtrack.estimate.radio import TbdLmbFilter
    from searchtrack.estimate.radio.filter import FilterConfig
    from searchtrack.models.radio import RadioScenario

    assert isinstance(_store(), LabelledParticleBelief)
    assert not isinstance(object(), LabelledParticleBelief)
    filt = TbdLmbFilter(RadioScenario(), FilterConfig(particles_per_label=20), seed=0)
    assert isinstance(filt, LabelledParticleBelief)
    for name in ("x", "mode", "tau", "w", "r"):
        assert getattr(filt, name) is getattr(filt.state, name)
        assert not getattr(filt, name).flags.writeable


def test_update_and_resample_read_any_belief() -> None:
    """On a belief of separate arrays (``int64`` modes) the steps give exactly what they give
    on the store holding the same numbers, modes as ``int8``."""
    store = _store(4)
    other = _columns(store)
    ll = np.random.default_rng(1).normal(0.0, 3.0, store.w.shape)
    a, b = update(store, ll), update(other, ll)
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name))
    assert b.mode.dtype == np.int8
    a = resample(store, np.random.default_rng(2), 7)
    b = resample(other, np.random.default_rng(2), 7)
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name))
    assert b.mode.dtype == np.int8 and b.n_particles == 7
    np.testing.assert_array_equal(other.r, store.r)
