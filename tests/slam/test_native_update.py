"""The native map update (``bearing_env._core.update_maps``, csrc/slam/) against numba's
:func:`bearing_env.slam.kernels.update_maps`, bit for bit.

Each setting builds three copies of the same batch state (:class:`BatchedPolygonSLAM`):
numba updates one, the native core the two others (on one thread and on two). Movements
are simulated for every map (random landmarks, a random walk, bounded noise, outliers
and missed readings), 10-30 per map and episode, so regions restart, windows age, the
robust fusion rebuilds; after every call the outputs must match, and after every episode
every state array (its bytes: NaN payloads and signed zeros count).

Fast: a few thousand movements. Slow (``-m slow``): at least 1,000,000 movements across
random settings, also runnable as a script::

    python -m tests.slam.test_native_update --movements 1000000
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from typing import Any

import numpy as np
import pytest

from bearing_env import _core
from bearing_env.slam import kernels
from bearing_env.slam.batch import STATE_ARRAYS, BatchedPolygonSLAM

TWO_PI = 2.0 * math.pi
ARENA = (1.0, 0.7)


@dataclasses.dataclass(frozen=True)
class Setting:
    """One batch's settings and how its movements are simulated."""

    n_landmarks: int = 6  # L1 and L2 included
    epsilon_deg: float = 2.0
    transfer: str = "conservative"
    edge_samples: int = 3
    fusion: str = "intersect"
    on_inconsistency: str = "restart"
    max_outliers: int = 1
    window: int = 6
    risk: float = 0.05
    robust_set: str = "guaranteed"
    noise_bound: str = "estimate"
    with_robot: bool = True
    noise_factor: float = 1.0  # the true noise bound over epsilon
    p_outlier: float = 0.0  # chance a reading is replaced by a random angle
    p_missing: float = 0.0  # chance a reading is missed (NaN)
    # Degenerate inputs: bearings rounded to a grid (exact ties, collinear cones), moves
    # of length 0 (start and end bearings alike: unbounded regions), landmarks on top of
    # each other (identical regions).
    quantum_deg: float = 0.0
    p_still: float = 0.0
    p_twin: float = 0.0
    maps: int = 8
    seed: int = 0

    def batch(self) -> BatchedPolygonSLAM:
        return BatchedPolygonSLAM(
            self.maps,
            self.n_landmarks,
            math.radians(self.epsilon_deg),
            transfer=self.transfer,
            edge_samples=self.edge_samples,
            on_inconsistency=self.on_inconsistency,
            fusion=self.fusion,
            max_outliers=self.max_outliers,
            window=self.window,
            risk=self.risk,
            robust_set=self.robust_set,
            noise_bound=self.noise_bound,
        )


def wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + math.pi) % TWO_PI - math.pi


