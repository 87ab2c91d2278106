"""Hand-written exploration policies: the paper's random polygonal trajectory, parallax,
and the one-step greedy planners (on the robot's map, and on the true map)."""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.core import WorldView
from bearing_env.numerics import wrap, wrap_angle
from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM, world_to_fl
from bearing_env.validation import int_at_least

from .base import Action, ActionCodec, Movement, policy_rng
from .belief import (
    ObservationReader,
    ObservationView,
    PoseBelief,
    RobotBelief,
    resect_position,
    spread_turn,
)
from .env_access import MapReader, bearing_env_of, world_of
from .hypotheses import HypothesisPlanner, RayMemory
from .planning import (
    ComplexArray,
    FloatArray,
    Sensor,
    Worlds,
    landmark_positions_fl,
    simulate_potentials,
    uncertainty_potential,
)
from .visibility import (
    BUMP_RADIUS,
    OBSTACLE_RADIUS,
    TOO_CLOSE,
    BearingMemory,
    TrueSensor,
    VisibilityPredictor,
    keep_in_view,
    travel_until,
)

#: The largest region (FL units²) of a mapped landmark whose estimate is precise enough
#: to resect the robot's position from its bearing (a limited camera).
RESECTION_AREA = 0.5
#: Turns tried by the bootstrap move on the continuous id (every 5 degrees).
BOOTSTRAP_TURNS = 72
#: After a move stopped by the wall, turns closer than this to straight ahead are avoided:
#: the wall is (roughly) in front.
BLOCKED_AHEAD = math.pi / 3
#: After a move stopped by the wall, only turns within this of the landmarks' direction
#: are considered (back toward the inside of the arena).
INWARD_AFTER_BLOCK = math.pi / 3


class MovementPolicy:
    """Shared plumbing: the action codec, the observation and map readers and the rng.

    Subclasses act on the observation and on ``info["robot_map"]`` (the robot's own map,
    see :mod:`bearing_env.agents.env_access`), never on the live env: they run the same on
    a vector env's rows (:class:`bearing_env.agents.vector.VectorPolicy`) and on remote or
    pickled copies of the env.
    """

    name = "movement_policy"
    #: True for policies that read ground truth (an upper reference, not a robot policy).
    privileged = False
    #: True for policies that read the robot's map (``info["robot_map"]``): they refuse
    #: an env made with ``robot_map_info=False`` when they are built.
    reads_robot_map = False

    def __init__(self, env: gym.Env) -> None:
        self.env = env
        self.codec = ActionCodec(env)
        self.reader = ObservationReader(env)
        self.maps = MapReader(env)
        if self.reads_robot_map:
            self.maps.require(type(self).__name__)
        self.rng = policy_rng(None)
        #: Where a privileged policy reads the truth: the env's world (a vector env's
        #: row, under :class:`~bearing_env.agents.vector.VectorPolicy`). Robot policies
        #: never call it.
        self.world_source: Callable[[], WorldView] = partial(world_of, env)

    def reset(self, seed: int | None = None) -> None:
        self.rng = policy_rng(seed)

    def act(self, observation: NDArray[np.float32], info: dict[str, Any]) -> Action:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"


def _bootstrap_turns(codec: ActionCodec) -> NDArray[np.float64]:
    if codec.discrete:
        return codec.turn_table.copy()
    turns = 2.0 * math.pi * np.arange(BOOTSTRAP_TURNS) / BOOTSTRAP_TURNS
    return wrap_angle(turns)


def landmark_direction(bearings: NDArray[np.float64]) -> float | None:
    """Direction (relative to the heading) of the landmarks as a group: the circular mean
    of their bearings; None when they surround the robot (no clear direction)."""
    total = complex(np.sum(np.cos(bearings)), np.sum(np.sin(bearings)))
    if bearings.size == 0 or abs(total) < 0.25 * bearings.size:
        return None
    return math.atan2(total.imag, total.real)


