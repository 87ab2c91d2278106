"""The action specs: one per action kind, the one home of its space, its decoding (what
the envs do with an action) and its encoding (the action nearest a wanted movement,
what the agents send).

An action is one straight-line movement: a turn on the spot (radians, counter-clockwise,
relative to the heading) and a length (metres).

* :data:`CONTINUOUS` (``BearingSLAM-v1``): ``Box(-1, 1, (2,), float32)``; ``a[0]`` turns
  by ``pi * a[0]``, ``a[1]`` maps linearly onto the ``move_length`` range.
* :data:`DISCRETE` (``BearingSLAMDiscrete-v1``): ``Discrete(n_turns * n_move_lengths)``;
  action ``k`` is the ``k // n_move_lengths``-th of ``n_turns`` evenly spaced turns and
  the ``k % n_move_lengths``-th of evenly spaced lengths. Its grid fixes the space, so
  ``n_turns`` and ``n_move_lengths`` cannot change on a live env (:attr:`grid_fixed`).
"""

from __future__ import annotations

import functools
import math
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.envs import kernels
from bearing_env.envs.config import EnvConfig
from bearing_env.numerics import wrap, wrap_angle
from bearing_env.validation import is_real

FloatArray = NDArray[np.float64]
#: The action dtypes the native decoder takes (C-contiguous): others are cast first.
_DECODED_DTYPES = (np.dtype(np.float32), np.dtype(np.float64))


def real_values(actions: Any, what: str) -> NDArray[Any]:
    """``actions`` as a numeric array; strings, bools, complex numbers and other objects
    are refused (numpy would quietly turn ``"0.5"`` or ``True`` into a float)."""
    values = np.asarray(actions)
    if values.dtype == object:
        flat = values.ravel().tolist()
        if not all(is_real(value) for value in flat):
            raise ValueError(f"{what} must be real numbers, got {actions!r}")
        values = np.array(flat, dtype=np.float64).reshape(values.shape)
    elif values.dtype.kind not in "iuf":
        raise ValueError(f"{what} must be real numbers, got {actions!r} (dtype {values.dtype})")
    return values


@functools.lru_cache(maxsize=64)
def grid_tables(
    n_turns: int, n_move_lengths: int, lo: float, hi: float
) -> tuple[FloatArray, FloatArray]:
    """A discrete grid's (turn angles, move lengths), read-only: ``n_turns`` evenly spaced
    turns from 0 (wrapped to [-pi, pi)) and ``n_move_lengths`` lengths from lo to hi."""
    turns = wrap_angle(2.0 * math.pi * np.arange(n_turns) / n_turns)
    lengths = np.linspace(lo, hi, n_move_lengths)
    turns.flags.writeable = lengths.flags.writeable = False
    return turns, lengths


