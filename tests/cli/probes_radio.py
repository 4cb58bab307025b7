"""Malformed inputs for ``searchtrack radio simulate|track|mission`` that once exhausted memory,
overflowed or ran without end: each must now be answered with one line naming the file and the
key (or the option), exit status 2 and nothing written.

Probes have the form of :mod:`tests.cli.probes` (``(name, build, status, words)``).
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np

from tests.cli.probes import Build, Probe, _radio_sim, _radio_track, _write


def _radio_mission_with(text: str, *extra: str) -> Build:
    """``radio mission`` on scenario ``text`` (20 particles, a folder ``out``)."""

    def build(tmp: Path) -> list[str]:
        return ["radio", "mission", str(_write(tmp / "s.toml", text)), "--particles", "20",
                "--out", str(tmp / "out"), *extra]

    return build


def npy_header(shape: tuple[int, ...], descr: str = "<f4") -> bytes:
    """A version 1.0 ``.npy`` header declaring ``shape`` of ``descr``."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False,
                                               "shape": shape})
    return buf.getvalue()


def replace_member(path: Path, member: str, data: bytes) -> None:
    """Rewrite the zip archive ``path`` with ``member`` holding ``data``."""
    with zipfile.ZipFile(path) as src:
        members = [(info.filename, src.read(info)) for info in src.infolist()]
    with zipfile.ZipFile(path, "w") as dst:
        for name, body in members:
            dst.writestr(name, data if name == member else body)


def _header_bomb(shape: tuple[int, ...]) -> Build:
    """A small RUN.npz whose ``frames`` header declares ``shape`` over 4 kB of data."""

    def build(tmp: Path) -> list[str]:
        argv = _radio_track(lambda a: None)(tmp)
        replace_member(Path(argv[2]), "frames.npy", npy_header(shape) + bytes(4000))
        return argv

    return build


RADIO_PROBES: list[Probe] = [
    ("radio simulate: duration_s = 1e300", _radio_sim("duration_s = 1e300\n"), 2,
     ("s.toml", "duration_s")),
    ("radio simulate: fft_size = 100000000", _radio_sim("[signal]\nfft_size = 100000000\n"), 2,
     ("s.toml", "signal.fft_size")),
    ("radio simulate: --noise 1e300", _radio_sim("duration_s = 2.0\n", "--noise", "1e300"), 2,
     ("--noise",)),
    ("radio simulate: receiver_gain_db = 1e300", _radio_sim(
        "duration_s = 2.0\n[signal]\nreceiver_gain_db = 1e300\n"), 2,
     ("s.toml", "signal.receiver_gain_db")),
    ("radio simulate: half_width_bins = 10**12", _radio_sim(
        "duration_s = 2.0\n[signal]\nhalf_width_bins = 1000000000000\n"), 2,
     ("s.toml", "signal.half_width_bins")),
    ("radio mission: n_headings = 100000000", _radio_mission_with(
        "duration_s = 2.0\n[uav]\nn_headings = 100000000\n"), 2, ("s.toml", "uav.n_headings")),
    ("radio mission: plan_interval_s = 1e300", _radio_mission_with(
        "duration_s = 2.0\n[uav]\nplan_interval_s = 1e300\n"), 2,
     ("s.toml", "uav.plan_interval_s")),
    ("radio mission: cv_accel_std = 1e300", _radio_mission_with(
        "duration_s = 2.0\n[motion]\ncv_accel_std = 1e300\n"), 2,
     ("s.toml", "motion.cv_accel_std")),
    ("radio mission: --plan-particles 10**13", _radio_mission_with(
        "duration_s = 2.0\n", "--plan-particles", "10000000000000"), 2, ("plan_particles",)),
    ("radio mission: --horizon 10**6", _radio_mission_with(
        "duration_s = 2.0\n", "--horizon", "1000000"), 2, ("horizon",)),
    ("radio track: frames header of 10 PiB", _header_bomb((10**11, 111, 256)), 2,
     ("run.npz", "frames", "declares")),
    ("radio track: --particles 10**13", _radio_track(lambda a: None, "--particles",
                                                     "10000000000000"), 2, ("--particles",)),
]
