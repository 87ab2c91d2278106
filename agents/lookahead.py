"""Receding-horizon planning on the robot's own map: beam search over move sequences.

:class:`Lookahead` plans ``depth`` moves ahead and makes the first move of the best plan,
then plans again after the next observation. Each plan is scored by simulating the SLAM
updates of its moves on copies of the robot's map (``BatchedPolygonSLAM.update(...,
robot=False)``: areas only), all the candidates of one depth in one batched call.

**Uncertainty.** The robot's map is uncertain: a landmark is somewhere in its region, not
at its centroid, and so is the robot. Simulated bearings from the centroids alone predict
regions that the real readings will not give, and a plan that is good for the centroids
can be poor for the truth (a naive two-step search on the centroids did worse than the
one-step greedy planner). So every plan is scored over ``hypotheses`` worlds: the first
puts every landmark and the robot at their estimates (centroids), the others draw them
uniformly inside their regions (the robot's offset from its region's centroid carried to
its believed pose). A plan's score is the mean, over the worlds, of the predicted
potential (the env's default: sum of capped log areas) after its last move; the beam
keeps the ``width`` best partial plans at each depth.

The robot does not know where the walls are: the simulation ignores them, and after a
move stopped by a wall only turns back toward the landmarks are considered for the first
move (as :class:`~bearing_env.agents.heuristics.GreedyOneStep` does). Moves shorter than
the arena's minimum baseline do not update the map.

:class:`LookaheadOracle` is the same search on the *true* map (one world: the true
landmarks and pose, the true FL scale, moves cut at the true walls): privileged, an upper
reference.
"""

from __future__ import annotations

import math
import time

import gymnasium as gym
import numpy as np

from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM, world_to_fl
from bearing_env.validation import int_at_least

from .base import Movement
from .belief import ObservationView
from .heuristics import GreedyOneStep, _allowed_turns
from .planning import (
    ComplexArray,
    FloatArray,
    Mover,
    Sensor,
    Worlds,
    beam_search,
    sample_in_polygon,
    uncertainty_potential,
)
from .visibility import TrueSensor

__all__ = ["Lookahead", "LookaheadOracle", "Worlds", "beam_search", "sample_in_polygon"]


