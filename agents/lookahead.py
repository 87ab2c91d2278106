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
from collections.abc import Callable
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM, world_to_fl
from bearing_env.validation import int_at_least

from .base import Movement
from .belief import ObservationView
from .env_access import bearing_env_of
from .heuristics import GreedyOneStep, _allowed_turns
from .planning import Sensor, bearings_from, uncertainty_potential

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


@dataclass(frozen=True)
class Worlds:
    """The hypothesised worlds a plan is scored in (all in FL)."""

    #: Landmark positions (H, n): L1 = 0, L2 = 1, then one position per mapped landmark
    #: (NaN where it has no region yet).
    landmarks: ComplexArray
    #: The robot's position in each world (H,).
    positions: ComplexArray


def sample_in_polygon(vertices: ComplexArray, count: int, rng: np.random.Generator) -> ComplexArray:
    """``count`` points drawn uniformly inside a convex polygon (its vertices, in order)."""
    if vertices.size < 3:
        return np.full(count, vertices.mean() if vertices.size else complex(np.nan, np.nan))
    # A fan of triangles from vertex 0, chosen by area, then a uniform point in each.
    a, b, c = vertices[0], vertices[1:-1], vertices[2:]
    areas = np.abs(((b - a).conjugate() * (c - a)).imag)
    total = float(areas.sum())
    if total <= 0.0:
        return np.full(count, vertices.mean())
    triangle = rng.choice(areas.size, size=count, p=areas / total)
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1.0
    u, v = np.where(flip, 1.0 - u, u), np.where(flip, 1.0 - v, v)
    return np.asarray(a + u * (b[triangle] - a) + v * (c[triangle] - a))


#: Distances (nodes, K, H) in FL units travelled by each candidate from each node's
#: positions (nodes, H) with headings (nodes, K).
Mover = Callable[[ComplexArray, FloatArray, FloatArray], FloatArray]


