"""``BearingSLAMDiscrete-v1``: the same task with a discrete set of turns and lengths."""

from __future__ import annotations

from typing import ClassVar

from bearing_env.envs.actions import DISCRETE, ActionSpec
from bearing_env.envs.bearing_slam import BearingSLAMEnv, FloatArray
from bearing_env.envs.config import DEFAULT_N_MOVE_LENGTHS, DEFAULT_N_TURNS

__all__ = ["DEFAULT_N_MOVE_LENGTHS", "DEFAULT_N_TURNS", "BearingSLAMDiscreteEnv"]


class BearingSLAMDiscreteEnv(BearingSLAMEnv):
    """
    ## Description

    `BearingSLAM-v1` (see `BearingSLAMEnv`, which documents the task, observation,
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

    All the arguments of `BearingSLAMEnv` (as keywords, or as `config=EnvConfig(...)`),
    plus:

    - `n_turns`: number of relative headings, 1 to `MAX_ACTION_TABLE` (4096); default 8.
    - `n_move_lengths`: number of move lengths, 1 to 4096; default 3, or 1 when
      `move_length` is a single length.

    Both are fields of `EnvConfig` too (the continuous env ignores them).

    ```python
    import gymnasium as gym
    env = gym.make("bearing_env:BearingSLAMDiscrete-v1", scenario="khepera", n_turns=12)
    ```

    ## Version History

    * v0: Initial version.
    * v1: the conservative transfer grows regions by a local bound instead of one
      global radius per movement (bearing_env 0.2.0); `-v0` keeps the old bound
      (`transfer="conservative_global"`), see `bearing_env.tasks.VERSIONS`.
    """

    # Its setting attributes, the grid's read-only ones (n_turns, n_move_lengths)
    # included, and its signature are installed by BearingSLAMEnv.__init_subclass__.
    action_spec: ClassVar[ActionSpec] = DISCRETE

    @property
    def turn_angles(self) -> FloatArray:
        """The relative turns of the action grid, radians."""
        return DISCRETE.tables(self.config)[0]

    @property
    def move_lengths(self) -> FloatArray:
        """The move lengths of the action grid, metres."""
        return DISCRETE.tables(self.config)[1]
