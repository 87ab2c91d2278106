"""The observation specs: one per observation kind, the one home of its features, its
space and its conversion from the flat vector the kernels write.

Every observation starts as the flat vector (float32) that
``bearing_env.envs.kernels._write_observation`` writes: the robot block
(:data:`ROBOT_FEATURES`), one block per mapped landmark slot L3, L4, ...
(:data:`LANDMARK_FEATURES`), then one block per bearing slot L1, L2, ...
(:data:`BEARING_FEATURES`). The kernels' block sizes are the lengths of these tuples.

* :data:`FLAT` (``observation="flat"``, the default): that vector, a ``Box``.
* :data:`ENTITIES` (``observation="entities"``): a ``Dict`` of the robot block and a
  landmark table, a row per slot with the columns :data:`ENTITY_FEATURES` (the same
  numbers, rearranged).
* :data:`SHAPES` (``observation="shapes"``): the entity observation with three more
  columns per row, :data:`SHAPE_FEATURES`: the shape of each landmark's region (how
  elongated, along which axis). The kernels then write one more block per mapped slot at
  the end of the flat vector.

An env picks its spec once (:func:`spec_for`); the rest asks the spec.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.envs import candidates
from bearing_env.envs.config import AREA_FLOOR, EnvConfig

#: The robot block, first in the flat vector.
ROBOT_FEATURES: tuple[str, ...] = (
    "robot_x",
    "robot_y",
    "robot_log_area",
    "robot_unknown",
    "heading_cos",
    "heading_sin",
    "progress",
    "last_frame_changed",
    "last_move_blocked",
)
#: One block per mapped landmark slot (L3, L4, ...), after the robot block.
LANDMARK_FEATURES: tuple[str, ...] = ("present", "uninitialised", "x", "y", "log_area")
#: One block per bearing slot (L1, L2, L3, ...), last.
BEARING_FEATURES: tuple[str, ...] = ("present", "cos", "sin")

#: The columns of the entity observation's landmark table, one row per landmark slot
#: (L1, L2, L3, ...): present, is-frame (L1 and L2, fixed at (0, 0) and (1, 0) in FL),
#: not initialised yet, the estimate in FL, the log-area, and the latest bearing.
ENTITY_FEATURES: tuple[str, ...] = (
    "present",
    "is_frame",
    "uninitialised",
    "x",
    "y",
    "log_area",
    "bearing_cos",
    "bearing_sin",
)

#: The shape of a landmark's region, in the ``"shapes"`` kind, from the second moments
#: of its area: ``elongation`` is half the log of the ratio of the principal moments (the
#: log of the axis ratio of the ellipse of the same moments: 0 when round, clipped to
#: :data:`ELONGATION_LIMIT`), ``axis_cos2``/``axis_sin2`` the long axis's direction
#: theta in FL as (cos 2 theta, sin 2 theta) (an axis has no sign; (0, 0) when round).
#: Zeros for a landmark without a region yet (and for L1, L2).
SHAPE_FEATURES: tuple[str, ...] = ("elongation", "axis_cos2", "axis_sin2")
#: The elongation's upper bound (an axis ratio of e**10, about 22,000; the native core's
#: value, read from it).
ELONGATION_LIMIT: float = _core.ELONGATION_LIMIT

# The native step writes blocks of the sizes it was compiled with; the names above are
# their columns, so the two must agree (a mismatch would shift every observation).
if (len(ROBOT_FEATURES), len(LANDMARK_FEATURES), len(BEARING_FEATURES), len(SHAPE_FEATURES)) != (
    _core.ROBOT_BLOCK,
    _core.LANDMARK_BLOCK,
    _core.BEARING_BLOCK,
    _core.SHAPE_BLOCK,
):
    raise ImportError("the observation's feature names disagree with the native core's blocks")
#: The landmark table's columns in the ``"shapes"`` kind.
SHAPE_ENTITY_FEATURES: tuple[str, ...] = ENTITY_FEATURES + SHAPE_FEATURES

#: FL coordinates in the observation are clipped to +-this (the frame is |L1 - L2| = 1, so
#: this is 50 baselines away: far beyond any landmark of a sensible layout).
FL_COORD_LIMIT = 50.0


def observation_size(max_landmarks: int) -> int:
    """Length of the flat observation vector for ``max_landmarks`` landmark slots."""
    return (
        len(ROBOT_FEATURES)
        + len(LANDMARK_FEATURES) * (max_landmarks - 2)
        + len(BEARING_FEATURES) * max_landmarks
    )


def observation_slices(max_landmarks: int) -> dict[str, slice]:
    """Where each block lives in the flat observation vector.

    ``"robot"`` is the robot block; ``"landmarks"`` reshapes to ``(max_landmarks - 2,
    len(LANDMARK_FEATURES))``; ``"bearings"`` to ``(max_landmarks, len(BEARING_FEATURES))``.
    """
    robot_end = len(ROBOT_FEATURES)
    landmarks_end = robot_end + len(LANDMARK_FEATURES) * (max_landmarks - 2)
    return {
        "robot": slice(0, robot_end),
        "landmarks": slice(robot_end, landmarks_end),
        "bearings": slice(landmarks_end, observation_size(max_landmarks)),
    }


class FlatObservation:
    """``observation="flat"``: the flat vector itself (see the module doc)."""

    kind: ClassVar[str] = "flat"

    def flat_size(self, max_landmarks: int) -> int:
        """Length of the flat vector the kernels write for this kind."""
        return observation_size(max_landmarks)

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        """The Box of envs with ``config`` (the env's Observation Space section)."""
        log_min, log_max = math.log(AREA_FLOOR), math.log(config.task.area_cap)
        limit = FL_COORD_LIMIT
        # (low, high) per feature, in the order of ROBOT_, LANDMARK_ and BEARING_FEATURES.
        robot_low = [-limit, -limit, log_min, 0, -1, -1, 0, 0, 0]
        robot_high = [limit, limit, log_max, 1, 1, 1, 1, 1, 1]
        landmark_low = [0, 0, -limit, -limit, min(log_min, 0.0)]
        landmark_high = [1, 1, limit, limit, max(log_max, 0.0)]
        bearing_low, bearing_high = [0, -1, -1], [1, 1, 1]
        n_slots = config.observations.max_landmarks
        low = np.concatenate(
            [robot_low, np.tile(landmark_low, n_slots - 2), np.tile(bearing_low, n_slots)]
        )
        high = np.concatenate(
            [robot_high, np.tile(landmark_high, n_slots - 2), np.tile(bearing_high, n_slots)]
        )
        # Rounding to float32 must not leave a computed value outside its own bound.
        return spaces.Box(
            np.nextafter(low.astype(np.float32), np.float32(-np.inf)),
            np.nextafter(high.astype(np.float32), np.float32(np.inf)),
            dtype=np.float32,
        )

    def convert(self, flat: NDArray[np.float32], max_landmarks: int) -> Any:
        """The observation from flat vectors: they are it."""
        return flat


class EntityObservation:
    """``observation="entities"``: a robot block and a landmark table (see the module doc)."""

    kind: ClassVar[str] = "entities"
    #: The landmark table's columns.
    features: ClassVar[tuple[str, ...]] = ENTITY_FEATURES

    def flat_size(self, max_landmarks: int) -> int:
        """Length of the flat vector the kernels write for this kind."""
        return observation_size(max_landmarks)

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        """The flat space's bounds, rearranged as :meth:`convert` rearranges the values
        (each table column's bounds are its extremes over the slots)."""
        flat = FLAT.space(config)
        assert isinstance(flat, spaces.Box)
        slots = config.observations.max_landmarks
        convert = EntityObservation.convert  # the flat kind's vector, not a longer one
        low, high = convert(self, flat.low, slots), convert(self, flat.high, slots)
        rows = (slots, len(ENTITY_FEATURES))
        table_low = np.minimum(low["landmarks"], high["landmarks"]).reshape(rows).min(axis=0)
        table_high = np.maximum(low["landmarks"], high["landmarks"]).reshape(rows).max(axis=0)
        return spaces.Dict(
            {
                "robot": spaces.Box(low["robot"], high["robot"], dtype=np.float32),
                "landmarks": spaces.Box(
                    np.tile(table_low, slots), np.tile(table_high, slots), dtype=np.float32
                ),
            }
        )

    def convert(self, flat: NDArray[np.float32], max_landmarks: int) -> dict[str, Any]:
        """The entity view of flat observations (..., observation_size): the same numbers,
        rearranged. ``"robot"`` (..., len(ROBOT_FEATURES)) is the robot block;
        ``"landmarks"`` (..., max_landmarks * len(ENTITY_FEATURES)) is the landmark table,
        a row per slot, flattened row by row (a 1-D Box per observation, as SB3's checker
        wants: reshape to (max_landmarks, len(ENTITY_FEATURES))). L1 and L2 are the frame:
        estimate (0, 0) and (1, 0), exact (log-area ``log(AREA_FLOOR)``). Rows of absent
        landmarks are all zeros.
        """
        flat = np.asarray(flat, dtype=np.float32)
        blocks = observation_slices(max_landmarks)
        lead = flat.shape[:-1]
        mapped = flat[..., blocks["landmarks"]].reshape(*lead, max_landmarks - 2, -1)
        bearings = flat[..., blocks["bearings"]].reshape(*lead, max_landmarks, -1)
        table = np.zeros((*lead, max_landmarks, len(ENTITY_FEATURES)), dtype=np.float32)
        column = {name: index for index, name in enumerate(ENTITY_FEATURES)}
        landmark = {name: index for index, name in enumerate(LANDMARK_FEATURES)}
        bearing = {name: index for index, name in enumerate(BEARING_FEATURES)}
        table[..., column["present"]] = bearings[..., bearing["present"]]
        frame = table[..., :2, :]
        frame[..., column["is_frame"]] = frame[..., column["present"]]
        frame[..., 1, column["x"]] = frame[..., 1, column["present"]]
        exact = np.float32(math.log(AREA_FLOOR))
        frame[..., column["log_area"]] = exact * frame[..., column["present"]]
        for name in ("uninitialised", "x", "y", "log_area"):
            table[..., 2:, column[name]] = mapped[..., landmark[name]]
        table[..., column["bearing_cos"]] = bearings[..., bearing["cos"]]
        table[..., column["bearing_sin"]] = bearings[..., bearing["sin"]]
        robot = flat[..., blocks["robot"]].copy()
        return {"robot": robot, "landmarks": table.reshape(*lead, -1)}


class ShapeEntityObservation(EntityObservation):
    """``observation="shapes"``: the entity observation, each row followed by its
    region's shape (:data:`SHAPE_FEATURES`; see the module doc)."""

    kind: ClassVar[str] = "shapes"
    features: ClassVar[tuple[str, ...]] = SHAPE_ENTITY_FEATURES

    def flat_size(self, max_landmarks: int) -> int:
        return observation_size(max_landmarks) + len(SHAPE_FEATURES) * (max_landmarks - 2)

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        """The entity space with the shape columns' bounds: elongation in [0,
        ELONGATION_LIMIT], the axis in [-1, 1]^2."""
        entity = super().space(config)
        assert isinstance(entity, spaces.Dict)
        slots, width = config.observations.max_landmarks, len(ENTITY_FEATURES)
        table = entity["landmarks"]
        assert isinstance(table, spaces.Box)
        shape_low = np.array([0.0, -1.0, -1.0], dtype=np.float32)
        shape_high = np.array([ELONGATION_LIMIT, 1.0, 1.0], dtype=np.float32)
        low = np.concatenate([table.low.reshape(slots, width), np.tile(shape_low, (slots, 1))], 1)
        high = np.concatenate(
            [table.high.reshape(slots, width), np.tile(shape_high, (slots, 1))], 1
        )
        return spaces.Dict(
            {
                "robot": entity["robot"],
                "landmarks": spaces.Box(low.ravel(), high.ravel(), dtype=np.float32),
            }
        )

    def convert(self, flat: NDArray[np.float32], max_landmarks: int) -> dict[str, Any]:
        """The entity view of the flat vectors' first part, each table row followed by its
        slot's shape block from the end of the vector (zeros for L1 and L2)."""
        flat = np.asarray(flat, dtype=np.float32)
        base = observation_size(max_landmarks)
        entity = super().convert(flat[..., :base], max_landmarks)
        lead = flat.shape[:-1]
        table = entity["landmarks"].reshape(*lead, max_landmarks, len(ENTITY_FEATURES))
        shapes = np.zeros((*lead, max_landmarks, len(SHAPE_FEATURES)), dtype=np.float32)
        shapes[..., 2:, :] = flat[..., base:].reshape(*lead, max_landmarks - 2, -1)
        entity["landmarks"] = np.concatenate([table, shapes], axis=-1).reshape(*lead, -1)
        return entity


FLAT = FlatObservation()
ENTITIES = EntityObservation()
SHAPES = ShapeEntityObservation()
BaseSpec = FlatObservation | EntityObservation
#: The spec of each ``config.observations.observation`` kind.
SPECS: dict[str, BaseSpec] = {spec.kind: spec for spec in (FLAT, ENTITIES, SHAPES)}


class WithCandidates:
    """An observation kind followed by the planner features (``planner_features=True``,
    :mod:`bearing_env.envs.candidates`): the flat vector ends with them, K candidates of
    ``len(CANDIDATE_FEATURES)`` each; a ``Dict`` kind carries them as ``"candidates"``."""

    def __init__(self, base: BaseSpec, size: int, bounds: tuple[Any, Any]) -> None:
        self.base = base
        self.kind = base.kind
        #: The features' length (K * len(CANDIDATE_FEATURES)) and their (low, high).
        self.size = size
        self.bounds = bounds

    def flat_size(self, max_landmarks: int) -> int:
        return self.base.flat_size(max_landmarks) + self.size

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        base = self.base.space(config)
        low, high = (np.asarray(bound, dtype=np.float32) for bound in self.bounds)
        if isinstance(base, spaces.Box):
            low, high = np.concatenate([base.low, low]), np.concatenate([base.high, high])
            return spaces.Box(low, high, dtype=np.float32)
        assert isinstance(base, spaces.Dict)
        return spaces.Dict({**base.spaces, "candidates": spaces.Box(low, high, dtype=np.float32)})

    def convert(self, flat: NDArray[np.float32], max_landmarks: int) -> Any:
        """The base kind's observation of the vector's first part, with the features."""
        if self.base.kind == FLAT.kind:  # (by kind: an unpickled spec is a copy)
            return flat
        observation = self.base.convert(flat[..., : -self.size], max_landmarks)
        return {**observation, "candidates": np.array(flat[..., -self.size :], dtype=np.float32)}


#: An env's observation spec: one kind's, or one with the planner features.
ObservationSpec = BaseSpec | WithCandidates


def spec_for(config: EnvConfig) -> ObservationSpec:
    """The observation spec of envs with ``config``."""
    base = SPECS[config.observations.observation]
    if not config.observations.planner_features:
        return base
    return WithCandidates(base, candidates.features_size(config), candidates.feature_bounds(config))


def entity_observations(flat: NDArray[np.float32], max_landmarks: int) -> dict[str, Any]:
    """:meth:`EntityObservation.convert` (the entity view of flat observations)."""
    return ENTITIES.convert(flat, max_landmarks)
