"""``BearingSLAM-v0`` as a natively batched vector environment.

``gym.make_vec("BearingSLAM-v0", num_envs=64, vectorization_mode="vector_entry_point")``
returns :class:`BearingSLAMVectorEnv`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from bearing_env.envs.bearing_slam import BearingSLAMEnv, Movement, _row_info
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.slam import PolygonSLAM
from bearing_env.slam.batch import BatchedPolygonSLAM

AUTORESET_MODES = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)

#: Per-landmark info arrays and the value that pads them when landmark counts vary.
LANDMARK_INFO_PADDING: dict[str, Any] = {
    "landmark_area": np.inf,
    "landmark_error": np.inf,
    "landmark_contains_truth": False,
}


class SharedMaps:
    """One :class:`BatchedPolygonSLAM` per landmark count, with a row per sub-env.

    Sub-envs with a range of landmark counts switch batches at reset; the rows of the
    other batches are simply left idle.
    """

    def __init__(self, num_maps: int, epsilon: float, transfer: str) -> None:
        self.num_maps = num_maps
        self.epsilon = epsilon
        self.transfer = transfer
        self.batches: dict[int, BatchedPolygonSLAM] = {}

    def batch_for(self, n_landmarks: int) -> BatchedPolygonSLAM:
        if n_landmarks not in self.batches:
            self.batches[n_landmarks] = BatchedPolygonSLAM(
                self.num_maps, n_landmarks, self.epsilon, transfer=self.transfer
            )
        return self.batches[n_landmarks]


class SharedMapRow:
    """A sub-env's map factory: its own row of the shared batch (picklable)."""

    def __init__(self, maps: SharedMaps, index: int) -> None:
        self.maps = maps
        self.index = index

    def __call__(self, n_landmarks: int) -> PolygonSLAM:
        return PolygonSLAM.view(self.maps.batch_for(n_landmarks), self.index)


