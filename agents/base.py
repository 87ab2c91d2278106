"""The policy protocol, and the action codec every policy shares.

A policy is built from the env it acts in, ``Policy(env, **options)``, and then driven
with ``reset(seed)`` at the start of every episode and ``act(observation, info)`` at
every step. ``info`` holds the robot's own map (``info["robot_map"]``, what the map-based
policies read: see :mod:`bearing_env.agents.env_access`) and ground truth for evaluation,
which robot policies never read.

Policies choose a *movement* as a turn (radians, counter-clockwise, relative to the
current heading) and a length (metres); :class:`ActionCodec` turns that into the env's
action, continuous (``BearingSLAM-v1``) or discrete (``BearingSLAMDiscrete-v1``, the
nearest entry of the env's turn and length tables).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.actions import DISCRETE, ActionSpec
from bearing_env.numerics import wrap

from .env_access import bearing_env_of

#: Policies draw their own random numbers from ``default_rng([seed, POLICY_STREAM])``,
#: not ``default_rng(seed)``: the env seeds its generator from the same episode seed, and
#: a policy using the identical stream would see its turns correlated with the noise.
POLICY_STREAM = 0x5EED_A6E7

Action = Any


@runtime_checkable
class Policy(Protocol):
    """What the comparison harness needs from a policy."""

    name: str

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode; ``seed`` fixes the policy's own randomness."""

    def act(self, observation: NDArray[np.float32], info: dict[str, Any]) -> Action:
        """The action for ``observation`` (an element of the env's action space)."""


def policy_rng(seed: int | None) -> np.random.Generator:
    """The policy's generator for an episode seed (independent of the env's stream)."""
    if seed is None:
        return np.random.default_rng()
    return np.random.default_rng([int(seed), POLICY_STREAM])


@dataclass(frozen=True)
class Movement:
    """One candidate movement: a turn (radians, CCW, relative to the current heading), a
    length (metres) and the env action that commands it."""

    turn: float
    length: float
    action: Action


class ActionCodec:
    """Maps movements to the actions of one env (continuous or discrete), and back,
    through the env's own action spec (:mod:`bearing_env.envs.actions`: the one home of
    decoding and encoding).

    Continuous: ``a[0] = turn / pi``, ``a[1]`` maps linearly onto the env's
    ``move_length`` range ``(lo, hi)``; lengths outside the range are clipped to it.
    Discrete: the nearest turn of ``env.turn_angles`` (circular distance) and the nearest
    length of ``env.move_lengths``.
    """

    def __init__(self, env: gym.Env) -> None:
        base = bearing_env_of(env)
        self.spec: ActionSpec = base.action_spec
        self.config = base.config
        self.length_range: tuple[float, float] = (
            float(base.config.actions.move_length[0]),
            float(base.config.actions.move_length[1]),
        )
        self.discrete = self.spec.kind == "discrete"
        if self.discrete:
            self.turn_table, self.length_table = DISCRETE.tables(self.config)

    @property
    def max_length(self) -> float:
        return self.length_range[1]

    def encode(self, turn: float, length: float) -> Action:
        """The env action closest to "turn by ``turn`` radians, move ``length`` metres"."""
        return self.spec.encode(self.config, turn, length)

    def decode(self, action: Action) -> tuple[float, float]:
        """(turn in radians, length in metres) that ``action`` commands, as the env reads it."""
        turns, lengths = self.spec.decode(self.config, np.asarray([action]))
        return float(turns[0]), float(lengths[0])

    def movement(self, turn: float, length: float) -> Movement:
        """The movement the env will actually perform for the nearest action."""
        action = self.encode(turn, length)
        actual_turn, actual_length = self.decode(action)
        return Movement(actual_turn, actual_length, action)

    def candidates(self, n_turns: int, lengths: int | tuple[float, ...]) -> list[Movement]:
        """A grid of candidate movements, without duplicates.

        Continuous: ``n_turns`` turns evenly spaced over the circle (starting at 0) times
        ``lengths`` (a count of lengths evenly spaced down from the longest, or explicit
        metres). Discrete: the env's own table (``n_turns`` and ``lengths`` are ignored
        unless ``lengths`` is a count smaller than the table, which keeps the longest).
        """
        if self.discrete:
            table_lengths = self.length_table
            if isinstance(lengths, int) and lengths < table_lengths.size:
                table_lengths = np.sort(table_lengths)[::-1][:lengths]
            chosen = [(float(t), float(ln)) for t in self.turn_table for ln in table_lengths]
        else:
            lo, hi = self.length_range
            if isinstance(lengths, int):
                if lengths < 1:
                    raise ValueError(f"lengths must be >= 1, got {lengths}")
                # Evenly spaced from the longest down to lo (one length: the longest).
                length_values = [hi] if lengths == 1 else list(np.linspace(hi, lo, lengths))
            else:
                length_values = [float(v) for v in lengths]
            turns = [wrap(2.0 * math.pi * k / n_turns) for k in range(n_turns)]
            chosen = [(t, float(ln)) for ln in length_values for t in turns]
        movements: list[Movement] = []
        seen: set[tuple[float, float]] = set()
        for turn, length in chosen:
            movement = self.movement(turn, length)
            key = (round(movement.turn, 9), round(movement.length, 9))
            if key not in seen:
                seen.add(key)
                movements.append(movement)
        return movements
