"""The planners' scoring: the readings computed natively (no sensor) and in Python (with a
sensor that misses nothing) score the same bits, on maps built from random movements, for
every fusion; the golden greedy, lookahead and oracle traces hold the scores to the
Python update path they replaced."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bearing_env.agents import planning
from bearing_env.slam import PolygonSLAM


def identity_sensor(
    bearings: np.ndarray, positions: np.ndarray, headings: np.ndarray
) -> np.ndarray:
    """A sensor that misses nothing: simulate_potentials takes its Python path with it."""
    return bearings


def mapped(fusion: str, seed: int, moves: int, n: int = 5) -> PolygonSLAM:
    """A map of n landmarks after `moves` noisy movements of a random walk."""
    rng = np.random.default_rng(seed)
    slam = PolygonSLAM(n, epsilon=0.05, fusion=fusion)
    landmarks = rng.uniform(-2.0, 3.0, size=n) + 1j * rng.uniform(-2.0, 3.0, size=n)
    landmarks[0], landmarks[1] = 0.0, 1.0
    position, heading = complex(rng.uniform(-1, 2), rng.uniform(-1, 2)), rng.uniform(-3, 3)
    for _ in range(moves):
        heading += rng.uniform(-1.5, 1.5)
        end = position + rng.uniform(0.2, 1.0) * np.exp(1j * heading)
        noise = rng.uniform(-0.05, 0.05, size=(2, n))
        start_b = planning.bearings_from(position, heading, landmarks) + noise[0]
        end_b = planning.bearings_from(end, heading, landmarks) + noise[1]
        slam.update(start_b, end_b)
        position = end
    return slam


@pytest.mark.parametrize("fusion", ["intersect", "relaxed", "robust"])
@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**16),
    moves=st.integers(0, 6),
    count=st.integers(1, 17),
    unknown=st.booleans(),
    log_area=st.booleans(),
)
def test_the_native_scoring_gives_the_python_paths_bits(
    fusion: str, seed: int, moves: int, count: int, unknown: bool, log_area: bool
) -> None:
    slam = mapped(fusion, seed, moves)
    rng = np.random.default_rng(seed + 1)
    landmarks = planning.landmark_positions_fl(slam)
    if unknown:
        landmarks[-1] = complex(np.nan, np.nan)
    start = complex(rng.uniform(-1, 2), rng.uniform(-1, 2))
    headings = rng.uniform(-np.pi, np.pi, size=count)
    distances = rng.uniform(0.0, 1.0, size=count)
    distances[rng.random(count) < 0.2] = 0.0  # candidates that do not move
    scratch: dict[int, object] = {}
    native = planning.simulate_potentials(
        slam, start, landmarks, headings, distances, 4.0, log_area=log_area, scratch=scratch  # type: ignore[arg-type]
    )
    again = planning.simulate_potentials(
        slam, start, landmarks, headings, distances, 4.0, log_area=log_area, scratch=scratch  # type: ignore[arg-type]
    )
    python = planning.simulate_potentials(
        slam, start, landmarks, headings, distances, 4.0, log_area=log_area,
        sensor=identity_sensor,
    )  # fmt: skip
    assert native.tobytes() == python.tobytes()
    assert again.tobytes() == native.tobytes()  # a reused scratch batch scores the same


def test_the_native_scoring_leaves_the_map_untouched() -> None:
    slam = mapped("intersect", 3, 4)
    before = slam.areas.copy(), slam.batch.vertices.copy()
    planning.simulate_potentials(
        slam, 0.5 + 0.5j, planning.landmark_positions_fl(slam), np.array([0.0, 1.0, 2.0]),
        np.array([0.5, 0.0, 0.8]), 4.0,
    )  # fmt: skip
    assert np.array_equal(slam.areas, before[0])
    assert np.array_equal(slam.batch.vertices, before[1])