def beam_search(
    slam: PolygonSLAM,
    worlds: Worlds,
    heading: float,
    turns: FloatArray,
    lengths: FloatArray,
    first_allowed: NDArray[np.bool_],
    mover: Mover,
    depth: int,
    width: int,
    area_cap: float,
    scratch: dict[tuple[str, int], BatchedPolygonSLAM] | None = None,
    sensor: Sensor | None = None,
) -> tuple[int, float]:
    """The index of the first candidate of the best plan, and that plan's mean score.

    Candidates are ``(turns[k], lengths[k])`` (turn relative to the heading, length in
    metres); only the ``first_allowed`` ones may start a plan. Each depth's expansions
    are one batched update (:meth:`BatchedPolygonSLAM.update_trusted`: the bearings are
    made here) on copies of the beam's maps; ``scratch``: the caller's batches of copies
    by role and size, kept between calls and refilled in place
    (:meth:`BatchedPolygonSLAM.take`) instead of made anew at each depth. ``sensor``
    predicts the readings' misses (its landmarks are the worlds'; None: every landmark
    seen).
    """
    batches: dict[tuple[str, int], BatchedPolygonSLAM] = {} if scratch is None else scratch
    n_worlds = worlds.positions.size
    known = np.isfinite(worlds.landmarks)  # (H, n)
    targets = np.where(known, worlds.landmarks, 0.0)
    maps = slam.replicate(n_worlds, into=batches.get(("root", n_worlds)))  # node 0, per world
    batches["root", n_worlds] = maps
    positions = worlds.positions[None, :]  # (nodes, H)
    headings = np.array([heading])  # (nodes,)
    firsts = np.array([-1])
    best_first, best_score = -1, math.inf
    for level in range(depth):
        allowed = first_allowed if level == 0 else np.ones(turns.size, dtype=bool)
        ks = np.flatnonzero(allowed)
        n_nodes, n_k = positions.shape[0], ks.size
        new_headings = headings[:, None] + turns[ks][None, :]  # (nodes, K)
        distances = mover(positions, new_headings, lengths[ks])  # (nodes, K, H)
        step = distances * np.exp(1j * new_headings)[:, :, None]
        starts = np.broadcast_to(positions[:, None, :], step.shape)
        ends = starts + step
        heading_grid = np.broadcast_to(new_headings[:, :, None], step.shape)
        b1 = bearings_from(starts, heading_grid, targets[None, None, :, :])
        b2 = bearings_from(ends, heading_grid, targets[None, None, :, :])
        # A landmark without a region, or a move too short, gives no information.
        moving = (distances > 0.0)[..., None] & known[None, None, :, :]
        b2 = np.where(moving, b2, b1)
        if sensor is not None:
            b1, b2 = sensor(b1, starts, heading_grid), sensor(b2, ends, heading_grid)
        rows = np.arange(n_nodes)[:, None, None] * n_worlds + np.arange(n_worlds)[None, None, :]
        rows = np.broadcast_to(rows, step.shape).reshape(-1)
        trials = maps.take(rows.astype(np.int64), into=batches.get(("trials", rows.size)))
        batches["trials", rows.size] = trials
        n = slam.n_landmarks
        trials.update_trusted(
            np.ascontiguousarray(b1.reshape(-1, n), dtype=np.float64),
            np.ascontiguousarray(b2.reshape(-1, n), dtype=np.float64),
            robot=False,
        )
        potentials = uncertainty_potential(trials.areas, area_cap).reshape(n_nodes, n_k, n_worlds)
        scores = potentials.mean(axis=2)  # (nodes, K)
        node_firsts = np.where(firsts[:, None] < 0, ks[None, :], firsts[:, None])
        order = np.argsort(scores, axis=None, kind="stable")
        best = int(order[0])
        best_first, best_score = int(node_firsts.reshape(-1)[best]), float(scores.reshape(-1)[best])
        if level == depth - 1:
            break
        keep = order[: min(width, order.size)]
        node_index, k_index = np.unravel_index(keep, scores.shape)
        chosen = (node_index * n_k + k_index)[:, None] * n_worlds + np.arange(n_worlds)[None, :]
        chosen_rows = chosen.reshape(-1).astype(np.int64)
        maps = trials.take(chosen_rows, into=batches.get(("beam", chosen_rows.size)))
        batches["beam", chosen_rows.size] = maps
        positions = ends[node_index, k_index]
        headings = new_headings[node_index, k_index]
        firsts = node_firsts[node_index, k_index]
    return best_first, best_score


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
    ) -> None:
        for value, label in ((depth, "depth"), (width, "width"), (hypotheses, "hypotheses")):
            int_at_least(value, 1, label)
        super().__init__(env, n_turns=n_turns, lengths=lengths)
        self.depth, self.width, self.hypotheses = depth, width, hypotheses
        self.min_baseline = float(bearing_env_of(env).config.layout.arena.min_baseline)
        self.planning_times: list[float] = []
        #: The beam's copies of the map, by role and size, refilled at each decision.
        self._beam: dict[tuple[str, int], BatchedPolygonSLAM] = {}

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.planning_times = []

    def _choose(self, view: ObservationView, slam: PolygonSLAM) -> Movement:
        pose = self.belief.pose(slam)
        if pose is None or pose.metres_per_unit is None:
            return self._bootstrap(view)
        scale = pose.metres_per_unit
        started = time.perf_counter()
        worlds = self._worlds(slam, pose.position)

        def mover(positions: ComplexArray, headings: FloatArray, lengths: FloatArray) -> FloatArray:
            metres = np.where(lengths >= self.min_baseline, lengths, 0.0)
            shape = (positions.shape[0], lengths.size, positions.shape[1])
            return np.broadcast_to((metres / scale)[None, :, None], shape)

        sensor = self._sensor(view, pose, worlds.landmarks)
        movement = self._search(view, slam, worlds, pose.heading, mover, sensor)
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
            return self._bootstrap(view)
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

    One world, the truth: true landmarks and pose, the true FL scale, and every planned
    move cut where the true arena wall would stop it. It reads ground truth, so it is not
    a robot policy: it bounds what this search could do with a perfect map. ``hypotheses``
    is ignored (there is one world).
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
        arena, margin = world.arena, world.arena.wall_margin
        rotation = unit / scale

        def mover(positions: ComplexArray, headings: FloatArray, lengths: FloatArray) -> FloatArray:
            out = np.empty((positions.shape[0], lengths.size, positions.shape[1]))
            for n in range(positions.shape[0]):
                for h in range(positions.shape[1]):
                    at = origin + unit * positions[n, h]
                    for k in range(lengths.size):
                        direction = float(np.angle(np.exp(1j * headings[n, k]) * rotation))
                        free = arena.free_distance((at.real, at.imag), direction, margin)
                        travelled = min(float(lengths[k]), free)
                        out[n, k, h] = 0.0 if travelled < self.min_baseline else travelled / scale
            return out

        started = time.perf_counter()
        movement = self._search(view, slam, worlds, heading_fl, mover)
        self.planning_times.append(time.perf_counter() - started)
        return movement