class Walk:
    """Random worlds (one per map) and a random walk in each, read with bounded noise."""

    def __init__(self, setting: Setting, rng: np.random.Generator) -> None:
        self.setting, self.rng = setting, rng
        maps, n = setting.maps, setting.n_landmarks
        w, h = ARENA
        self.landmarks = rng.uniform(0, w, (maps, n)) + 1j * rng.uniform(0, h, (maps, n))
        # Sometimes L1 and L2 close together (frames too close to change, or overlapping).
        close = rng.random(maps) < 0.1
        self.landmarks[close, 1] = self.landmarks[close, 0] + 0.02 * np.exp(
            1j * rng.uniform(-np.pi, np.pi, close.sum())
        )
        if setting.p_twin > 0:
            for k in range(1, n):
                twin = rng.random(maps) < setting.p_twin
                self.landmarks[twin, k] = self.landmarks[twin, k - 1]
        self.position = rng.uniform(0, w, maps) + 1j * rng.uniform(0, h, maps)

    def move(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bearings (len(rows), n) at the start and end of one move of each map in rows."""
        s, rng = self.setting, self.rng
        start = self.position[rows]
        heading = rng.uniform(-np.pi, np.pi, rows.size)
        length = rng.uniform(0.05, 0.3, rows.size)
        if s.p_still > 0:
            length[rng.random(rows.size) < s.p_still] = 0.0
        end = start + length * np.exp(1j * heading)
        outside = (end.real < 0) | (end.real > ARENA[0]) | (end.imag < 0) | (end.imag > ARENA[1])
        centre = complex(ARENA[0] / 2, ARENA[1] / 2)
        heading[outside] = np.angle(centre - start[outside]) + rng.uniform(-0.5, 0.5, outside.sum())
        end = start + length * np.exp(1j * heading)
        self.position[rows] = end
        marks = self.landmarks[rows]
        bound = math.radians(s.epsilon_deg) * s.noise_factor
        shape = marks.shape
        b1 = wrap(
            np.angle(marks - start[:, None]) - heading[:, None] + bound * rng.uniform(-1, 1, shape)
        )
        b2 = wrap(
            np.angle(marks - end[:, None]) - heading[:, None] + bound * rng.uniform(-1, 1, shape)
        )
        for b in (b1, b2):
            if s.quantum_deg > 0:
                quantum = math.radians(s.quantum_deg)
                b[...] = wrap(np.round(b / quantum) * quantum)
            if s.p_outlier > 0:
                out = rng.random(shape) < s.p_outlier
                b[out] = rng.uniform(-np.pi, np.pi, out.sum())
            if s.p_missing > 0:
                b[rng.random(shape) < s.p_missing] = np.nan
        return np.ascontiguousarray(b1), np.ascontiguousarray(b2)


def state_of(batch: BatchedPolygonSLAM) -> kernels.State:
    return kernels.State(*(getattr(batch, name) for name in STATE_ARRAYS))


def copy_state(source: BatchedPolygonSLAM, into: BatchedPolygonSLAM) -> None:
    for name in STATE_ARRAYS:
        getattr(into, name)[...] = getattr(source, name)


def same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def new_outputs(n_rows: int, m: int) -> kernels.Outputs:
    return kernels.Outputs(
        np.empty(n_rows, dtype=np.int8),
        np.empty((n_rows, m), dtype=np.int8),
        np.empty(n_rows, dtype=np.int64),
    )


def native_params(params: kernels.Params) -> Any:
    return _core.Params(*params)


def assert_same_state(
    reference: BatchedPolygonSLAM, native: BatchedPolygonSLAM, where: str
) -> None:
    for name in STATE_ARRAYS:
        a, b = getattr(reference, name), getattr(native, name)
        if not same(a, b):
            diff = np.argwhere(a.view(np.uint8) != b.view(np.uint8)) if a.shape == b.shape else []
            raise AssertionError(f"{where}: state.{name} differs (first bytes at {diff[:3]})")


def run_setting(setting: Setting, episodes: int, moves: tuple[int, int] = (10, 30)) -> int:
    """Episodes of the setting on numba and native (1 and 2 threads); returns the
    movements each core fused."""
    rng = np.random.default_rng(setting.seed)
    reference = setting.batch()
    natives = (setting.batch(), setting.batch())
    states = tuple(_core.MapState(state_of(batch)) for batch in natives)
    params = reference._kernel_params(setting.with_robot)
    nparams = native_params(params)
    ref_state = reference._kernel_state()
    m = setting.n_landmarks - 2
    movements = 0
    for episode in range(episodes):
        reference.reset()
        for batch in natives:
            copy_state(reference, batch)
        walk = Walk(setting, rng)
        for move in range(int(rng.integers(moves[0], moves[1] + 1))):
            # All maps in order, or a random subset in random order.
            if rng.random() < 0.5:
                rows = np.arange(setting.maps, dtype=np.int64)
            else:
                size = int(rng.integers(1, setting.maps + 1))
                rows = rng.permutation(setting.maps)[:size].astype(np.int64)
            b1, b2 = walk.move(rows)
            out = new_outputs(rows.size, m)
            kernels.update_maps(b1, b2, rows, params, ref_state, out)
            for threads, state in enumerate(states, start=1):
                got = new_outputs(rows.size, m)
                _core.update_maps(b1, b2, rows, nparams, state, got, threads)
                for name, a, b in zip(kernels.Outputs._fields, out, got, strict=True):
                    assert same(a, b), f"{setting} episode {episode} move {move}: out.{name}"
            movements += rows.size
        for threads, batch in enumerate(natives, start=1):
            assert_same_state(reference, batch, f"{setting} episode {episode} threads {threads}")
    return movements


# --------------------------------------------------------------------------------------
# Settings
# --------------------------------------------------------------------------------------

FAST_SETTINGS = [
    Setting(seed=1),
    Setting(seed=2, transfer="paper", n_landmarks=5, epsilon_deg=0.5),
    Setting(seed=3, edge_samples=1, epsilon_deg=10.0, noise_factor=1.5, with_robot=False),
    Setting(seed=4, edge_samples=8, n_landmarks=3, p_missing=0.1),
    Setting(seed=5, on_inconsistency="keep", p_outlier=0.1, noise_factor=1.3),
    Setting(seed=6, fusion="relaxed", max_outliers=1, window=4, p_outlier=0.1),
    Setting(
        seed=7,
        fusion="relaxed",
        max_outliers=2,
        window=5,
        on_inconsistency="keep",
        p_outlier=0.15,
        p_missing=0.05,
        n_landmarks=8,
    ),
    Setting(
        seed=8,
        fusion="relaxed",
        max_outliers=0,
        window=3,
        transfer="paper",
        noise_factor=1.4,
        with_robot=False,
    ),
    Setting(seed=9, fusion="robust", p_outlier=0.1, noise_factor=1.5),
    Setting(
        seed=10,
        fusion="robust",
        noise_bound="nominal",
        robust_set="likely",
        p_outlier=0.1,
        transfer="paper",
    ),
    Setting(
        seed=11,
        fusion="robust",
        robust_set="likely",
        noise_factor=2.0,
        epsilon_deg=1.0,
        p_missing=0.05,
        n_landmarks=10,
    ),
    Setting(
        seed=12,
        fusion="robust",
        noise_bound="nominal",
        on_inconsistency="keep",
        with_robot=False,
        p_outlier=0.2,
        risk=0.2,
    ),
    Setting(
        seed=13,
        fusion="robust",
        n_landmarks=30,
        epsilon_deg=3.0,
        noise_factor=1.6,
        p_outlier=0.05,
        maps=4,
    ),
    Setting(seed=15, quantum_deg=1.0, p_still=0.1, p_twin=0.2, p_missing=0.05),
    Setting(seed=16, fusion="relaxed", quantum_deg=5.0, p_still=0.1, p_twin=0.2, window=4),
    Setting(seed=17, fusion="robust", quantum_deg=0.5, p_still=0.1, p_twin=0.2, noise_factor=1.5),
    Setting(
        seed=14, fusion="relaxed", n_landmarks=30, window=8, max_outliers=3, p_outlier=0.1, maps=4
    ),
]


def random_setting(rng: np.random.Generator, seed: int) -> Setting:
    """A random setting over every option (for the large run)."""
    fusion = str(rng.choice(["intersect", "relaxed", "robust"]))
    window = int(rng.integers(2, 10))
    return Setting(
        n_landmarks=int(rng.integers(3, 31)),
        epsilon_deg=float(rng.uniform(0.5, 10.0)),
        transfer=str(rng.choice(["conservative", "paper"])),
        edge_samples=int(rng.integers(1, kernels.MAX_EDGE_SAMPLES + 1)),
        fusion=fusion,
        on_inconsistency=str(rng.choice(["restart", "keep"])),
        max_outliers=int(rng.integers(0, min(window, 4))),
        window=window,
        risk=float(rng.choice([0.01, 0.05, 0.2])),
        robust_set=str(rng.choice(["guaranteed", "likely"])),
        noise_bound=str(rng.choice(["estimate", "nominal"])),
        with_robot=bool(rng.random() < 0.7),
        noise_factor=float(rng.choice([0.5, 1.0, 1.3, 1.7, 2.5])),
        p_outlier=float(rng.choice([0.0, 0.02, 0.1, 0.25])),
        p_missing=float(rng.choice([0.0, 0.05, 0.2])),
        quantum_deg=float(rng.choice([0.0, 0.0, 0.0, 0.5, 5.0])),
        p_still=float(rng.choice([0.0, 0.0, 0.1])),
        p_twin=float(rng.choice([0.0, 0.0, 0.1])),
        maps=int(rng.integers(2, 17)),
        seed=seed,
    )


@pytest.mark.parametrize("setting", FAST_SETTINGS, ids=lambda s: f"seed{s.seed}-{s.fusion}")
def test_native_update_matches_numba(setting: Setting) -> None:
    assert run_setting(setting, episodes=2) > 0


def run_large(movements: int, seed: int = 0, report: bool = True) -> tuple[int, int]:
    """Random settings until at least ``movements`` movements; returns (movements, settings)."""
    rng = np.random.default_rng(seed)
    done = settings = 0
    started = time.perf_counter()
    while done < movements:
        setting = random_setting(rng, seed=1_000_000 * seed + settings)
        done += run_setting(setting, episodes=int(rng.integers(3, 12)))
        settings += 1
        if report and settings % 20 == 0:
            elapsed = time.perf_counter() - started
            print(f"{done:,} movements, {settings} settings, {elapsed:.0f} s", flush=True)
    return done, settings


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(10))
def test_native_update_large(seed: int) -> None:
    """1,000,000 movements in all, in ten parts of random settings."""
    done, _ = run_large(100_000, seed=seed + 1)
    assert done >= 100_000


# --------------------------------------------------------------------------------------
# Threads and bad inputs
# --------------------------------------------------------------------------------------


def test_threads_split_like_numba_parallel() -> None:
    """More threads than rows, three and four threads: the same bits as numba's parallel
    kernel with the same blocks."""
    setting = Setting(seed=21, fusion="robust", p_outlier=0.1, noise_factor=1.5, maps=7)
    rng = np.random.default_rng(21)
    reference = setting.batch()
    params = reference._kernel_params(True)
    natives = {threads: setting.batch() for threads in (3, 4, 9)}
    states = {t: _core.MapState(state_of(b)) for t, b in natives.items()}
    walk = Walk(setting, rng)
    rows = np.arange(setting.maps, dtype=np.int64)
    for move in range(20):
        b1, b2 = walk.move(rows)
        out = new_outputs(rows.size, setting.n_landmarks - 2)
        kernels.update_maps_parallel(3, b1, b2, rows, params, reference._kernel_state(), out)
        for threads in natives:
            got = new_outputs(rows.size, setting.n_landmarks - 2)
            _core.update_maps(b1, b2, rows, native_params(params), states[threads], got, threads)
            assert all(same(a, b) for a, b in zip(out, got, strict=True)), (move, threads)
    for threads, batch in natives.items():
        assert_same_state(reference, batch, f"threads {threads}")


def test_helpers_match_numba() -> None:
    rng = np.random.default_rng(5)
    for _ in range(200):
        size = int(rng.integers(0, 6))
        indices = rng.integers(-2, 8, int(rng.integers(0, 6))).astype(np.int64)
        for distinct in (False, True):
            expected = kernels.check_indices(indices, size, distinct)
            assert _core.check_indices(indices, size, distinct) == expected
    values = rng.normal(size=(4, 5))
    assert _core.none_infinite(values) is True
    values[2, 3] = np.nan
    assert _core.none_infinite(values) is True
    values[1, 4] = -np.inf
    assert _core.none_infinite(values) is False
    assert _core.none_infinite(values[:, ::2]) is kernels.none_infinite(values[:, ::2])
    assert _core.none_infinite(values.T) is kernels.none_infinite(values.T)
    assert _core.none_infinite(np.empty((0, 3))) is True
    for n, p, risk, cap in [
        (0, 0.1, 0.05, 6),
        (10, 0.0, 0.05, 6),
        (37, 0.02, 0.05, 6),
        (5, 0.9999, 0.01, 6),
        (200, 0.3, 0.2, 3),
        (1, 0.5, 0.5, 0),
    ]:
        assert _core.binomial_q(n, p, risk, cap) == kernels.binomial_q(n, p, risk, cap)
    for name in (
        "CAPACITY",
        "MAX_WINDOW",
        "ROBUST_LEVELS",
        "HISTORY",
        "PROBE_SHRINK",
        "BOUND_GROWTH",
        "MAX_NOISE_SCALE",
        "INDEX_OK",
        "INDEX_OUT_OF_RANGE",
        "INDEX_REPEATED",
        "FRAME_REJECTED",
        "LANDMARK_MISSING",
        "FUSION_ROBUST",
    ):
        assert getattr(_core, name) == getattr(kernels, name), name


def test_contains_points_matches_numba() -> None:
    setting = Setting(seed=31, maps=6, n_landmarks=7)
    rng = np.random.default_rng(31)
    batch = setting.batch()
    walk = Walk(setting, rng)
    rows = np.arange(setting.maps, dtype=np.int64)
    for _ in range(8):
        batch.update(*walk.move(rows))
    for relative in (0.0, 1e-12, 1e-3):
        subset = rng.permutation(setting.maps)[:4].astype(np.int64)
        centres = batch.centroids[subset]
        points = centres + rng.normal(scale=0.05, size=centres.shape) * (1 + 1j)
        points[0, 0] = batch.vertices[subset[0], 0, 0]  # a vertex: on the boundary
        points = np.ascontiguousarray(np.nan_to_num(points))
        expected = np.empty(points.shape, dtype=bool)
        got = np.empty(points.shape, dtype=bool)
        kernels.contains_points(batch.vertices, batch.counts, subset, points, relative, expected)
        _core.contains_points(batch.vertices, batch.counts, subset, points, relative, got)
        assert np.array_equal(expected, got)


def test_bad_inputs_name_the_argument() -> None:
    setting = Setting(maps=3, n_landmarks=5)
    batch = setting.batch()
    state = state_of(batch)
    native = _core.MapState(state)
    params = native_params(batch._kernel_params(True))
    rows = np.arange(3, dtype=np.int64)
    b = np.zeros((3, 5))
    out = new_outputs(3, 3)
    _core.update_maps(b, b, rows, params, native, out)  # fine

    def fails(error: type[Exception], match: str, *args: Any, **kwargs: Any) -> None:
        with pytest.raises(error, match=match):
            _core.update_maps(*args, **kwargs)

    fails(TypeError, "bearings_start", b.astype(np.float32), b, rows, params, native, out)
    fails(ValueError, "bearings_end", b, np.zeros((3, 6)), rows, params, native, out)
    fails(ValueError, "bearings_start", np.zeros((6, 5))[::2], b, rows, params, native, out)
    fails(ValueError, "bearings_start", np.zeros((2, 5)), b, rows, params, native, out)
    fails(TypeError, "rows", b, b, rows.astype(np.int32), params, native, out)
    fails(ValueError, "rows", b, b, np.array([0, 1, 3]), params, native, out)
    fails(ValueError, "rows", b, b, np.array([0, -1, 2]), params, native, out)
    fails(ValueError, "rows", b, b, np.array([0, 1, 1]), params, native, out, threads=2)
    fails(ValueError, "threads", b, b, rows, params, native, out, threads=0)
    fails(ValueError, "out.landmark_status", b, b, rows, params, native, new_outputs(3, 4))
    fails(
        ValueError,
        "out.n_bad",
        b,
        b,
        rows,
        params,
        native,
        kernels.Outputs(out[0], out[1], np.empty(2, dtype=np.int64)),
    )
    fails(
        TypeError,
        "out.frame_status",
        b,
        b,
        rows,
        params,
        native,
        kernels.Outputs(out[0].astype(np.int64), out[1], out[2]),
    )
    fails(TypeError, "out", b, b, rows, params, native, (out[0], out[1]))
    with pytest.raises(TypeError):
        _core.update_maps(b, b, rows, batch._kernel_params(True), native, out)
    # Settings the state was not made for.
    relaxed = native_params(batch._kernel_params(True)._replace(fusion=kernels.FUSION_RELAXED))
    fails(ValueError, "FUSION_RELAXED", b, b, rows, relaxed, native, out)
    robust = native_params(batch._kernel_params(True)._replace(fusion=kernels.FUSION_ROBUST))
    fails(ValueError, "FUSION_ROBUST", b, b, rows, robust, native, out)

    # A corrupt state (counts or positions that would index past a buffer).
    for fusion, name, value in [
        ("intersect", "counts", kernels.CAPACITY + 1),
        ("intersect", "robot_counts", -1),
        ("relaxed", "window_next", 99),
        ("relaxed", "window_counts", 1000),
        ("robust", "level_counts", -3),
        ("robust", "history_next", 16),
        ("robust", "noise_scale", 0.0),
    ]:
        corrupt = dataclasses.replace(setting, fusion=fusion).batch()
        getattr(corrupt, name).flat[0] = value
        corrupt_params = native_params(corrupt._kernel_params(True))
        with pytest.raises(ValueError, match=f"corrupt state: {name}"):
            _core.update_maps(b, b, rows, corrupt_params, _core.MapState(state_of(corrupt)), out)

    # Params.
    good = tuple(batch._kernel_params(True))
    for index, value, match in [
        (1, 2, "transfer"),
        (2, 0, "edge_samples"),
        (2, 9, "edge_samples"),
        (3, 5, "on_inconsistency"),
        (4, 3, "fusion"),
        (5, -1, "max_outliers"),
        (0, -0.1, "epsilon"),
        (0, math.nan, "epsilon"),
        (7, math.inf, "risk"),
    ]:
        bad = list(good)
        bad[index] = value
        with pytest.raises(ValueError, match=match):
            _core.Params(*bad)
    assert _core.Params(*good).fusion == good[4]

    # MapState.
    with pytest.raises(TypeError, match="state"):
        _core.MapState([*state])
    with pytest.raises(ValueError, match="34"):
        _core.MapState(tuple(state)[:-1])
    bad_fields: list[tuple[str, Any, type[Exception]]] = [
        ("counts", state.counts.astype(np.int32), TypeError),
        ("areas", state.areas[:2], ValueError),
        ("window_counts", np.zeros((3, 1, 3), dtype=np.int64), ValueError),
        ("vertices", np.zeros((3, 3, 64), dtype=np.complex128), ValueError),
        ("history_bearings", np.zeros((3, 0, 2, 4)), ValueError),
        ("robot_heading", np.zeros(6)[::2], ValueError),
        ("level_counts", np.zeros((3, 3, 2), dtype=np.int64), ValueError),
        ("probe_vertices", np.zeros((3, 3, 7), dtype=np.complex128), ValueError),
        ("window_inlier", state.window_inlier.astype(np.int8), TypeError),
    ]
    for name, value, error in bad_fields:
        with pytest.raises(error, match=rf"state\.{name}"):
            _core.MapState(state._replace(**{name: value}))
    readonly = state.counts.copy()
    readonly.flags.writeable = False
    with pytest.raises(ValueError, match=r"state\.counts"):
        _core.MapState(state._replace(counts=readonly))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--movements", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    started = time.perf_counter()
    done, settings = run_large(args.movements, seed=args.seed)
    elapsed = time.perf_counter() - started
    print(f"bit-identical: {done:,} movements ({settings} settings) in {elapsed:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