class ContinuousActions:
    """``BearingSLAM-v1``'s actions (see the module doc)."""

    kind: ClassVar[str] = "continuous"
    #: Whether the settings fix the action space (none do here).
    grid_fixed: ClassVar[bool] = False
    #: The shape of one action.
    shape: ClassVar[tuple[int, ...]] = (2,)

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        return spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)

    def check_one(self, config: EnvConfig, action: Any) -> NDArray[Any]:
        """One action as an array of shape (2,) (ValueError otherwise)."""
        try:
            values = np.asarray(action)
        except (TypeError, ValueError) as error:
            raise ValueError(f"action must be 2 numbers in [-1, 1], got {action!r}") from error
        if values.shape != (2,):
            raise ValueError(f"action must have shape (2,), got shape {values.shape}: {action!r}")
        return values

    def decode(self, config: EnvConfig, actions: Any) -> tuple[FloatArray, FloatArray]:
        """(turn angles, move lengths) of actions (N, 2) in [-1, 1]^2."""
        values = actions
        if not (  # the common case, an array the native decoder takes as it is
            type(values) is np.ndarray
            and values.dtype in _DECODED_DTYPES
            and values.flags.c_contiguous
        ):
            values = real_values(actions, "actions")
            if values.dtype not in _DECODED_DTYPES:
                # float16, longdouble and integer actions: the native decoder takes float32
                # or float64 only. Cast; the range check follows.
                values = values.astype(np.float64)
            values = np.ascontiguousarray(values)
        if values.ndim != 2 or values.shape[1] != 2:
            raise ValueError(f"actions must have shape (N, 2), got shape {values.shape}")
        turns, lengths = np.empty(values.shape[0]), np.empty(values.shape[0])
        lo, hi = config.actions.move_length
        outcome = _core.decode_continuous(values, lo, hi, turns, lengths)
        if outcome == kernels.ACTIONS_NOT_FINITE:
            raise ValueError(f"actions must be finite, got {actions!r}")
        if outcome == kernels.ACTIONS_OUTSIDE:
            raise ValueError(f"actions {actions!r} are outside the action space [-1, 1]^2")
        return turns, lengths

    def encode(self, config: EnvConfig, turn: float, length: float) -> NDArray[np.float32]:
        """The action nearest "turn by ``turn``, move ``length``" (lengths clipped to the
        ``move_length`` range)."""
        lo, hi = config.actions.move_length
        turn_unit = wrap(turn) / math.pi
        length_unit = 1.0 if hi <= lo else 2.0 * (length - lo) / (hi - lo) - 1.0
        return np.clip(np.array([turn_unit, length_unit]), -1.0, 1.0).astype(np.float32)


class DiscreteActions:
    """``BearingSLAMDiscrete-v1``'s actions (see the module doc)."""

    kind: ClassVar[str] = "discrete"
    grid_fixed: ClassVar[bool] = True
    shape: ClassVar[tuple[int, ...]] = ()

    def space(self, config: EnvConfig) -> spaces.Space[Any]:
        return spaces.Discrete(config.actions.n_turns * config.actions.n_move_lengths)

    def tables(self, config: EnvConfig) -> tuple[FloatArray, FloatArray]:
        """The grid: (turn angles (n_turns,), move lengths (n_move_lengths,)), read-only
        (made once per grid: every step decodes through them)."""
        grid = config.actions
        lo, hi = grid.move_length
        return grid_tables(grid.n_turns, grid.n_move_lengths, float(lo), float(hi))

    def check_one(self, config: EnvConfig, action: Any) -> NDArray[Any]:
        """One action index as an array of shape () (ValueError otherwise)."""
        values = np.asarray(action)
        if values.shape != ():
            n_actions = config.actions.n_turns * config.actions.n_move_lengths
            raise ValueError(f"action must be an integer in [0, {n_actions}), got {action!r}")
        return values

    def decode(self, config: EnvConfig, actions: Any) -> tuple[FloatArray, FloatArray]:
        """(turn angles, move lengths) of action indices (N,)."""
        n_actions = config.actions.n_turns * config.actions.n_move_lengths
        values = real_values(actions, f"actions (integers in [0, {n_actions}))")
        if values.dtype.kind == "f":
            if not np.all(np.isfinite(values)) or np.any(values != np.round(values)):
                raise ValueError(f"actions must be integers in [0, {n_actions}), got {actions!r}")
        index = values.astype(np.int64)
        if np.any((index < 0) | (index >= n_actions)):
            raise ValueError(
                f"actions {actions!r} are outside the action space Discrete({n_actions})"
            )
        turns, lengths = self.tables(config)
        turn_index, length_index = np.divmod(index, config.actions.n_move_lengths)
        return turns[turn_index], lengths[length_index]

    def encode(self, config: EnvConfig, turn: float, length: float) -> int:
        """The index of the grid's nearest turn (circular distance) and nearest length."""
        turns, lengths = self.tables(config)
        turn_index = int(np.argmin(np.abs(wrap_angle(turns - turn))))
        length_index = int(np.argmin(np.abs(lengths - length)))
        return turn_index * lengths.size + length_index


CONTINUOUS = ContinuousActions()
DISCRETE = DiscreteActions()
ActionSpec = ContinuousActions | DiscreteActions