def _allowed_turns(
    turns: NDArray[np.float64], view: ObservationView, fallback: bool = True
) -> NDArray[np.bool_]:
    """Which turns to consider: all, unless the last move was stopped by a wall.

    The robot does not know where the walls are, but it knows it hit one roughly ahead,
    and the landmarks stand inside the arena: after a blocked move it only considers turns
    away from straight ahead and back toward the landmarks (within 60 degrees of the
    circular mean of their bearings).
    """
    if not view.blocked:
        return np.ones(turns.shape, dtype=bool)
    allowed = np.abs(turns) >= BLOCKED_AHEAD
    inward = landmark_direction(view.seen_bearings)
    if inward is not None:
        allowed &= np.cos(turns - inward) > math.cos(INWARD_AFTER_BLOCK)
    if fallback and not allowed.any():
        return np.ones(turns.shape, dtype=bool)
    return allowed


def bootstrap_movement(
    codec: ActionCodec,
    view: ObservationView,
    memory: NDArray[np.float64] | None = None,
    half_fov: float = math.pi,
    obstacles: NDArray[np.complex128] | None = None,
) -> Movement:
    """The move made before there is a map (or a scale): longest length, in the direction
    that keeps every landmark farthest from the line of motion (see ``spread_turn``).

    With a forward camera (``half_fov`` below pi) and the robot's ``memory`` of bearings
    (:class:`~bearing_env.agents.visibility.BearingMemory`) it turns to keep L1, L2 and
    as many landmarks as it can in view instead (:func:`limited_view_movement`).
    ``obstacles``: where moves were blocked (metres, in the robot's frame, heading 0):
    only the turns that get furthest before them are considered."""
    turns = _bootstrap_turns(codec)
    if obstacles is not None and obstacles.size:
        travelled = travel_until(
            np.zeros(turns.size, dtype=np.complex128), turns, np.full(turns.size, codec.max_length),
            obstacles, OBSTACLE_RADIUS,
        )  # fmt: skip
        turns = turns[travelled >= travelled.max() - 1e-12]
    if memory is not None and half_fov < math.pi:
        return limited_view_movement(codec, view, turns, memory, half_fov)
    allowed = _allowed_turns(turns, view)
    inward = landmark_direction(view.seen_bearings)
    if inward is not None and np.any(allowed & (np.cos(turns - inward) > 0.0)):
        # |sin| does not tell a direction from its opposite: take the one toward the
        # landmarks, away from the walls.
        allowed &= np.cos(turns - inward) > 0.0
    choice = spread_turn(view.seen_bearings if view.seen.any() else view.bearings, turns[allowed])
    return codec.movement(float(turns[allowed][choice]), codec.max_length)


def limited_view_movement(
    codec: ActionCodec,
    view: ObservationView,
    turns: NDArray[np.float64],
    memory: NDArray[np.float64],
    half_fov: float,
) -> Movement:
    """The bootstrap move of a forward camera: while L1 or L2 has never been seen, turn
    most of a field of view on and make the shortest move (looking around); then the
    longest move in the turn that keeps the most remembered landmarks in view, L1 and L2
    first (:func:`~bearing_env.agents.visibility.keep_in_view`), among the turns allowed
    after a blocked move when there are such. A landmark ahead drifts out of a forward
    view as the robot nears it: when L1 and L2 are too far apart in the view (more than
    :data:`~bearing_env.agents.visibility.TOO_CLOSE` of its half-width, the robot is too
    close to both to keep them in view over a move) it backs off first, the longest move
    away from them, unless a wall just stopped it."""
    if memory.size < 2 or not np.all(np.isfinite(memory[:2])):
        return codec.movement(wrap(min(1.8 * half_fov, math.pi)), codec.length_range[0])
    if not view.blocked and abs(wrap(float(memory[0] - memory[1]))) > TOO_CLOSE * half_fov:
        between = math.atan2(math.sin(memory[0]) + math.sin(memory[1]),
                             math.cos(memory[0]) + math.cos(memory[1]))  # fmt: skip
        return codec.movement(wrap(between + math.pi), codec.max_length)
    scores = keep_in_view(memory, turns, half_fov)
    allowed = _allowed_turns(turns, view, fallback=False)
    if allowed.any():
        scores = np.where(allowed, scores, -np.inf)
    return codec.movement(float(turns[int(np.argmax(scores))]), codec.max_length)


