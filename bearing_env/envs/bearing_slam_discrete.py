"""``BearingSLAMDiscrete-v0``: the same task with a discrete set of turns and lengths."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces
from numpy.typing import ArrayLike, NDArray

from bearing_env.envs.bearing_slam import (
    DEFAULT_AREA_CAP,
    DEFAULT_MAX_MOVES,
    DEFAULT_TARGET_AREA,
    BearingSLAMEnv,
    FloatArray,
    _int_at_least,
)
from bearing_env.world import Arena, NoiseModel, wrap_angle

#: Default number of relative headings: every 45 degrees.
DEFAULT_N_TURNS = 8
#: Default number of move lengths when ``move_length`` is a range.
DEFAULT_N_MOVE_LENGTHS = 3


class BearingSLAMDiscreteEnv(BearingSLAMEnv):
    """
    ## Description

    `BearingSLAM-v0` (see `BearingSLAMEnv`, which documents the task, observation,
    rewards, episode end and info) with a discrete action space, for value-based agents
    such as DQN.

    ## Action Space

    `Discrete(n_turns * n_move_lengths)` (default `8 * 3 = 24`). Action `a` means:

    - turn on the spot by `turns[a // n_move_lengths]`, where `turns[t] = 2 * pi * t /
      n_turns` wrapped to `[-pi, pi)`: with the default 8, the turns are 0, 45, 90, 135,
      -180, -135, -90 and -45 degrees (counter-clockwise positive). Turns are relative to
      the current heading: the robot has no compass.
    - then move straight by `lengths[a % n_move_lengths]`, the `n_move_lengths` lengths
      evenly spaced over `move_length = (lo, hi)` (both ends included).

    If `move_length` is a single length, `n_move_lengths` defaults to 1. The tables are
    available as the attributes `turn_angles` (radians) and `move_lengths` (metres).
    An action outside the space raises `ValueError`.

    ## Observation Space

    As `BearingSLAMEnv`.

    ## Rewards

    As `BearingSLAMEnv`.

    ## Episode End

    As `BearingSLAMEnv`.

    ## Arguments

    All the arguments of `BearingSLAMEnv`, plus:

    - `n_turns`: number of relative headings (>= 1); default 8.
    - `n_move_lengths`: number of move lengths (>= 1); default 3, or 1 when
      `move_length` is a single length.

    ```python
    import gymnasium as gym
    env = gym.make("bearing_env:BearingSLAMDiscrete-v0", scenario="khepera", n_turns=12)
    ```

    ## Version History

    * v0: Initial version.
    """

    def __init__(
        self,
        scenario: str | None = None,
        n_landmarks: int | tuple[int, int] | None = None,
        landmarks: ArrayLike | None = None,
        arena: tuple[float, float] | Arena | None = None,
        epsilon_deg: float = 2.0,
        noise: NoiseModel | Mapping[str, Any] | str | None = None,
        transfer: str = "conservative",
        reward: str = "log_area",
        target_area: float = DEFAULT_TARGET_AREA,
        max_moves: int = DEFAULT_MAX_MOVES,
        move_length: float | tuple[float, float] | None = None,
        path_cost: float = 0.0,
        move_cost: float = 0.0,
        area_cap: float = DEFAULT_AREA_CAP,
        max_landmarks: int | None = None,
        render_mode: str | None = None,
        n_turns: int = DEFAULT_N_TURNS,
        n_move_lengths: int | None = None,
    ) -> None:
        # The action tables must exist before the base class builds the action space.
        self.n_turns = _int_at_least(n_turns, 1, "n_turns")
        self._requested_n_move_lengths = (
            None if n_move_lengths is None else _int_at_least(n_move_lengths, 1, "n_move_lengths")
        )
        super().__init__(
            scenario=scenario,
            n_landmarks=n_landmarks,
            landmarks=landmarks,
            arena=arena,
            epsilon_deg=epsilon_deg,
            noise=noise,
            transfer=transfer,
            reward=reward,
            target_area=target_area,
            max_moves=max_moves,
            move_length=move_length,
            path_cost=path_cost,
            move_cost=move_cost,
            area_cap=area_cap,
            max_landmarks=max_landmarks,
            render_mode=render_mode,
        )

    def _make_action_space(self) -> spaces.Space[Any]:
        lo, hi = self.move_length
        if self._requested_n_move_lengths is not None:
            self.n_move_lengths = self._requested_n_move_lengths
        else:
            self.n_move_lengths = 1 if lo == hi else DEFAULT_N_MOVE_LENGTHS
        self.turn_angles = wrap_angle(2.0 * math.pi * np.arange(self.n_turns) / self.n_turns)
        self.move_lengths = np.linspace(lo, hi, self.n_move_lengths)
        return spaces.Discrete(self.n_turns * self.n_move_lengths)

    def _batch_settings(self) -> tuple[Any, ...]:
        return (*super()._batch_settings(), self.n_turns, self.n_move_lengths)

    def _decode_actions(self, actions: NDArray[Any]) -> tuple[FloatArray, FloatArray]:
        """(turn angles, move lengths) from a batch of action indices (N,)."""
        values = np.asarray(actions)
        if not np.issubdtype(values.dtype, np.integer):
            as_float = values.astype(np.float64)
            if not np.all(np.isfinite(as_float)) or np.any(as_float != np.round(as_float)):
                raise ValueError(
                    f"actions must be integers in [0, {self.action_space.n}), got {actions!r}"
                )
        index = values.astype(np.int64)
        if np.any((index < 0) | (index >= self.action_space.n)):
            raise ValueError(
                f"actions {actions!r} are outside the action space Discrete({self.action_space.n})"
            )
        turn_index, length_index = np.divmod(index, self.n_move_lengths)
        return self.turn_angles[turn_index], self.move_lengths[length_index]

    def _decode_action(self, action: Any) -> tuple[float, float]:
        values = np.asarray(action)
        if values.shape != () or not np.issubdtype(values.dtype, np.integer):
            if values.shape == () and np.issubdtype(values.dtype, np.floating):
                # A float that is exactly an integer (e.g. from a generic tensor) is fine.
                if not math.isfinite(float(values)) or float(values) != int(values):
                    raise ValueError(
                        f"action must be an integer in [0, {self.action_space.n}), "
                        f"got {action!r}"
                    )
            else:
                raise ValueError(
                    f"action must be an integer in [0, {self.action_space.n}), got {action!r}"
                )
        index = int(values)
        if not 0 <= index < self.action_space.n:
            raise ValueError(
                f"action {action!r} is outside the action space Discrete({self.action_space.n})"
            )
        turn_index, length_index = divmod(index, self.n_move_lengths)
        return float(self.turn_angles[turn_index]), float(self.move_lengths[length_index])