class Lookahead(GreedyOneStep):
    """Receding-horizon beam search on the robot's own map, over uncertain estimates.

    See the module doc. It reads the observation and the robot's own map
    (``info["robot_map"]``), never ground truth.

    Args:
        env: the env it acts in (either id).
        depth: moves per plan (1 is a one-step planner over the worlds).
        width: partial plans kept at each depth (the beam).
        n_turns: turns of the candidate grid, evenly spaced over the circle (continuous
            id; the discrete id uses its table's turns).
        lengths: number of lengths, evenly spaced down from the longest, or explicit
            lengths in metres (continuous id); on the discrete id, how many of the
            table's lengths, longest first. Candidates = n_turns x lengths.
        hypotheses: worlds each plan is scored in: the estimates, plus ``hypotheses - 1``
            drawn inside the regions (from the policy's seeded generator).

    ``planning_times`` holds the wall-clock seconds of every planned move of the episode
    (bootstrap moves excluded), for reports.

    With a limited camera it takes :class:`GreedyOneStep`'s route with its own
    candidates and ``depth`` as the longest plan in hypothesised worlds: its worlds drawn
    inside the uncertainty regions did worse there (docs/policies.md, "A limited
    sensor"); then ``planning_times`` holds every decision's time.
    """

    name = "lookahead"

    def __init__(
        self,
        env: gym.Env,
        depth: int = 2,
        width: int = 8,
        n_turns: int = 24,
        lengths: int | tuple[float, ...] = 2,
        hypotheses: int = 4,
        bootstrap_worlds: int = 8,
    ) -> None:
        for value, label in ((depth, "depth"), (width, "width"), (hypotheses, "hypotheses")):
            int_at_least(value, 1, label)
        super().__init__(
            env, n_turns=n_turns, lengths=lengths, bootstrap_worlds=bootstrap_worlds,
            bootstrap_depth=depth,
        )  # fmt: skip
        self.depth, self.width, self.hypotheses = depth, width, hypotheses
        self.planning_times: list[float] = []
        #: The beam's copies of the map, by role and size, refilled at each decision.
        self._beam: dict[tuple[str, int], BatchedPolygonSLAM] = {}

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.planning_times = []

    def _choose(self, view: ObservationView, slam: PolygonSLAM) -> Movement:
        if self.before_map is not None:
            # A limited camera: GreedyOneStep's route with this planner's candidates, up
            # to this depth in hypothesised worlds when no move helps at once (the
            # uncertainty-region worlds below did worse there: docs/policies.md).
            started = time.perf_counter()
            movement = super()._choose(view, slam)
            self.planning_times.append(time.perf_counter() - started)
            return movement
        pose = self._pose(view, slam)
        if pose is None or pose.metres_per_unit is None:
            return self._without_map(view, slam, pose)
        scale = pose.metres_per_unit
        started = time.perf_counter()
        worlds = self._worlds(slam, pose.position)

        self._record_bump(view, pose)

        def by_length(
            positions: ComplexArray, headings: FloatArray, lengths: FloatArray
        ) -> FloatArray:
            if self.avoid_bumps and self.bumps:
                return self._travel(
                    positions[:, None, :], headings[:, :, None], lengths[None, :, None], scale
                )
            metres = np.where(lengths >= self.min_baseline, lengths, 0.0)
            shape = (positions.shape[0], lengths.size, positions.shape[1])
            return np.broadcast_to((metres / scale)[None, :, None], shape)

        sensor = self._sensor(view, pose, worlds.landmarks)
        movement = self._search(view, slam, worlds, pose.heading, by_length, sensor)
        self.planning_times.append(time.perf_counter() - started)
        return movement

    def _search(
        self,
        view: ObservationView,
        slam: PolygonSLAM,
        worlds: Worlds,
        heading: float,
        mover: Mover,
        sensor: Sensor | None = None,
    ) -> Movement:
        turns = np.array([c.turn for c in self.candidates])
        lengths = np.array([c.length for c in self.candidates])
        allowed = _allowed_turns(turns, view)
        first, score = beam_search(
            slam,
            worlds,
            heading,
            turns,
            lengths,
            allowed,
            mover,
            self.depth,
            self.width,
            self.area_cap,
            scratch=self._beam,
            sensor=sensor,
        )
        if first < 0 or score >= uncertainty_potential(slam.areas, self.area_cap):
            return self._without_map(view, slam)
        return self.candidates[first]

    def _worlds(self, slam: PolygonSLAM, position: complex) -> Worlds:
        n_draws = self.hypotheses - 1
        batch, row = slam.batch, slam.index
        mapped = np.empty((self.hypotheses, slam.n_landmarks - 2), dtype=np.complex128)
        mapped[0] = batch.centroids[row]
        for j in range(slam.n_landmarks - 2):
            region = batch.polygon(row, j)
            if region.size == 0:
                mapped[:, j] = complex(np.nan, np.nan)
            elif n_draws:
                mapped[1:, j] = sample_in_polygon(region, n_draws, self.rng)
        positions = np.full(self.hypotheses, position, dtype=np.complex128)
        robot_region = batch.robot_polygon(row)
        if robot_region.size and n_draws:
            offsets = sample_in_polygon(robot_region, n_draws, self.rng) - batch.robot_centroid[row]
            positions[1:] += offsets
        frame = np.broadcast_to(np.array([0.0, 1.0], dtype=np.complex128), (self.hypotheses, 2))
        return Worlds(np.concatenate([frame, mapped], axis=1), positions)


class LookaheadOracle(Lookahead):
    """PRIVILEGED upper reference: :class:`Lookahead` on the *true* map.

    One world, the truth: true landmarks and pose, the true FL scale, every planned move
    cut where the true arena wall or an obstacle would stop it, and the readings the real
    sensor would miss missed (:class:`~bearing_env.agents.visibility.TrueSensor`). It
    reads ground truth, so it is not a robot policy: it bounds what this search could do
    with a perfect map. ``hypotheses`` is ignored (there is one world).
    """

    name = "lookahead_oracle"
    privileged = True

    def _choose(self, view: ObservationView, slam: PolygonSLAM) -> Movement:
        world = self.world_source()
        l1, l2 = world.landmarks[0], world.landmarks[1]
        origin, unit = complex(*l1), complex(*(l2 - l1))
        scale = abs(unit)
        position = world_to_fl(world.position, l1, l2)
        truth = world_to_fl(world.landmarks, l1, l2)
        worlds = Worlds(
            (truth[:, 0] + 1j * truth[:, 1])[None, :],
            np.array([complex(position[0], position[1])]),
        )
        heading_fl = world.heading - math.atan2(unit.imag, unit.real)
        sensor = TrueSensor(world)  # the real field of view, range and obstacles
        rotation = unit / scale

        def mover(positions: ComplexArray, headings: FloatArray, lengths: FloatArray) -> FloatArray:
            out = np.empty((positions.shape[0], lengths.size, positions.shape[1]))
            for n in range(positions.shape[0]):
                for h in range(positions.shape[1]):
                    at = origin + unit * positions[n, h]
                    for k in range(lengths.size):
                        direction = float(np.angle(np.exp(1j * headings[n, k]) * rotation))
                        travelled = sensor.travel(
                            np.array([at.real, at.imag]), direction, float(lengths[k])
                        )
                        out[n, k, h] = travelled / scale
            return out

        started = time.perf_counter()
        movement = self._search(
            view, slam, worlds, heading_fl, mover, None if sensor.trivial else sensor
        )
        self.planning_times.append(time.perf_counter() - started)
        return movement