class RandomPolygonal(MovementPolicy):
    """The paper's trajectory: a uniformly random rotation on the spot, then a straight line.

    Args:
        env: the env it acts in (either id).
        length: metres per move; None (default) draws it uniformly over the env's
            ``move_length`` range (the range's only value if the env's length is fixed).
            On the discrete id: the nearest length of the table, or a random one.
    """

    name = "random_polygonal"

    def __init__(self, env: gym.Env, length: float | None = None) -> None:
        super().__init__(env)
        lo, hi = self.codec.length_range
        if length is not None:
            length = float(length)
            if not lo - 1e-12 <= length <= hi + 1e-12:
                raise ValueError(
                    f"length {length!r} m is outside the env's move_length range "
                    f"({lo:g}, {hi:g}); pass move_length to the env to change it"
                )
        self.length = length

    def act(self, observation: NDArray[np.float32], info: dict[str, Any]) -> Action:
        # Both draws every step, so the turn sequence does not depend on the length option.
        turn_unit = self.rng.uniform(-1.0, 1.0)
        length_unit = self.rng.uniform(0.0, 1.0)
        lo, hi = self.codec.length_range
        length = self.length if self.length is not None else lo + length_unit * (hi - lo)
        if self.codec.discrete:
            n_turns, n_lengths = self.codec.turn_table.size, self.codec.length_table.size
            turn_index = min(int(0.5 * (turn_unit + 1.0) * n_turns), n_turns - 1)
            if self.length is None:
                length_index = min(int(length_unit * n_lengths), n_lengths - 1)
            else:
                length_index = int(np.argmin(np.abs(self.codec.length_table - self.length)))
            return int(turn_index * n_lengths + length_index)
        return self.codec.encode(math.pi * turn_unit, length)


#: Parallax's ways of choosing between the two directions across the line of sight.
PARALLAX_SIGN_RULES: tuple[str, ...] = ("inward", "axis")


