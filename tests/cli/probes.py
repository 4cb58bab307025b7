"""Malformed inputs for every command, each with the exit status and the words its one-line
error must contain (shared by the bad-input tests and ``benchmarks/cli_probes.py``).

A probe is ``(name, build, status, words)``: ``build(tmp)`` writes what the probe needs under
``tmp`` and returns the command line (without the program name); ``words`` must appear in the
error output (``{tmp}`` is replaced by the folder).
"""

from __future__ import annotations

import bz2
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

OPTW = Path(__file__).parents[2] / "searchtrack" / "data" / "optw"
C101 = OPTW / "c101.txt"
SCENARIOS = Path(__file__).parents[2] / "searchtrack" / "data" / "scenarios"

Build = Callable[[Path], list[str]]
Probe = tuple[str, Build, int, tuple[str, ...]]

GOOD_SCENARIO = ('name = "probe"\nduration_s = 3.0\nseed = 1\n[map]\n'
                 'grid = { rows = 4, cols = 4, block_m = 100.0 }\n[uavs]\ncount = 2\n'
                 '[targets]\ncount = 2\n')
GOOD_SCANS: dict[str, object] = {
    "area": [[0, 100], [0, 100]], "dt": 1.0,
    "sensor": {"pd": 0.9, "sigma": 5.0, "clutter_rate": 1.0},
    "motion": {"model": "cv", "q": 0.5}, "scans": [[[10, 10]], [[12, 11], [80, 80]]]}


def _write(path: Path, data: str | bytes) -> Path:
    if isinstance(data, bytes):
        path.write_bytes(data)
    else:
        path.write_text(data, encoding="utf-8")
    return path


def _instance(tmp: Path, edit: Callable[[list[str]], list[str]], name: str = "bad.txt") -> str:
    lines = C101.read_text(encoding="utf-8").splitlines()
    return str(_write(tmp / name, "\n".join(edit(lines)) + "\n"))


def _set_field(line: str, index: int, value: str) -> str:
    toks = line.split()
    toks[index] = value
    return " ".join(toks)


def _scenario(tmp: Path, text: str) -> str:
    return str(_write(tmp / "s.toml", text))


def _scans(tmp: Path, change: Callable[[dict[str, object]], None]) -> str:
    data = json.loads(json.dumps(GOOD_SCANS))
    change(data)
    return str(_write(tmp / "scans.json", json.dumps(data)))


def _solve(*extra: str) -> Build:
    return lambda tmp: ["optw", "solve", str(C101), "--time-limit", "0.5", *extra]


def _mission(text: str, *extra: str) -> Build:
    return lambda tmp: ["mission", "run", _scenario(tmp, text), "--out", str(tmp / "out"),
                        *extra]


def _track(change: Callable[[dict[str, object]], None], *extra: str) -> Build:
    return lambda tmp: ["track", _scans(tmp, change), "--out", str(tmp / "est.json"), *extra]


def _nothing(data: dict[str, object]) -> None:
    return None


def _setter(path: str, value: object) -> Callable[[dict[str, object]], None]:
    keys = path.split(".")

    def change(data: dict[str, object]) -> None:
        obj: object = data
        for key in keys[:-1]:
            obj = obj[key]  # type: ignore[index]
        obj[keys[-1]] = value  # type: ignore[index]

    return change


def _radio_sim(text: str, *extra: str) -> Build:
    def build(tmp: Path) -> list[str]:
        return ["radio", "simulate", str(_write(tmp / "s.toml", text)), "--out",
                str(tmp / "r.npz"), *extra]

    return build


def _radio_track(change: Callable[[dict[str, Any]], None], *extra: str) -> Build:
    """A two-interval RUN.npz of the paper scenario, changed by ``change``."""

    def build(tmp: Path) -> list[str]:
        import numpy as np

        from searchtrack.models.radio import RadioScenario

        sc = RadioScenario.paper()
        sig = sc.signal
        arrays: dict[str, Any] = {
            "frames": np.full((2, sig.frames, sig.fft_size), 0.1, dtype=np.float32),
            "uav_poses": np.zeros((2, 3)), "times_s": np.array([1.0, 2.0]),
            "labels": np.arange(sig.n_labels), "frequencies_hz": np.array(sig.frequencies_hz),
            "scenario": np.array(json.dumps(sc.to_dict())), "seed": np.array(0)}
        change(arrays)
        path = tmp / "run.npz"
        with path.open("wb") as fh:
            np.savez(fh, **arrays)
        return ["radio", "track", str(path), "--out", str(tmp / "e.json"), *extra]

    return build