class BearingSLAMVectorEnv(VectorEnv[NDArray[np.float32], NDArray[Any], NDArray[Any]]):
    """
    ## Description

    `num_envs` copies of :class:`~bearing_env.envs.bearing_slam.BearingSLAMEnv` stepped
    together, each step in one batched numpy computation per group of sub-envs with the
    same landmark count and settings: all robots move at once (`step_worlds`), all maps
    fuse their movement in one :class:`BatchedPolygonSLAM` update (most of the work), and
    observations, rewards and infos are built as arrays. Only the noise draws loop over
    sub-envs, because each owns its random generator. These are the single env's own
    functions, which it runs with a batch of one, so the two cannot drift apart.

    For the same per-env seeds and actions it reproduces
    `gym.make_vec(id, num_envs, vectorization_mode="sync")` exactly: observations,
    rewards, terminations, truncations and infos are equal bit for bit, step for step.
    Each map's result does not depend on the other maps in its batch (see
    :mod:`bearing_env.slam.batch`).

    ## Spaces

    `single_observation_space` and `single_action_space` are the single environment's;
    `observation_space` and `action_space` batch them along a first axis of `num_envs`.

    ## Autoreset

    Gymnasium 1.x semantics, chosen with `autoreset_mode`:

    - `AutoresetMode.NEXT_STEP` (default): a sub-env that terminated or truncated is
      reset by the next `step()`, which ignores its action and returns its first
      observation with reward 0;
    - `AutoresetMode.SAME_STEP`: it is reset at once; its last observation and info are
      in `infos["final_obs"]` and `infos["final_info"]` (what SB3's adapter needs).

    ## Arguments

    - `num_envs`: number of sub-environments, >= 1.
    - `autoreset_mode`: `"next_step"` (default) or `"same_step"` (or the enum).
    - `max_episode_steps`: truncate after this many steps, like the `TimeLimit` that
      `gym.make` adds (`gym.make_vec` passes the registered 20); None for no limit.
    - `render_mode`: None or `"rgb_array"` (`render()` returns a tuple of frames).
    - `n_landmarks=(lo, hi)` works too. The per-landmark info arrays (`landmark_area`,
      `landmark_error`, `landmark_contains_truth`) are then padded to `max_landmarks - 2`
      entries (with inf, inf and False) so they batch; Gymnasium's own vector envs cannot
      batch them at all.
    - every other keyword: as for the single environment (`scenario`, `n_landmarks`,
      `epsilon_deg`, ...), validated by it.

    ## Version History

    * v0: Initial version.
    """

    metadata: dict[str, Any] = {  # noqa: RUF012
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": ["rgb_array"],
    }
    single_env_class: type[BearingSLAMEnv] = BearingSLAMEnv

    def __init__(
        self,
        num_envs: int = 1,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        **env_kwargs: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)):
            raise TypeError(f"num_envs must be an int, got {num_envs!r}")
        if num_envs < 1:
            raise ValueError(f"num_envs must be >= 1, got {num_envs}")
        self.autoreset_mode = _autoreset_mode(autoreset_mode)
        if max_episode_steps is not None and (
            isinstance(max_episode_steps, bool)
            or not isinstance(max_episode_steps, (int, np.integer))
            or max_episode_steps < 1
        ):
            raise ValueError(
                f"max_episode_steps must be None or an int >= 1, got {max_episode_steps!r}"
            )
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(
                f"unknown render_mode {render_mode!r}; expected None or one of "
                f"{tuple(self.metadata['render_modes'])}"
            )
        self.num_envs = int(num_envs)
        self.max_episode_steps = None if max_episode_steps is None else int(max_episode_steps)
        self.render_mode = render_mode
        # Instance-level metadata: the class's dict is shared and must not be mutated.
        self.metadata = {**type(self).metadata, "autoreset_mode": self.autoreset_mode}

        self.envs = [
            self.single_env_class(render_mode=render_mode, **env_kwargs)
            for _ in range(self.num_envs)
        ]
        first = self.envs[0]
        self._maps = SharedMaps(self.num_envs, first.epsilon, first.transfer)
        for index, env in enumerate(self.envs):
            env._make_slam = SharedMapRow(self._maps, index)  # type: ignore[method-assign]
            env._slam = env._make_slam(env.n_landmarks)

        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

        lo, hi = first.landmark_counts
        #: Landmark slots of the per-landmark info arrays when counts vary per episode.
        self._info_slots = first.max_landmarks - 2 if hi > lo else None
        self._autoreset_envs = np.zeros(self.num_envs, dtype=bool)
        self._elapsed_steps = np.zeros(self.num_envs, dtype=np.int64)
        self._has_reset = False

    # ------------------------------------------------------------------------------------
    # VectorEnv API
    # ------------------------------------------------------------------------------------

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Reset every sub-env; an int seed gives sub-env ``i`` the seed ``seed + i``."""
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)  # type: ignore[arg-type]
            if len(seeds) != self.num_envs:
                raise ValueError(
                    f"seed must be None, an int or {self.num_envs} seeds, got {len(seeds)}"
                )
        observations, infos = [], {}
        for index, (env, env_seed) in enumerate(zip(self.envs, seeds, strict=True)):
            observation, info = env.reset(seed=env_seed, options=options)
            observations.append(observation)
            infos = self._add_info(infos, self._padded(info), index)
        self._autoreset_envs[:] = False
        self._elapsed_steps[:] = 0
        self._has_reset = True
        return np.stack(observations), infos

    def step(
        self, actions: NDArray[Any]
    ) -> tuple[
        NDArray[np.float32],
        NDArray[np.float64],
        NDArray[np.bool_],
        NDArray[np.bool_],
        dict[str, Any],
    ]:
        if not self._has_reset:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.shape != self.action_space.shape:
            raise ValueError(
                f"actions must have shape {self.action_space.shape} (num_envs = "
                f"{self.num_envs}), got {actions.shape}"
            )
        n = self.num_envs
        resetting = self._autoreset_envs & (self.autoreset_mode == AutoresetMode.NEXT_STEP)

        # The world half of every stepping sub-env, then all SLAM updates at once.
        groups = self._groups(np.flatnonzero(~resetting))
        movements: list[Movement | None] = [None] * n
        for group in groups:
            first = self.envs[group[0]]
            turns, lengths = first._decode_actions(actions[group])
            moved = self.single_env_class._move_batch(
                [self.envs[i] for i in group], turns, lengths
            )
            for index, movement in zip(group, moved, strict=True):
                movements[index] = movement
        frame_changed, inconsistent = self._update_maps(movements)

        observations = np.zeros(self.observation_space.shape, dtype=np.float32)
        rewards = np.zeros(n, dtype=np.float64)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        infos: dict[str, Any] = {}
        for group in groups:
            (
                observations[group],
                rewards[group],
                terminations[group],
                truncations[group],
                group_infos,
            ) = self.single_env_class._finish_steps(
                [self.envs[i] for i in group],
                [movements[i] for i in group],  # type: ignore[misc]
                frame_changed[group],
                inconsistent[group],
            )
            self._elapsed_steps[group] += 1
            if self.max_episode_steps is not None:
                truncations[group] |= self._elapsed_steps[group] >= self.max_episode_steps
            infos = self._merge_rows(infos, self._padded(group_infos), group)
            if self.autoreset_mode == AutoresetMode.SAME_STEP:
                for j in np.flatnonzero(terminations[group] | truncations[group]):
                    index = int(group[j])
                    final_info = self._padded(_row_info(group_infos, int(j)))
                    final = {"final_obs": observations[index].copy(), "final_info": final_info}
                    infos = self._add_info(infos, final, index)
                    observations[index], info = self.envs[index].reset()
                    self._elapsed_steps[index] = 0
                    infos = self._add_info(infos, self._padded(info), index)
        for index in np.flatnonzero(resetting):
            observations[index], info = self.envs[index].reset()
            self._elapsed_steps[index] = 0
            infos = self._add_info(infos, self._padded(info), index)
        self._autoreset_envs = terminations | truncations
        return observations, rewards, terminations, truncations, infos

    def render(self) -> tuple[Any, ...] | None:
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Call method ``name`` of every sub-env (or read the attribute if not callable)."""
        results = []
        for env in self.envs:
            attribute = getattr(env, name)
            results.append(attribute(*args, **kwargs) if callable(attribute) else attribute)
        return tuple(results)

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Attribute ``name`` of every sub-env."""
        return tuple(getattr(env, name) for env in self.envs)

    def set_attr(self, name: str, values: Any | Sequence[Any]) -> None:
        """Set attribute ``name`` of every sub-env (one value for all, or one per env)."""
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"expected {self.num_envs} values for {name!r}, got {len(values)}")
        for env, value in zip(self.envs, values, strict=True):
            setattr(env, name, value)

    # ------------------------------------------------------------------------------------
    # Internals
    # ------------------------------------------------------------------------------------

    def _padded(self, info: dict[str, Any]) -> dict[str, Any]:
        """With varying landmark counts, per-landmark arrays padded to a fixed length
        (Gymnasium batches an info key into one array, so every sub-env's must agree).
        Works on one env's info and on batched infos (landmarks on the last axis)."""
        if self._info_slots is None:
            return info
        padded = dict(info)
        for key, fill in LANDMARK_INFO_PADDING.items():
            values = info[key]
            padded[key] = np.full((*values.shape[:-1], self._info_slots), fill, values.dtype)
            padded[key][..., : values.shape[-1]] = values
        return padded

    def _groups(self, indices: NDArray[np.int64]) -> list[NDArray[np.int64]]:
        """Sub-envs that can be stepped as one batch: same landmark count (so one map
        batch) and same settings. Sub-envs share their settings unless ``set_attr``
        changed some; then each distinct setting gets its own batch, computed alike."""
        groups: dict[tuple[Any, ...], list[int]] = {}
        for index in indices.tolist():
            env = self.envs[index]
            groups.setdefault((env.n_landmarks, env._batch_settings()), []).append(index)
        return [np.array(group) for group in groups.values()]

    def _merge_rows(
        self, infos: dict[str, Any], batched: dict[str, Any], rows: NDArray[np.int64]
    ) -> dict[str, Any]:
        """What ``_add_info`` would build from each row's info, for many rows at once."""
        for key, value in batched.items():
            if isinstance(value, dict):
                array = self._merge_rows(infos.get(key, {}), value, rows)
            else:
                array = infos.get(key)
                if array is None:
                    array = np.zeros((self.num_envs, *value.shape[1:]), dtype=value.dtype)
                array[rows] = value
            mask = infos.get(f"_{key}", np.zeros(self.num_envs, dtype=np.bool_))
            mask[rows] = True
            infos[key], infos[f"_{key}"] = array, mask
        return infos

    def _update_maps(
        self, movements: list[Movement | None]
    ) -> tuple[NDArray[np.bool_], NDArray[np.int64]]:
        """One batched SLAM update per landmark count, over the sub-envs that moved."""
        frame_changed = np.zeros(self.num_envs, dtype=bool)
        inconsistent = np.zeros(self.num_envs, dtype=np.int64)
        moved: dict[int, list[int]] = {}
        for index, movement in enumerate(movements):
            if movement is not None and movement.changes_map:
                moved.setdefault(self.envs[index].n_landmarks, []).append(index)
        for n_landmarks, rows in moved.items():
            result = self._maps.batch_for(n_landmarks).update(
                np.stack([movements[i].start_bearings for i in rows]),  # type: ignore[union-attr]
                np.stack([movements[i].end_bearings for i in rows]),  # type: ignore[union-attr]
                maps=np.array(rows),
            )
            frame_changed[rows] = result.frame_changed
            inconsistent[rows] = result.n_inconsistent
        return frame_changed, inconsistent


class BearingSLAMDiscreteVectorEnv(BearingSLAMVectorEnv):
    """``BearingSLAMDiscrete-v0`` batched: :class:`BearingSLAMVectorEnv` over
    :class:`~bearing_env.envs.bearing_slam_discrete.BearingSLAMDiscreteEnv` (actions are
    an array of ``num_envs`` discrete action indices)."""

    single_env_class = BearingSLAMDiscreteEnv


def _autoreset_mode(value: AutoresetMode | str) -> AutoresetMode:
    """The enum from itself, its value (``"SameStep"``) or its name (``"same_step"``)."""
    mode: AutoresetMode | None = None
    if isinstance(value, AutoresetMode):
        mode = value
    elif isinstance(value, str):
        by_name = {m.name.lower(): m for m in AutoresetMode}
        mode = by_name.get(value.lower()) or next(
            (m for m in AutoresetMode if m.value.lower() == value.lower()), None
        )
    if mode not in AUTORESET_MODES:
        raise ValueError(
            "autoreset_mode must be one of "
            f"{[m.name.lower() for m in AUTORESET_MODES]} (or the AutoresetMode enum), "
            f"got {value!r}"
        )
    return mode