class BeliefPolicy(MovementPolicy):
    """A :class:`MovementPolicy` that tracks its own pose from the map, its commands and
    the observation (:class:`RobotBelief`), reset with each episode."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.belief = RobotBelief(bearing_env_of(env).epsilon)
        #: The camera's half field of view (pi: panoramic) and the remembered bearings.
        self.half_fov = VisibilityPredictor(env).half_fov
        self.memory = BearingMemory()

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.belief.reset()
        self.memory.reset()

    def _observe(self, view: ObservationView) -> None:
        """Take in the observation: the pose belief and the bearing memory."""
        self.belief.observe(view)
        self.memory.observe(view.bearings, view.seen, view.progress == 0.0)

    def _commanded(self, movement: Movement, view: ObservationView) -> None:
        remembered = self.memory.bearings if self.half_fov < math.pi else None
        self.belief.commanded(movement, view, remembered)
        self.memory.commanded(movement.turn)

    def _bootstrap(self, view: ObservationView) -> Movement:
        return bootstrap_movement(self.codec, view, self.memory.bearings, self.half_fov)


class Parallax(BeliefPolicy):
    """Move perpendicular to the line of sight of the most uncertain landmark.

    The most uncertain landmark is the one with the largest region (an uninitialised one
    first). A move across its line of sight gives the largest bearing change between the
    two readings, hence the narrowest region in depth. Two directions are perpendicular
    to the line of sight; ``sign_rule`` picks one:

    - ``"inward"`` (default): the one closer to the direction of the landmarks as a group
      (the circular mean of their bearings). The landmarks stand inside the arena, so
      this keeps the robot away from the walls it cannot see;
    - ``"axis"``: the one that brings the line of sight closer to perpendicular to the
      long axis of the landmark's region, so that the bearing cone cuts the region
      across (the axis is the region's principal axis in FL, compared from the robot's
      believed pose).

    Measured on 60 Khepera episodes, median total area after 10 moves: 0.41 with
    ``"inward"``, 0.63 with ``"axis"`` (which runs into walls more: 3.8 blocked moves per
    episode against 2.7). After a move stopped by the wall, only a perpendicular that
    heads back toward the landmarks is taken; if neither does, the robot heads straight
    for the landmarks. The first move, before there is a map, is the bootstrap move
    (see :func:`bootstrap_movement`). Uses only the robot's map, its own commands and the
    observation, never ground truth.

    With a forward camera (``field_of_view_deg`` below 360 for the env) a landmark at
    right angles to the move is out of view at both readings, so the move crosses the
    line of sight at the widest angle that keeps the landmark in view (80% of half the
    field of view); a target the last reading missed is aimed at from its estimate and
    the believed pose.

    Args:
        env: the env it acts in (either id).
        length: metres per move; default the longest the env allows.
        sign_rule: ``"inward"`` or ``"axis"`` (above).
    """

    name = "parallax"
    reads_robot_map = True  # its belief of the pose and its target come from the map

    def __init__(
        self, env: gym.Env, length: float | None = None, sign_rule: str = "inward"
    ) -> None:
        super().__init__(env)
        if sign_rule not in PARALLAX_SIGN_RULES:
            raise ValueError(f"sign_rule must be one of {PARALLAX_SIGN_RULES}, got {sign_rule!r}")
        self.length = self.codec.max_length if length is None else float(length)
        self.sign_rule = sign_rule
        half_fov = VisibilityPredictor(env).half_fov
        #: The angle between the move and the line of sight to the target.
        self.across = math.pi / 2 if half_fov >= math.pi / 2 else 0.8 * half_fov

    def act(self, observation: NDArray[np.float32], info: dict[str, Any]) -> Action:
        view = self.reader.read(observation)
        self._observe(view)
        slam = self.maps.read(info, view.n_landmarks)
        pose = self.belief.pose(slam)
        if pose is None:
            movement = self._bootstrap(view)
        else:
            movement = self.codec.movement(self._turn(view, slam, pose), self.length)
        self._commanded(movement, view)
        return movement.action

    def _turn(self, view: ObservationView, slam: PolygonSLAM, pose: PoseBelief) -> float:
        target = int(np.argmax(slam.areas))  # inf (uninitialised) first
        sight = _sight(view, slam, pose, target)
        options = np.array([wrap(sight + self.across), wrap(sight - self.across)])
        inward = landmark_direction(view.seen_bearings)
        if view.blocked:
            allowed = _allowed_turns(options, view, fallback=False)
            if not allowed.any():
                # Both perpendiculars run along or into the wall: head back inside first.
                return 0.0 if inward is None else inward
            options = options[allowed]
        if options.size == 1:
            return float(options[0])
        if self.half_fov < math.pi:
            # A forward camera: the perpendicular that keeps L1 and L2 in view.
            scores = keep_in_view(self.memory.bearings, options, self.half_fov)
            if scores[0] != scores[1]:
                return float(options[int(np.argmax(scores))])
        if self.sign_rule == "inward" and inward is not None:
            return float(options[int(np.argmax(np.cos(options - inward)))])
        polygon = slam.polygons[target]
        if polygon is None or pose.metres_per_unit is None:
            return float(options[np.argmin(np.abs(options))])
        axis = _principal_axis(polygon)
        estimate = complex(*slam.estimates[target])
        distance = self.length / pose.metres_per_unit
        across = []
        for turn in options:
            heading = pose.heading + float(turn)
            end = pose.position + distance * complex(math.cos(heading), math.sin(heading))
            # |sin| of the angle between the new line of sight and the long axis.
            across.append(abs(math.sin(np.angle(estimate - end) - axis)))
        return float(options[int(np.argmax(across))])


def _sight(view: ObservationView, slam: PolygonSLAM, pose: PoseBelief, target: int) -> float:
    """The bearing of mapped landmark ``target``: as read, or (missed) as predicted from
    its estimate and the believed pose, or straight ahead when it has no estimate."""
    if view.seen[2 + target]:
        return float(view.bearings[2 + target])
    estimate = complex(*slam.estimates[target])
    if not (math.isfinite(estimate.real) and math.isfinite(estimate.imag)):
        return 0.0
    return wrap(float(np.angle(estimate - pose.position)) - pose.heading)


def _principal_axis(polygon: NDArray[np.float64]) -> float:
    """Direction (radians) of the long axis of a polygon's vertex cloud."""
    centred = polygon - polygon.mean(axis=0)
    _, _, vh = np.linalg.svd(centred, full_matrices=False)
    return float(math.atan2(vh[0, 1], vh[0, 0]))


