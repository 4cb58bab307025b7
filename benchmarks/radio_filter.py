"""The radio-tag TBD-LMB filter (Nguyen et al.): ms per step and per likelihood evaluation.

    python benchmarks/radio_filter.py [--steps 10] [--particles 1000 5000 20000 50000]

Set-up: the paper's signal and birth model (Σ_η = 0.025² V², 4 labels), tag 0 alive at its
release site (800, 300) m with τ = 0.1 s, the UAV 100 m away; measurements drawn in the STFT
domain (:func:`~searchtrack.models.radio.stft.simulate_stft`). Birth fraction 0.1, so each
step weighs ``1.1 N`` particles per label. One BLAS thread; the likelihood kernel is serial.

Filter step (median ms over ``--steps`` steps after 3 warm-up steps that also compile the
kernel): ``predict`` (motion, births, mixing), ``lik`` (eq. 22 for every particle, with the
amplitudes and frames), ``update`` (eqs. 29–30), ``resample`` (systematic, back to ``N``),
``step`` = all four with the Numba kernel, ``step ref`` = the same with the NumPy/SciPy-i0e
reference likelihood. Likelihood only: ``kernel`` (the Numba call of
:func:`~searchtrack.estimate.radio.likelihood.label_log_likelihoods`) and ``reference``
(:func:`~searchtrack.estimate.radio.likelihood.log_likelihood_ratio_reference` per label, same
amplitudes and frames), over ``4 × 1.1 N`` particles. Target: ``step`` ≤ 100 ms at
``N`` = 50 000 (the paper's ``N_s``). Timings depend on the machine's load.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from searchtrack.estimate.radio.filter import FilterConfig
from searchtrack.estimate.radio.likelihood import (
    label_log_likelihoods,
    log_likelihood_ratio_reference,
)
from searchtrack.estimate.radio.particles import predict, resample, update
from searchtrack.estimate.radio.tbd import TbdLmbFilter
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.models.radio.signal import RadioSignal
from searchtrack.models.radio.stft import simulate_stft

FloatArray = NDArray[np.float64]
Likelihood = Callable[[RadioSignal, FloatArray, FloatArray, FloatArray, FloatArray], FloatArray]
TAG_XY = np.array([[800.0, 300.0]])
POSE = np.array([900.0, 300.0, np.pi])
PHASES = ("predict", "lik", "update", "resample")


def reference_likelihoods(signal: RadioSignal, z: FloatArray, x: FloatArray, tau: FloatArray,
                          pose: FloatArray) -> FloatArray:
    """``(Λ, N)`` eq. 22 with the NumPy/SciPy reference, label by label."""
    gamma = signal.amplitude(x[:, :, ::2], pose)
    frame = signal.frame_of(tau)
    return np.stack([log_likelihood_ratio_reference(signal, z, lab, gamma[lab], frame[lab])
                     for lab in range(signal.n_labels)])


def time_steps(scenario: RadioScenario, n: int, steps: int,
               likelihood: Likelihood) -> dict[str, float]:
    """Median ms of each phase and of the whole step over ``steps`` steps after a warm-up."""
    config = FilterConfig(particles_per_label=n)
    f = TbdLmbFilter(scenario, config, seed=0)
    state = f.labelled_particles()
    rng, zrng = np.random.default_rng(1), np.random.default_rng(2)
    times: dict[str, list[float]] = {p: [] for p in (*PHASES, "step")}
    for k in range(3 + steps):
        z = simulate_stft(scenario.signal, TAG_XY, [0], [0.1], POSE, zrng)
        t0 = time.perf_counter()
        pred = predict(state, scenario, rng, n_birth=config.n_birth)
        t1 = time.perf_counter()
        ll = likelihood(scenario.signal, z, pred.x, pred.tau, POSE)
        t2 = time.perf_counter()
        post = update(pred, ll)
        t3 = time.perf_counter()
        state = resample(post, rng, n)
        t4 = time.perf_counter()
        if k >= 3:
            for name, dt in zip((*PHASES, "step"), (t1 - t0, t2 - t1, t3 - t2, t4 - t3, t4 - t0),
                                strict=True):
                times[name].append(1e3 * dt)
    return {name: float(np.median(v)) for name, v in times.items()}


def time_likelihood(scenario: RadioScenario, n: int, repeats: int) -> tuple[float, float]:
    """Median ms of the Numba and the reference likelihood on ``4 × 1.1 n`` particles."""
    signal = scenario.signal
    rng = np.random.default_rng(3)
    m = n + FilterConfig(particles_per_label=n).n_birth
    x = np.zeros((signal.n_labels, m, 4))
    x[:, :, ::2] = TAG_XY[0] + rng.normal(0.0, 30.0, (signal.n_labels, m, 2))
    tau = rng.uniform(0.0, signal.period_s, (signal.n_labels, m))
    z = simulate_stft(signal, TAG_XY, [0], [0.1], POSE, rng)
    out = []
    for fn in (label_log_likelihoods, reference_likelihoods):
        fn(signal, z, x, tau, POSE)
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            fn(signal, z, x, tau, POSE)
            ts.append(time.perf_counter() - t0)
        out.append(1e3 * float(np.median(ts)))
    return out[0], out[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--particles", type=int, nargs="+", default=[1000, 5000, 20000, 50000])
    args = parser.parse_args()
    scenario = RadioScenario.paper()
    print("filter step, 4 labels, birth fraction 0.1 (median ms per step)")
    header = (f"{'N/label':>8s} {'predict':>8s} {'lik':>8s} {'update':>8s} {'resample':>8s} "
              f"{'step':>8s} {'step ref':>9s} {'target':>7s}")
    print(header)
    print("-" * len(header))
    with threadpool_limits(1):
        for n in args.particles:
            fast = time_steps(scenario, n, args.steps, label_log_likelihoods)
            ref = time_steps(scenario, n, args.steps, reference_likelihoods)
            target = f"{100.0:7.0f}" if n == 50_000 else f"{'':7s}"
            print(f"{n:8d} {fast['predict']:8.2f} {fast['lik']:8.2f} {fast['update']:8.2f} "
                  f"{fast['resample']:8.2f} {fast['step']:8.2f} {ref['step']:9.2f} {target}",
                  flush=True)
        print()
        print("likelihood only, 4 labels × 1.1 N particles (median ms)")
        header = (f"{'N/label':>8s} {'particles':>9s} {'kernel':>8s} {'reference':>9s} "
                  f"{'speed-up':>8s}")
        print(header)
        print("-" * len(header))
        for n in args.particles:
            kern, ref_ms = time_likelihood(scenario, n, args.steps)
            total = 4 * (n + FilterConfig(particles_per_label=n).n_birth)
            print(f"{n:8d} {total:9d} {kern:8.2f} {ref_ms:9.2f} {ref_ms / kern:7.1f}x",
                  flush=True)


if __name__ == "__main__":
    main()
