"""The readings the world-model benchmarks feed ``PolygonSLAM.update``: recorded from env
episodes, as the env's own map was fed them.

:func:`record` runs the paper's random polygonal trajectory
(:class:`~bearing_env.agents.RandomPolygonal`) on a registered task for a few seeded
episodes and keeps, for every movement, the bearings of each landmark at its start and at
its end (radians from the direction of motion, NaN for a missed reading): the two arrays
``PolygonSLAM.update`` takes. Recording is deterministic per seed and cheap (160 env steps
per task, well under a second), so the benchmarks record at run time and no data file
is kept.

:func:`synthetic_readings` is the older workload of ``bench-slam``, kept as a secondary
figure: one random layout in a 100 x 100 arena with |L1 - L2| = 20 and moves of 25,
repeated.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

import bearing_env  # noqa: F401  (registers the tasks)
from bearing_env.agents import RandomPolygonal
from bearing_env.slam import MapSettings

FloatArray = NDArray[np.float64]
Reading = tuple[FloatArray, FloatArray]

#: The tasks whose episodes the update() benchmarks replay, in the order they are listed.
RECORDED_TASKS: tuple[str, ...] = ("BearingSLAM-Khepera-v1", "BearingSLAM-Random8-v1")
#: Episodes recorded per task, and the seed of the first (episode k: seed + k).
RECORDED_EPISODES = 8
RECORDED_SEED = 0
#: How the benchmarks' tables name each recorded task, and the synthetic readings.
WORKLOAD_LABELS: dict[str, str] = {
    "BearingSLAM-Khepera-v1": "Khepera-v1 readings",
    "BearingSLAM-Random8-v1": "Random8-v1 readings",
}
SYNTHETIC_LABEL = "synthetic readings (100x100 arena, repeated layout)"


@dataclass(frozen=True)
class Recording:
    """A task's recorded movements: ``start[k]`` and ``end[k]`` are the bearings (one per
    landmark) at the start and end of movement ``k``; ``episodes[k]`` is its episode."""

    env_id: str
    seed: int
    #: The env's map settings (epsilon, transfer, fusion, ...), which the readings fed.
    settings: MapSettings
    start: FloatArray
    end: FloatArray
    episodes: NDArray[np.int64]

    @property
    def n_landmarks(self) -> int:
        return int(self.start.shape[1])

    @property
    def movements(self) -> int:
        return int(self.start.shape[0])

    def readings(self) -> list[Reading]:
        """The (start, end) pairs in order, each a contiguous float64 array."""
        return [(self.start[k].copy(), self.end[k].copy()) for k in range(self.movements)]

    def episode_readings(self) -> Iterator[list[Reading]]:
        """The readings episode by episode (a map starts afresh with each)."""
        pairs = self.readings()
        for episode in range(int(self.episodes.max()) + 1 if self.movements else 0):
            yield [pairs[k] for k in np.flatnonzero(self.episodes == episode)]


def _fed_readings(env: gym.Env) -> Reading:
    """The bearings the env's map was fed at its last step: (start, end), one per landmark.

    The env hands out the end bearing (the observation's bearing slots, as float32 cos and
    sin) but not the start one; both are in its batch state, which its renderer reads
    too (``bearing_env.rendering.scene``), so the recorder reads them there."""
    base = env.unwrapped
    n = int(base.n_landmarks)  # type: ignore[attr-defined]
    state = base._state  # type: ignore[attr-defined]
    start = np.array(state.start_bearings[0, :n], dtype=np.float64)
    end = np.array(state.latest_bearings[0, :n], dtype=np.float64)
    return start, end


def record(env_id: str, episodes: int = RECORDED_EPISODES, seed: int = RECORDED_SEED) -> Recording:
    """``episodes`` episodes of the random polygonal trajectory on ``env_id`` (episode
    ``k``: env and policy seeded ``seed + k``), every movement's readings kept."""
    env = gym.make(env_id)
    try:
        policy = RandomPolygonal(env)
        settings = env.unwrapped.slam.settings  # type: ignore[attr-defined]
        starts: list[FloatArray] = []
        ends: list[FloatArray] = []
        episode_of: list[int] = []
        for episode in range(episodes):
            observation, info = env.reset(seed=seed + episode)
            policy.reset(seed=seed + episode)
            done = False
            while not done:
                action = policy.act(observation, info)
                observation, _, terminated, truncated, info = env.step(action)
                start, end = _fed_readings(env)
                starts.append(start)
                ends.append(end)
                episode_of.append(episode)
                done = bool(terminated or truncated)
    finally:
        env.close()
    return Recording(
        env_id=env_id,
        seed=seed,
        settings=settings,
        start=np.array(starts),
        end=np.array(ends),
        episodes=np.array(episode_of, dtype=np.int64),
    )


def synthetic_readings(n_landmarks: int, n_moves: int, seed: int) -> list[Reading]:
    """Noisy bearing pairs of a random polygonal walk in a 100 x 100 arena: one random
    layout (|L1 - L2| = 20), moves of 25, bearing noise within 2 degrees."""
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(2.0)
    landmarks = rng.uniform(0, 100, n_landmarks) + 1j * rng.uniform(0, 100, n_landmarks)
    landmarks[1] = landmarks[0] + 20.0
    pos = 50.0 + 50.0j
    readings = []
    for _ in range(n_moves):
        heading = np.exp(1j * rng.uniform(-np.pi, np.pi))
        nxt = pos + 25.0 * heading
        if not (0 < nxt.real < 100 and 0 < nxt.imag < 100):
            nxt, heading = pos - 25.0 * heading, -heading
            if not (0 < nxt.real < 100 and 0 < nxt.imag < 100):
                nxt = pos + 0.5 * (50 + 50j - pos)
                heading = (nxt - pos) / abs(nxt - pos)
        b1 = np.angle((landmarks - pos) / heading) + rng.uniform(-eps, eps, n_landmarks)
        b2 = np.angle((landmarks - nxt) / heading) + rng.uniform(-eps, eps, n_landmarks)
        readings.append((b1, b2))
        pos = nxt
    return readings