class GreedyOneStep(BeliefPolicy):
    """One-step greedy planner on the robot's own map.

    For each of K candidate movements (``n_turns`` turns x ``lengths`` lengths, K = 16 by
    default; on the discrete id the table's turns x its ``lengths`` longest lengths), it
    simulates the SLAM update on a copy of the robot's map with noise-free bearings from
    the *estimated* map (L1 = 0, L2 = 1, the landmark centroids, the robot's believed pose:
    see :mod:`bearing_env.agents.belief`) and takes the move whose predicted sum of capped log areas
    is lowest, i.e. the largest expected decrease of the env's default potential.
    Landmarks not yet initialised count at the env's ``area_cap`` and cannot be simulated
    (no predicted progress). It never reads ground truth: of ``info`` only the robot's
    own map (``info["robot_map"]``), no world.

    Before the first movement that changes frames (no map, no pose, or no FL scale yet)
    it makes the bootstrap move (longest length, every landmark away from the line of
    motion); also when no candidate is predicted to help. The robot does not know where
    the walls are, so the simulation ignores them; instead, after a move stopped by a wall
    it only considers turns away from straight ahead and back toward the landmarks (see
    ``_allowed_turns``). Without that rule it got stuck in corners, bouncing between two
    walls with moves too short to change frames.

    Scoring fuses every candidate into its own copy of the map in one batched update
    (``PolygonSLAM.replicate``; see :func:`bearing_env.agents.planning.simulate_potentials`).

    With ``predict_visibility`` (the default) the simulated readings miss what the robot
    expects its sensor to miss (:class:`~bearing_env.agents.visibility.VisibilityPredictor`:
    its field of view and range, obstacles where it bumped into them): with a forward
    camera a move that turns L1 or L2 out of view predicts no progress, as the real
    update skips it. With the paper's panoramic camera it changes nothing.

    With a limited camera (a forward field of view or a range) the moves the map gives
    nothing to plan on are planned in hypothesised worlds
    (:mod:`bearing_env.agents.hypotheses`; the shortest plan predicted to help, up to
    ``bootstrap_depth`` moves), and the believed position is resected from the latest
    bearings of L1 and L2 (:func:`~bearing_env.agents.belief.resect_position`). With a
    limited camera or obstacles in the arena, simulated moves stop at the places where
    moves were blocked, and so does the bootstrap's choice of turn.

    Args:
        env: the env it acts in (either id).
        n_turns: turns evenly spaced over the circle (continuous id; the discrete id
            uses its table's turns).
        lengths: number of lengths, evenly spaced down from the longest to the shortest
            of the env's range, or explicit lengths in metres (continuous id); on the
            discrete id, how many of the table's lengths to use, longest first.
        predict_visibility: simulate missed readings (above); False simulates the
            panoramic camera whatever the env's sensor.
        bootstrap_worlds: with a limited camera, the worlds the moves the map gives
            nothing to plan on are planned in
            (:class:`~bearing_env.agents.hypotheses.HypothesisPlanner`); 0: the
            bearing-memory bootstrap alone. Unused with the panoramic camera.
        bootstrap_depth: the longest plan tried there (the shortest that helps wins).
    """

    name = "greedy_one_step"
    reads_robot_map = True

    def __init__(
        self,
        env: gym.Env,
        n_turns: int = 8,
        lengths: int | tuple[float, ...] = 2,
        predict_visibility: bool = True,
        bootstrap_worlds: int = 8,
        bootstrap_depth: int = 2,
    ) -> None:
        super().__init__(env)
        self.visibility = VisibilityPredictor(env) if predict_visibility else None
        #: Plans the moves before the map with a limited camera (None: panoramic, or
        #: ``bootstrap_worlds=0``).
        self.before_map: HypothesisPlanner | None = None
        camera = VisibilityPredictor(env)
        if camera.limited and int(bootstrap_worlds) > 0:
            self.before_map = HypothesisPlanner(
                self.codec,
                float(bearing_env_of(env).config.layout.arena.min_baseline),
                float(bearing_env_of(env).config.task.area_cap),
                self.visibility,
                hypotheses=int(bootstrap_worlds),
            )
        #: Plan moves around the places where moves were blocked (:attr:`bumps`): with a
        #: limited camera, or in an arena that has obstacles (the robot is told it is in
        #: a furnished room, not where the furniture stands).
        self.avoid_bumps = camera.limited or bool(bearing_env_of(env).config.layout.obstacles)
        #: Where moves were blocked this episode (FL, just ahead of the believed pose).
        self.bumps: list[complex] = []
        self.min_baseline = float(bearing_env_of(env).config.layout.arena.min_baseline)
        #: Where the robot saw each landmark (odometry rays), for the hypothesised worlds.
        self.rays = RayMemory(bearing_env_of(env).epsilon)
        #: The last resected position (FL) and the last commanded (turn, length).
        self._resected: complex | None = None
        self._last_move = (0.0, 0.0)
        #: The longest plan (moves) tried in hypothesised worlds.
        self.bootstrap_depth = int_at_least(bootstrap_depth, 1, "bootstrap_depth")
        if int(n_turns) < 1:
            raise ValueError(f"n_turns must be >= 1, got {n_turns!r}")
        self.candidates = self.codec.candidates(int(n_turns), lengths)
        # The candidates as arrays: scoring makes no Python object per candidate.
        self._turns = np.array([c.turn for c in self.candidates], dtype=np.float64)
        self._lengths = np.array([c.length for c in self.candidates], dtype=np.float64)
        #: Copies of the map to score candidates on, by count, refilled at each decision.
        self._trials: dict[int, BatchedPolygonSLAM] = {}
        #: The robot's map of the last decision, overwritten by the next info's.
        self._map: PolygonSLAM | None = None
        self.area_cap = float(bearing_env_of(env).config.task.area_cap)
        # Score moves with the potential the env rewards (reward="log_area" or "area").
        self.log_area = bearing_env_of(env).config.task.reward == "log_area"

    def act(self, observation: NDArray[np.float32], info: dict[str, Any]) -> Action:
        view = self.reader.read(observation)
        self._observe(view)
        self._map = self.maps.read(info, view.n_landmarks, into=self._map)
        movement = self._choose(view, self._map)
        self._commanded(movement, view)
        return movement.action

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.rays.reset()
        self.bumps = []
        self._resected = None
        self._last_move = (0.0, 0.0)
        if self.visibility is not None:
            self.visibility.reset()

    def _observe(self, view: ObservationView) -> None:
        super()._observe(view)
        self.rays.observe(view.bearings, view.seen, view.progress == 0.0, view.blocked)

    def _commanded(self, movement: Movement, view: ObservationView) -> None:
        super()._commanded(movement, view)
        self.rays.commanded(movement.turn, movement.length)
        self._last_move = (movement.turn, movement.length)

    def _sensor(
        self, view: ObservationView, pose: PoseBelief, landmarks: NDArray[np.complex128]
    ) -> Sensor | None:
        """The visibility prediction of this decision (None: every landmark seen), after
        recording a bump when the last move was blocked."""
        if self.visibility is None or pose.metres_per_unit is None:
            return None
        if view.blocked:
            self.visibility.bumped(pose.position, pose.heading, pose.metres_per_unit)
        if self.visibility.trivial:
            return None
        return partial(
            self.visibility.missed, landmarks=landmarks, metres_per_unit=pose.metres_per_unit
        )

    def _bootstrap(self, view: ObservationView) -> Movement:
        obstacles = self.rays.bump_offsets() if self.avoid_bumps else None
        return bootstrap_movement(
            self.codec, view, self.memory.bearings, self.half_fov, obstacles=obstacles
        )

    def _without_map(
        self, view: ObservationView, slam: PolygonSLAM, pose: PoseBelief | None = None
    ) -> Movement:
        """The move when the map gives nothing to plan on. With a limited camera it is
        planned in hypothesised worlds (:class:`~bearing_env.agents.hypotheses.HypothesisPlanner`):
        in FL, from the map and the believed ``pose`` with a scale, the landmarks not yet
        mapped where the robot remembers them; or, while no landmark is mapped, in the
        robot's own frame. Else (or when that predicts no progress) the bootstrap."""
        memory = self.memory.bearings
        planner = self.before_map
        if planner is None or memory.size < 2 or not np.all(np.isfinite(memory[:2])):
            return self._bootstrap(view)
        allowed = _allowed_turns(planner.turns, view)
        movement = None
        offsets = self.rays.offsets(planner.hypotheses, planner.ranges, self.rng)
        scale = None if pose is None else pose.metres_per_unit
        if pose is not None and scale is None:
            # No scale from the map's movements yet: |L1 - L2| in metres as the rays put it.
            spans = np.abs(offsets[:, 0] - offsets[:, 1])
            scale = float(np.median(spans)) if np.all(np.isfinite(spans)) else None
        if pose is not None and scale is not None:
            worlds = planner.fill_unmapped(
                self._map_worlds(slam, pose.position, planner.hypotheses),
                offsets, pose.heading, scale, self._vague(slam),
            )  # fmt: skip
            bumps = np.array(self.bumps, dtype=np.complex128)
            movement = self._shortest_plan(slam, worlds, pose.heading, scale, allowed, bumps)
        elif not np.any(np.isfinite(slam.areas)):
            worlds = planner.robot_frame_worlds(offsets)
            movement = self._shortest_plan(
                slam, worlds, 0.0, 1.0, allowed, self.rays.bump_offsets(), in_fl=False
            )
        return self._bootstrap(view) if movement is None else movement

    def _record_bump(self, view: ObservationView, pose: PoseBelief) -> None:
        """After a blocked move, remember (FL) that something stands just ahead."""
        if view.blocked and pose.metres_per_unit is not None:
            ahead = (BUMP_RADIUS / pose.metres_per_unit) * np.exp(1j * pose.heading)
            self.bumps.append(pose.position + ahead)

    def _shortest_plan(
        self,
        slam: PolygonSLAM,
        worlds: Worlds,
        heading: float,
        metres_per_unit: float,
        allowed: NDArray[np.bool_],
        obstacles: ComplexArray,
        in_fl: bool = True,
    ) -> Movement | None:
        """The first move of the shortest plan (1, 2, ... :attr:`bootstrap_depth` moves)
        predicted to help in hypothesised worlds: when no move helps at once, a pair of
        moves whose first one leads to a better view (a deeper plan's first move more
        often runs into walls the robot does not know)."""
        assert self.before_map is not None
        for depth in range(1, self.bootstrap_depth + 1):
            movement = self.before_map.plan(
                slam, worlds, heading, metres_per_unit, allowed, depth,
                with_bumps=in_fl, obstacles=obstacles,
            )  # fmt: skip
            if movement is not None:
                return movement
        return None

    def _vague(self, slam: PolygonSLAM) -> NDArray[np.bool_]:
        """Which landmarks (n,) the map places too vaguely to plan on (a region at the
        cap or wider: its centroid can be far off): the hypothesised worlds put them
        where the robot saw them instead."""
        return np.concatenate([[False, False], ~(slam.areas < self.area_cap)])

    def _map_worlds(self, slam: PolygonSLAM, position: complex, count: int) -> Worlds:
        """``count`` copies of the map's world: its estimates and the believed position."""
        landmarks = np.broadcast_to(landmark_positions_fl(slam), (count, slam.n_landmarks))
        return Worlds(landmarks.copy(), np.full(count, position, dtype=np.complex128))

    def _pose(self, view: ObservationView, slam: PolygonSLAM) -> PoseBelief | None:
        """The believed pose; with a limited camera its position is resected from the
        latest reading of L1, L2 and the landmarks mapped within :data:`RESECTION_AREA`
        when it saw two of them (the map's robot region is wide when few movements
        changed frames)."""
        pose = self.belief.pose(slam)
        if pose is None or self.before_map is None:
            return pose
        landmarks = landmark_positions_fl(slam)
        sharp = np.concatenate([[True, True], slam.areas <= RESECTION_AREA])
        position = resect_position(
            pose.heading, view.readings, np.where(sharp, landmarks, complex(np.nan, np.nan))
        )
        if position is None and self._resected is not None and pose.metres_per_unit is not None:
            # Not resected now: the last resection carried by the move made since.
            _, length = self._last_move
            ahead = (length / pose.metres_per_unit) * np.exp(1j * pose.heading)
            position = self._resected + (0.5 if view.blocked else 1.0) * ahead
        self._resected = position
        if position is None:
            return pose
        return PoseBelief(position, pose.heading, pose.metres_per_unit)

    def _travel(
        self, positions: ComplexArray, headings: FloatArray, lengths: FloatArray, scale: float
    ) -> FloatArray:
        """FL distances of moves of ``lengths`` metres: cut at the recorded bumps when the
        policy avoids them (0 below the minimum baseline), else the full lengths."""
        distances = np.asarray(lengths / scale, dtype=np.float64)
        if not (self.avoid_bumps and self.bumps):
            return distances
        obstacles = np.array(self.bumps, dtype=np.complex128)
        cut = travel_until(positions, headings, distances, obstacles, OBSTACLE_RADIUS / scale)
        return np.where(cut * scale >= self.min_baseline, cut, 0.0)

    def _choose(self, view: ObservationView, slam: PolygonSLAM) -> Movement:
        pose = self._pose(view, slam)
        if pose is None or pose.metres_per_unit is None:
            return self._without_map(view, slam, pose)
        self._record_bump(view, pose)
        allowed = np.flatnonzero(_allowed_turns(self._turns, view))
        landmarks = landmark_positions_fl(slam)
        headings = pose.heading + self._turns[allowed]
        potentials = simulate_potentials(
            slam, pose.position, landmarks, headings,
            self._travel(np.array(pose.position), headings, self._lengths[allowed],
                         pose.metres_per_unit),
            self.area_cap, log_area=self.log_area, scratch=self._trials,
            sensor=self._sensor(view, pose, landmarks),
        )  # fmt: skip
        if np.min(potentials) >= uncertainty_potential(slam.areas, self.area_cap, self.log_area):
            # No candidate is predicted to help (e.g. every landmark is uninitialised).
            return self._without_map(view, slam, pose)
        return self.candidates[int(allowed[int(np.argmin(potentials))])]