def _radio_mission(*extra: str) -> Build:
    def build(tmp: Path) -> list[str]:
        return ["radio", "mission", str(_write(tmp / "s.toml", "duration_s = 2.0\n")),
                "--particles", "20", "--out", str(tmp / "out"), *extra]

    return build


PROBES: list[Probe] = [
    # ---- optw solve: files
    ("optw: missing file", lambda t: ["optw", "solve", str(t / "nope.txt")], 2,
     ("nope.txt", "no such file")),
    ("optw: a folder", lambda t: ["optw", "solve", str(t)], 2, ("not a regular file",)),
    ("optw: /dev/zero", lambda t: ["optw", "solve", "/dev/zero"], 2,
     ("/dev/zero", "not a regular file")),
    ("optw: not UTF-8", lambda t: ["optw", "solve", str(_write(t / "x.txt", b"1 1 1 1\n\xff"))],
     2, ("x.txt", "not UTF-8")),
    ("optw: truncated .bz2", lambda t: ["optw", "solve", str(_write(
        t / "c.txt.bz2", bz2.compress(C101.read_bytes())[:500]))], 2,
     ("c.txt.bz2", "truncated or corrupt")),
    ("optw: empty file", lambda t: ["optw", "solve", str(_write(t / "e.txt", ""))], 2,
     ("e.txt", "too short")),
    ("optw: header of 3 fields", lambda t: ["optw", "solve", _instance(
        t, lambda ls: ["1 1 100", *ls[1:]])], 2, ("bad.txt", "line 1", "not an OPTW instance")),
    ("optw: a scenario file", lambda t: ["optw", "solve", str(SCENARIOS / "demo.toml")], 2,
     ("demo.toml", "not an OPTW instance", "'k v N t'")),
    ("optw: NaN coordinate", lambda t: ["optw", "solve", _instance(
        t, lambda ls: [*ls[:3], _set_field(ls[3], 1, "nan"), *ls[4:]])], 2,
     ("bad.txt", "line 4", "not a finite number")),
    ("optw: window closes before it opens", lambda t: ["optw", "solve", _instance(
        t, lambda ls: [*ls[:3], _set_field(ls[3], -1, "1"), *ls[4:]])], 2,
     ("bad.txt", "line 4", "window closes")),
    ("optw: vertex line missing", lambda t: ["optw", "solve", _instance(t, lambda ls: ls[:-1])],
     2, ("bad.txt", "vertex lines")),
    ("optw: --seed 3000000000", _solve("--seed", "3000000000"), 2, ("--seed", "2147483647")),
    ("optw: --seed -1", _solve("--seed", "-1"), 2, ("--seed",)),
    ("optw: --decimals -1", _solve("--decimals", "-1"), 2, ("--decimals", "[0, 6]")),
    ("optw: --decimals 99", _solve("--decimals", "99"), 2, ("--decimals", "[0, 6]")),
    ("optw: --vehicles 1000", _solve("--vehicles", "1000"), 2,
     ("vehicles=1000", "100 customers")),
    ("optw: --vehicles 0", _solve("--vehicles", "0"), 2, ("--vehicles",)),
    ("optw: --time-limit 0", _solve("--time-limit", "0"), 2, ("--time-limit",)),
    ("optw: --time-limit nan", _solve("--time-limit", "nan"), 2, ("--time-limit",)),
    ("optw: unknown backend", _solve("--backend", "simplex"), 2, ("--backend", "simplex")),
    ("optw: labelling with 2 vehicles", _solve("--backend", "labelling", "--vehicles", "2"), 2,
     ("backend='labelling'", "single-vehicle")),
    ("optw: --json is a folder", lambda t: [*_solve()(t), "--json", str(t)], 2,
     ("--json", "is a folder")),
    ("optw: --json under a file", lambda t: [*_solve()(t), "--json",
                                            str(_write(t / "f", "x") / "r.json")], 2,
     ("--json", "is a file, not a folder")),
    # ---- optw bench
    ("bench: not a folder", lambda t: ["optw", "bench", str(C101)], 2, ("not a directory",)),
    ("bench: no instances", lambda t: ["optw", "bench", str(t)], 2, ("no instance files",)),
    ("bench: optima.csv without columns", lambda t: [
        "optw", "bench", str(_bench_dir(t, "name,value\nc101,1\n")), "--time-limit", "0.1"], 2,
     ("optima.csv", "needs columns")),
    ("bench: optima.csv with a word", lambda t: [
        "optw", "bench", str(_bench_dir(t, "instance,optimum\nc101,many\n")),
        "--time-limit", "0.1"], 2, ("optima.csv", "line 2", "not a number")),
    ("bench: optima.csv not UTF-8", lambda t: [
        "optw", "bench", str(_bench_dir(t, b"instance,optimum\n\xff,1\n")),
        "--time-limit", "0.1"], 2, ("optima.csv", "not UTF-8")),
    ("bench: one unreadable instance", lambda t: [
        "optw", "bench", str(_bench_dir(t, None, bad=True)), "--time-limit", "0.2",
        "--backend", "ils"], 1, ("bad", "ERROR")),
    # ---- mission run
    ("mission: missing scenario", lambda t: ["mission", "run", str(t / "no.toml")], 2,
     ("no.toml", "no such file")),
    ("mission: not UTF-8", lambda t: ["mission", "run", str(_write(t / "s.toml", b"\xff\xfe"))],
     2, ("s.toml", "not UTF-8")),
    ("mission: not TOML", _mission("name = \n"), 2, ("s.toml", "not valid TOML")),
    ("mission: unknown key", _mission(GOOD_SCENARIO + "[sensor]\naltitud_m = 3\n"), 2,
     ("s.toml", "sensor.altitud_m")),
    ("mission: wrong type", _mission(GOOD_SCENARIO.replace("count = 2\n[targets]",
                                                          "count = \"two\"\n[targets]")), 2,
     ("s.toml", "uavs.count")),
    ("mission: dt_s = 1e300", _mission(GOOD_SCENARIO.replace("seed = 1\n",
                                                             "seed = 1\ndt_s = 1e300\n")), 2,
     ("s.toml", "dt_s")),
    ("mission: duration_s = 1e300", _mission(GOOD_SCENARIO.replace("duration_s = 3.0",
                                                                   "duration_s = 1e300")), 2,
     ("s.toml", "duration_s")),
    ("mission: position noise 1e300", _mission(
        GOOD_SCENARIO + "[sensor]\npd = 0.9\npf = 0.01\nfootprint_radius_m = 100.0\n"
        "position_noise_m = 1e300\n"), 2,
     ("s.toml", "sensor.position_noise_m")),
    ("mission: --out is a file", lambda t: [
        "mission", "run", _scenario(t, GOOD_SCENARIO), "--out", str(_write(t / "f", "x"))], 2,
     ("--out", "is a file")),
    ("mission: --seed 3000000000", _mission(GOOD_SCENARIO, "--seed", "3000000000"), 2,
     ("--seed",)),
    ("mission: --duration -5", _mission(GOOD_SCENARIO, "--duration", "-5"), 2,
     ("--duration",)),
    ("mission: 100000 UAVs", _mission(GOOD_SCENARIO.replace("[uavs]\ncount = 2",
                                                           "[uavs]\ncount = 100000")), 2,
     ("uavs.count", "100000")),
    ("mission: 100000 targets", _mission(GOOD_SCENARIO.replace("[targets]\ncount = 2",
                                                              "[targets]\ncount = 100000")), 2,
     ("targets.count", "100000")),
    ("mission: a 100000 × 100000 grid", _mission(GOOD_SCENARIO.replace(
        "rows = 4, cols = 4", "rows = 100000, cols = 100000")), 2, ("map.grid",)),
    ("mission: truncated OSM map", lambda t: ["mission", "run", _osm_scenario(t), "--out",
                                              str(t / "o")], 2,
     ("m.osm.bz2", "truncated or corrupt")),
    # ---- track
    ("track: missing file", lambda t: ["track", str(t / "no.json"), "--out", str(t / "e")], 2,
     ("no.json", "no such file")),
    ("track: not UTF-8", lambda t: ["track", str(_write(t / "s.json", b"{\xff}")), "--out",
                                    str(t / "e.json")], 2, ("s.json", "not UTF-8")),
    ("track: not JSON", lambda t: ["track", str(_write(t / "s.json", "{")), "--out",
                                   str(t / "e.json")], 2, ("s.json", "not valid JSON")),
    ("track: unknown key in motion", _track(_setter("motion.speed", 3)), 2,
     ("scans.json", "motion.speed")),
    ("track: sigma 1e300", _track(_setter("sensor.sigma", 1e300)), 2,
     ("scans.json", "sensor.sigma")),
    ("track: dt 1e300", _track(_setter("dt", 1e300)), 2, ("scans.json", "dt")),
    ("track: detection at 1e300 m", _track(lambda d: d.__setitem__("scans", [[[1e300, 1]]])), 2,
     ("scans.json", "scans[0][0][0]")),
    ("track: clutter 1e12 per scan", _track(_setter("sensor.clutter_rate", 1e12)), 2,
     ("scans.json", "sensor.clutter_rate")),
    ("track: NaN detection", _track(lambda d: d.__setitem__("scans", [[["NaN", 1]]])), 2,
     ("scans.json", "scans[0][0]")),
    ("track: --out is a folder", lambda t: ["track", _scans(t, _nothing), "--out", str(t)], 2,
     ("--out", "is a folder")),
    ("track: --particles 0", _track(_nothing, "--particles", "0"), 2, ("--particles",)),
    ("track: --seed 3000000000", _track(_nothing, "--seed", "3000000000"), 2, ("--seed",)),
    ("radio simulate: missing scenario", lambda t: ["radio", "simulate", str(t / "no.toml"),
                                                    "--out", str(t / "r.npz")], 2, ("no.toml",)),
    ("radio simulate: not TOML", _radio_sim("duration_s = = 3\n"), 2, ("s.toml",)),
    ("radio simulate: unknown key", _radio_sim("[signal]\nbogus = 1\n"), 2,
     ("signal.bogus",)),
    ("radio simulate: NaN duration", _radio_sim("duration_s = nan\n"), 2, ("duration_s",)),
    ("radio simulate: negative duration", _radio_sim("duration_s = -4.0\n"), 2,
     ("duration_s",)),
    ("radio simulate: tag label twice", _radio_sim(
        "[[tags]]\nlabel = 0\nbirth_s = 1.0\ndeath_s = 9.0\ninitial_state = [1.0, 0.0, 1.0, 0.0]"
        "\ntau_s = 0.1\n[[tags]]\nlabel = 0\nbirth_s = 1.0\ndeath_s = 9.0\n"
        "initial_state = [5.0, 0.0, 5.0, 0.0]\ntau_s = 0.2\n"), 2, ("tags",)),
    ("radio simulate: --noise 0", _radio_sim("", "--noise", "0"), 2, ("--noise",)),
    ("radio track: not a run file", lambda t: ["radio", "track", str(_write(
        t / "r.npz", "hello")), "--out", str(t / "e.json")], 2, ("r.npz", "not a readable")),
    ("radio track: NaN frame", _radio_track(lambda a: a["frames"].__setitem__(
        (1, 2, 3), float("nan"))), 2, ("frames", "interval 1")),
    ("radio track: wrong frame shape", _radio_track(lambda a: a.__setitem__(
        "frames", a["frames"][:, :, :100])), 2, ("frames",)),
    ("radio track: tag set not the frames'", _radio_track(lambda a: a.__setitem__(
        "frequencies_hz", a["frequencies_hz"] * 1.5)), 2, ("frequencies_hz",)),
    ("radio track: unknown field", _radio_track(lambda a: a.__setitem__("extra", [1])), 2,
     ("extra",)),
    ("radio track: --particles 0", _radio_track(lambda a: None, "--particles", "0"), 2,
     ("--particles",)),
    ("radio mission: r_min < 0", _radio_mission("--r-min", "-5"), 2, ("r_min",)),
    ("radio mission: P_vmin 1.5", _radio_mission("--p-void", "1.5"), 2, ("p_void",)),
    ("radio mission: --horizon 0", _radio_mission("--horizon", "0"), 2, ("--horizon",)),
    ("radio mission: unknown planner", _radio_mission("--planner", "zigzag"), 2,
     ("--planner",)),
    ("radio mission: --explore 1", _radio_mission("--explore", "1"), 2, ("--explore",)),
    ("radio mission: negative spread inflation", _radio_mission("--spread-inflation", "-1"), 2,
     ("--spread-inflation",)),
    ("radio mission: negative roughening", _radio_mission("--roughening", "-2"), 2,
     ("--roughening",)),
    ("radio mission: unknown calibration", _radio_mission("--calibration", "literal"), 2,
     ("--calibration",)),
]


def _bench_dir(tmp: Path, optima: str | bytes | None, bad: bool = False) -> Path:
    folder = tmp / "bench"
    folder.mkdir()
    _write(folder / "c101.txt", C101.read_text(encoding="utf-8"))
    if optima is not None:
        _write(folder / "optima.csv", optima)
    if bad:
        _write(folder / "bad.txt", "not an instance\n")
    return folder


def _osm_scenario(tmp: Path) -> str:
    packed = (OPTW.parent / "osm" / "West-Oakland.osm.bz2").read_bytes()
    _write(tmp / "m.osm.bz2", packed[: len(packed) // 2])
    return _scenario(tmp, GOOD_SCENARIO.replace("grid = { rows = 4, cols = 4, block_m = 100.0 }",
                                                'osm = "m.osm.bz2"'))