class GreedyOracle(GreedyOneStep):
    """PRIVILEGED upper reference: :class:`GreedyOneStep` on the *true* map.

    Same candidates and the same scoring (simulated updates of the robot's current map),
    but the bearings are simulated from the true landmark positions and the true robot
    pose, the FL scale is the true ``|L1 - L2|``, each candidate's length is cut where the
    true arena wall or an obstacle would stop it, and a bearing the real sensor would miss
    (field of view, range, line of sight) is missed
    (:class:`~bearing_env.agents.visibility.TrueSensor`). It reads ground truth, so it is
    not a robot policy: it bounds what one-step planning could do.
    """

    name = "greedy_oracle"
    privileged = True

    def _choose(self, view: ObservationView, slam: PolygonSLAM) -> Movement:
        world = self.world_source()
        l1, l2 = world.landmarks[0], world.landmarks[1]
        baseline = complex(*(l2 - l1))
        metres_per_unit = abs(baseline)
        position = world_to_fl(world.position, l1, l2)
        heading_fl = world.heading - math.atan2(baseline.imag, baseline.real)
        truth = world_to_fl(world.landmarks, l1, l2)
        sensor = TrueSensor(world)  # the real field of view, range and obstacles
        distances = np.empty(len(self.candidates), dtype=np.float64)
        for k, candidate in enumerate(self.candidates):
            heading = world.heading + candidate.turn
            travelled = sensor.travel(world.position, heading, candidate.length)
            distances[k] = travelled / metres_per_unit
        potentials = simulate_potentials(
            slam,
            complex(position[0], position[1]),
            truth[:, 0] + 1j * truth[:, 1],
            heading_fl + self._turns,
            distances,
            self.area_cap,
            log_area=self.log_area,
            scratch=self._trials,
            sensor=None if sensor.trivial else sensor,
        )
        if np.min(potentials) >= uncertainty_potential(slam.areas, self.area_cap, self.log_area):
            return bootstrap_movement(self.codec, view)
        return self.candidates[int(np.argmin(potentials))]
