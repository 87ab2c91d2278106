"""``BearingSLAM-v1`` as a natively batched vector environment.

``gym.make_vec("BearingSLAM-v1", num_envs=64, vectorization_mode="vector_entry_point")``
returns :class:`BearingSLAMVectorEnv`. It steps the functional core of
:mod:`bearing_env.envs.core` on all its sub-envs at once; it holds no single-env objects.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any, ClassVar

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from bearing_env.envs import core
from bearing_env.envs.actions import CONTINUOUS, DISCRETE, ActionSpec
from bearing_env.envs.bearing_slam import BearingSLAMEnv, Setting, check_reset_options
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.envs.config import MAX_N_LANDMARKS, EnvConfig
from bearing_env.envs.core import MapBank, WorldView
from bearing_env.envs.state import BatchState
from bearing_env.validation import int_at_least, is_integer

AUTORESET_MODES = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP, AutoresetMode.DISABLED)
#: The keys ``reset(options=...)`` takes (the sub-envs themselves take none).
RESET_OPTIONS = ("reset_mask",)

#: Per-landmark info arrays and the value that pads them when landmark counts vary.
LANDMARK_INFO_PADDING: dict[str, Any] = {
    "landmark_area": np.inf,
    "landmark_error": np.inf,
    "landmark_contains_truth": False,
    "outliers": 0,
}

IntArray = NDArray[np.int64]


class BearingSLAMVectorEnv(VectorEnv[NDArray[np.float32], NDArray[Any], NDArray[Any]]):
    """
    ## Description

    `num_envs` copies of :class:`~bearing_env.envs.bearing_slam.BearingSLAMEnv` stepped
    together. The sub-envs are rows of one structure of arrays
    (:class:`~bearing_env.envs.state.BatchState`), and each step is one compiled call per
    group of rows with the same settings (`EnvConfig`) and landmark count: all robots
    move at once, all maps fuse their movement in one batched update (most of the work),
    and observations, rewards, episode ends and infos are written for the whole group
    (the relaxed fusion's window in the infos takes one more call). The readings' noise
    is drawn ahead, a block of moves at a time, by each sub-env's own generator, so no
    Python runs per sub-env on a step; resets (new layouts) run in Python for the
    sub-envs that ended. The functions are :mod:`bearing_env.envs.core`'s, which the
    single env runs with a batch of one, so the two cannot drift apart.

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
      in `infos["final_obs"]` and `infos["final_info"]` (what SB3's adapter needs);
    - `AutoresetMode.DISABLED`: it is not reset; `step()` raises `RuntimeError` until it
      is, by `reset(options={"reset_mask": terminated | truncated})`.

    `reset(seed=..., options={"reset_mask": mask})` resets only the sub-envs where `mask`
    (a numpy bool array of `num_envs`, at least one True) is True, in any mode: the others
    keep their episodes, pending autoresets and last observations, and the infos hold the
    reset sub-envs only (`_key` masks). The seeds of the others are not used. A mask of
    another type, dtype or shape, or an unknown option, raises `TypeError`/`ValueError`
    naming it; the first reset must reset every sub-env.

    ## Arguments

    - `num_envs`: number of sub-environments, >= 1.
    - `autoreset_mode`: `"next_step"` (default), `"same_step"` or `"disabled"` (or the
      enum).
    - `max_episode_steps`: an extra cap, as the `TimeLimit` that an explicit
      `gym.make(id, max_episode_steps=...)` adds; default None (the ids register none:
      `max_moves` is the episode cap).
    - `render_mode`: None or `"rgb_array"` (`render()` returns a tuple of frames).
    - `n_landmarks=(lo, hi)` works too. The per-landmark info arrays (`landmark_area`,
      `landmark_error`, `landmark_contains_truth`, `outliers`) are then padded to
      `max_landmarks - 2` entries (with inf, inf, False and 0) so they batch; Gymnasium's
      own vector envs cannot batch them at all.
    - `config`: an `EnvConfig`, or every other keyword: as for the single environment
      (`scenario`, `n_landmarks`, `epsilon_deg`, ...), validated by it.

    ## Sub-env attributes

    `get_attr(name)` gives one value per sub-env: any setting (`area_cap`,
    `path_cost`, ...; `config` for the whole `EnvConfig`), `n_landmarks`, `slam` (the
    sub-env's map, a `PolygonSLAM` view of the shared batch), `world` (its ground
    truth, read-only) and `np_random`. `set_attr(name, values)` changes settings per
    sub-env (validated), and `config` and `np_random`; any other name raises
    `AttributeError`. Sub-envs whose settings differ are stepped in separate groups.
    `call(name)` calls what `get_attr(name)` gives when it is callable.

    ## Version History

    * v0: Initial version.
    * v1: the conservative transfer grows regions by a local bound instead of one
      global radius per movement (bearing_env 0.2.0); `-v0` keeps the old bound
      (`transfer="conservative_global"`), see `bearing_env.tasks.VERSIONS`.
    """

    metadata: dict[str, Any] = {  # noqa: RUF012
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": ["rgb_array"],
    }
    #: The single env this batches: it validates the settings and defines the spaces.
    single_env_class: type[BearingSLAMEnv] = BearingSLAMEnv
    #: The action kind (its decoding), as the single env's.
    action_spec: ClassVar[ActionSpec] = CONTINUOUS

    def __init__(
        self,
        num_envs: int = 1,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        config: EnvConfig | None = None,
        **env_kwargs: Any,
    ) -> None:
        num_envs = int_at_least(num_envs, 1, "num_envs")
        self.autoreset_mode = _autoreset_mode(autoreset_mode)
        if max_episode_steps is not None:
            max_episode_steps = int_at_least(max_episode_steps, 1, "max_episode_steps")
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

        # One single env, only to validate the settings exactly as it does and to give
        # the spaces; the sub-envs themselves are rows of the batch state.
        prototype = self.single_env_class(config=config, **env_kwargs)
        first = prototype.config
        self.single_observation_space = prototype.observation_space
        self.single_action_space = prototype.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

        #: The distinct configs of the sub-envs, and which one each sub-env has.
        self._config_table: list[EnvConfig] = [first]
        self._config_index = np.zeros(self.num_envs, dtype=np.int64)
        observations, layout = first.observations, first.layout
        self._state = BatchState.empty(self.num_envs, observations.max_landmarks)
        self._state.n_landmarks[:] = layout.landmark_counts[1]
        self._maps = MapBank(self.num_envs)
        self._rngs: list[np.random.Generator | None] = [None] * self.num_envs
        self._worlds = [WorldView(self._state, row, first) for row in range(self.num_envs)]
        self._renderers: list[Any] = [None] * self.num_envs

        #: Landmark slots of the per-landmark info arrays when counts vary per episode.
        slots = observations.max_landmarks
        self._info_slots = slots - 2 if layout.has_count_range else None
        #: The sub-envs' observations, flat (the observation kind cannot change per env).
        self._flat_shape = (self.num_envs, prototype.observation_spec.flat_size(slots))
        self._observation_spec = prototype.observation_spec
        self._max_landmarks = slots
        self._autoreset_envs = np.zeros(self.num_envs, dtype=bool)
        self._elapsed_steps = np.zeros(self.num_envs, dtype=np.int64)
        self._has_reset = False
        #: The flat observations last returned: a reset with a ``reset_mask`` returns
        #: them again for the sub-envs it leaves alone, as ``SyncVectorEnv`` does.
        self._observations = np.zeros(self._flat_shape, dtype=np.float32)

    # ------------------------------------------------------------------------------------
    # VectorEnv API
    # ------------------------------------------------------------------------------------

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Reset every sub-env, or those of ``options["reset_mask"]`` (a bool array of
        ``num_envs``), as ``SyncVectorEnv`` does: the others keep their episodes and their
        last observations, and the infos hold only the reset sub-envs (``_key`` masks).
        An int seed gives sub-env ``i`` the seed ``seed + i``; a list gives one seed (or
        None) per sub-env; the seeds of sub-envs left alone are not used."""
        mask = self._reset_mask(options)
        seeds = self._seeds(seed)
        if not self._has_reset and not mask.all():
            raise ValueError(
                f"the first reset() must reset every sub-env, got options['reset_mask'] = {mask!r}"
            )
        rows = np.flatnonzero(mask)
        for row in rows.tolist():
            # As gym.Env.reset: a seed makes a new generator; without one, the
            # generator carries on (or is made from fresh entropy the first time).
            if seeds[row] is not None or self._rngs[row] is None:
                self._rngs[row], _ = seeding.np_random(seeds[row])
        observations = self._observations.copy()
        infos = self._reset_rows(rows, observations, {})
        self._autoreset_envs[rows] = False
        self._has_reset = True
        return self._returned(observations), infos

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
        if self.autoreset_mode == AutoresetMode.DISABLED and self._autoreset_envs.any():
            ended = np.flatnonzero(self._autoreset_envs).tolist()
            raise RuntimeError(
                f"sub-envs {ended} have ended (terminated or truncated) and autoreset_mode "
                "is DISABLED: reset them with reset(options={'reset_mask': ...}) before "
                "step() again"
            )
        actions = np.asarray(actions)
        if actions.shape != self.action_space.shape:
            raise ValueError(
                f"actions must have shape {self.action_space.shape} (num_envs = "
                f"{self.num_envs}), got {actions.shape}"
            )
        n = self.num_envs
        resetting = self._autoreset_envs & (self.autoreset_mode == AutoresetMode.NEXT_STEP)
        # Every group's actions are decoded (and checked) before anything moves.
        groups = [
            (config, rows, *self.action_spec.decode(config, actions[rows]))
            for config, rows in self._groups(np.flatnonzero(~resetting))
        ]

        if len(groups) == 1 and groups[0][1].size == n:  # the common case: one group, every row
            config, rows, turns, lengths = groups[0]
            report, group_infos = self._step_group(config, rows, turns, lengths)
            # Copies: the step reuses its report's arrays.
            observations, rewards = report.observations.copy(), report.rewards.copy()
            terminations, truncations = report.terminated.copy(), report.truncated.copy()
            infos = _as_vector_infos(group_infos, n)
        else:
            observations = np.zeros(self._flat_shape, dtype=np.float32)
            rewards = np.zeros(n, dtype=np.float64)
            terminations = np.zeros(n, dtype=bool)
            truncations = np.zeros(n, dtype=bool)
            infos = {}
            for config, rows, turns, lengths in groups:
                report, group_infos = self._step_group(config, rows, turns, lengths)
                observations[rows] = report.observations
                rewards[rows] = report.rewards
                terminations[rows] = report.terminated
                truncations[rows] = report.truncated
                infos = self._merge_rows(infos, group_infos, rows)
        finished: list[IntArray] = []
        if self.autoreset_mode == AutoresetMode.SAME_STEP:
            ended = np.flatnonzero(terminations | truncations)
            if ended.size:
                infos = self._merge_final(infos, ended, observations)
                finished.append(ended)
        if finished:  # SAME_STEP: reset at once, the reset's observation and info returned
            infos = self._reset_rows(np.concatenate(finished), observations, infos)
        infos = self._reset_rows(np.flatnonzero(resetting), observations, infos)
        self._autoreset_envs = terminations | truncations
        return self._returned(observations), rewards, terminations, truncations, infos

    def _step_group(
        self,
        config: EnvConfig,
        rows: IntArray,
        turns: NDArray[np.float64],
        lengths: NDArray[np.float64],
    ) -> tuple[Any, dict[str, Any]]:
        """One step of a group (one config and landmark count): its report, with the
        ``max_episode_steps`` cap applied, and its batched infos (padded)."""
        group = self._maps.group(self._state, rows, config)
        report, robot_map_info = core.step(self._state, group, turns, lengths)
        self._elapsed_steps[rows] += 1
        if self.max_episode_steps is not None:
            report.truncated[:] |= self._elapsed_steps[rows] >= self.max_episode_steps
        infos = core.infos(report, robot_map_info, core.sensor_info(self._state, group))
        return report, self._padded(infos)

    def _returned(self, flat: NDArray[np.float32]) -> Any:
        """The observations ``reset`` or ``step`` returns, kept as the latest ones."""
        self._observations = flat
        return self._observation(flat.copy())

    def _observation(self, flat: NDArray[np.float32]) -> Any:
        """Observations of the sub-envs' kind from flat ones (as the single env's)."""
        return self._observation_spec.convert(flat, self._max_landmarks)

    def render(self) -> tuple[Any, ...] | None:
        if self.render_mode is None:
            return None
        if not self._has_reset:
            raise RuntimeError("call reset() before render()")
        frames = []
        for row in range(self.num_envs):
            from bearing_env.rendering import Renderer, scene

            if self._renderers[row] is None:
                self._renderers[row] = Renderer(
                    self.render_mode,
                    self._row_config(row).layout.arena,
                    fps=BearingSLAMEnv.metadata["render_fps"],
                )
            slam = self._slam(row)
            frame = scene(self._state, row, self._row_config(row), slam)
            frames.append(self._renderers[row].render(frame))
        return tuple(frames)

    def close_extras(self, **kwargs: Any) -> None:
        for renderer in self._renderers:
            if renderer is not None:
                renderer.close()
        self._renderers = [None] * self.num_envs

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Call ``get_attr(name)``'s value of every sub-env (or return it if not callable)."""
        return tuple(
            value(*args, **kwargs) if callable(value) else value for value in self.get_attr(name)
        )

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Attribute ``name`` of every sub-env (see the Sub-env attributes section)."""
        return tuple(self._row_attribute(row, name) for row in range(self.num_envs))

    def set_attr(self, name: str, values: Any | Sequence[Any]) -> None:
        """Set attribute ``name`` of every sub-env (one value for all, or one per env)."""
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"expected {self.num_envs} values for {name!r}, got {len(values)}")
        attribute = getattr(self.single_env_class, name, None)
        if name == "config":
            configs = list(values)
            if not all(isinstance(value, EnvConfig) for value in configs):
                raise TypeError(f"config values must be EnvConfig objects, got {values!r}")
        elif isinstance(attribute, Setting):
            if attribute.read_only is not None:
                raise AttributeError(f"{name} is read-only: {attribute.read_only}")
            # All validated before any is applied, so a bad value changes nothing.
            configs = [
                self._row_config(row).replace(**{attribute.field: value})
                for row, value in enumerate(values)
            ]
        elif name == "np_random":
            self._rngs = list(values)
            for row, rng in enumerate(self._rngs):  # the next moves draw from the new ones
                core.bind_noise(self._state, row, rng)
            return
        elif attribute is not None or name in _ROW_ATTRIBUTES:
            raise AttributeError(f"the sub-envs' {name!r} cannot be set")
        else:
            raise AttributeError(
                f"the sub-envs have no attribute {name!r} to set; set_attr sets 'config', "
                "'np_random' and the settings (see EnvConfig)"
            )
        grid_fixed = self.action_spec.grid_fixed
        for row, config in enumerate(configs):
            core.check_config_switch(self._row_config(row), config, grid_fixed)
        for row, config in enumerate(configs):
            self._set_row_config(row, config)

    # ------------------------------------------------------------------------------------
    # Pickling
    # ------------------------------------------------------------------------------------

    def __getstate__(self) -> dict[str, Any]:
        # A pygame surface cannot be pickled; fresh ones are made on demand.
        state = self.__dict__.copy()
        state["_renderers"] = [None] * self.num_envs
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        # An out-of-band pickle may hand back read-only buffers: copy what is written
        # (the batch state does so itself, keeping its identity for the world views).
        self._config_index = np.require(self._config_index, requirements=["W"])
        self._autoreset_envs = np.require(self._autoreset_envs, requirements=["W"])
        self._elapsed_steps = np.require(self._elapsed_steps, requirements=["W"])

    # ------------------------------------------------------------------------------------
    # Internals
    # ------------------------------------------------------------------------------------

    def _row_config(self, row: int) -> EnvConfig:
        return self._config_table[int(self._config_index[row])]

    def _set_row_config(self, row: int, config: EnvConfig) -> None:
        core.switch_maps(self._state, self._maps, row, self._row_config(row), config)
        self._worlds[row].config = config
        if config not in self._config_table:
            self._config_table.append(config)
        self._config_index[row] = self._config_table.index(config)

    def _rng(self, row: int) -> np.random.Generator:
        rng = self._rngs[row]
        if rng is None:
            rng, _ = seeding.np_random()
            self._rngs[row] = rng
        return rng

    def _slam(self, row: int) -> Any:
        return self._maps.view(int(self._state.n_landmarks[row]), self._row_config(row), row)

    def _row_attribute(self, row: int, name: str) -> Any:
        if name == "config":
            return self._row_config(row)
        if name == "n_landmarks":
            return int(self._state.n_landmarks[row])
        if name == "slam":
            return self._slam(row)
        if name == "world":
            return self._worlds[row] if self._has_reset else None
        if name == "np_random":
            # The unspent noise drawn ahead goes back first (see BearingSLAMEnv.np_random).
            core.release_noise(self._state, row)
            return self._rng(row)
        if name in ("observation_space", "action_space"):
            return getattr(self, f"single_{name}")
        attribute = getattr(self.single_env_class, name, None)
        if isinstance(attribute, (Setting, property)):
            # Settings and the properties derived from the config alone (epsilon,
            # turn_angles, ...), read as the single env reads them.
            return attribute.__get__(SimpleNamespace(config=self._row_config(row)))
        raise AttributeError(f"the sub-envs have no attribute {name!r}")

    def _seeds(self, seed: Any) -> list[int | None]:
        """One seed per sub-env from ``reset``'s ``seed`` (TypeError/ValueError naming it)."""
        if seed is None:
            return [None] * self.num_envs
        if is_integer(seed):
            return [int(seed) + i for i in range(self.num_envs)]
        if isinstance(seed, (str, bytes)) or not isinstance(seed, (Sequence, np.ndarray)):
            raise TypeError(
                f"seed must be None, an int or a sequence of {self.num_envs} ints or None, "
                f"got {seed!r}"
            )
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ValueError(
                f"seed must be None, an int or {self.num_envs} seeds, got {len(seeds)}"
            )
        for value in seeds:
            if value is not None and not is_integer(value):
                raise TypeError(f"each seed must be an int or None, got {value!r} in {seed!r}")
        return [None if value is None else int(value) for value in seeds]

    def _reset_mask(self, options: object) -> NDArray[np.bool_]:
        """Which sub-envs ``reset(options=options)`` resets: ``options["reset_mask"]``,
        checked as ``SyncVectorEnv`` checks it (TypeError/ValueError naming it), else all."""
        checked = check_reset_options(options, RESET_OPTIONS)
        if "reset_mask" not in checked:
            return np.ones(self.num_envs, dtype=np.bool_)
        mask = checked["reset_mask"]
        if not isinstance(mask, np.ndarray) or mask.dtype != np.bool_:
            kind = f"dtype {mask.dtype}" if isinstance(mask, np.ndarray) else type(mask).__name__
            raise TypeError(
                f"options['reset_mask'] must be a numpy array of dtype bool, got {mask!r} ({kind})"
            )
        if mask.shape != (self.num_envs,):
            raise ValueError(
                f"options['reset_mask'] must have shape ({self.num_envs},), one entry per "
                f"sub-env, got shape {mask.shape}: {mask!r}"
            )
        if not mask.any():
            raise ValueError(f"options['reset_mask'] must reset at least one sub-env, got {mask!r}")
        return mask.copy()

    def _reset_rows(
        self, rows: IntArray, observations: NDArray[np.float32], infos: dict[str, Any]
    ) -> dict[str, Any]:
        """Start new episodes in ``rows``: their observations are written into
        ``observations`` and their infos merged into ``infos``."""
        if rows.size == 0:
            return infos
        for config, group in self._groups(rows, by_count=False):
            rngs = [self._rng(row) for row in group.tolist()]
            core.reset_rows(self._state, group, config, rngs, self._maps)
        for config, group in self._groups(rows):
            rows_group = self._maps.group(self._state, group, config)
            report, robot_map_info = core.report(self._state, rows_group)
            observations[group] = report.observations
            group_infos = core.infos(
                report, robot_map_info, core.sensor_info(self._state, rows_group)
            )
            infos = self._merge_rows(infos, self._padded(group_infos), group)
        self._elapsed_steps[rows] = 0
        return infos

    def _groups(self, rows: IntArray, by_count: bool = True) -> list[tuple[EnvConfig, IntArray]]:
        """``rows`` split into groups that step as one batch: same config and (unless
        ``by_count`` is False) same landmark count, so one map batch. Sub-envs share their
        config unless ``set_attr`` changed some; each distinct config gets its own group."""
        if rows.size == 0:
            return []
        keys = self._config_index[rows] * (MAX_N_LANDMARKS + 1)
        if by_count:
            keys = keys + self._state.n_landmarks[rows]
        if np.all(keys == keys[0]):  # the common case: one group
            return [(self._row_config(int(rows[0])), rows)]
        groups = []
        for key in np.unique(keys):
            group = rows[keys == key]
            groups.append((self._row_config(int(group[0])), group))
        return groups

    def _padded(self, info: dict[str, Any]) -> dict[str, Any]:
        """With varying landmark counts, per-landmark arrays padded to a fixed length
        (Gymnasium batches an info key into one array, so every sub-env's must agree).
        Works on batched infos (landmarks on the last axis)."""
        if self._info_slots is None:
            return info
        padded = dict(info)
        for key, fill in LANDMARK_INFO_PADDING.items():
            values = info[key]
            padded[key] = np.full((*values.shape[:-1], self._info_slots), fill, values.dtype)
            padded[key][..., : values.shape[-1]] = values
        if "seen" in info:  # every landmark, L1 and L2 included: two more slots
            seen = info["seen"]
            padded["seen"] = np.zeros((seen.shape[0], self._info_slots + 2), dtype=bool)
            padded["seen"][:, : seen.shape[1]] = seen
        return padded

    def _merge_final(
        self, infos: dict[str, Any], rows: IntArray, observations: NDArray[np.float32]
    ) -> dict[str, Any]:
        """What ``_add_info`` builds from ``{"final_obs": ..., "final_info": ...}`` of each
        finished sub-env (``rows``), from the step's vector ``infos``."""
        # Gymnasium keeps final observations in an object array, one array per sub-env.
        final_obs = np.full(self.num_envs, None, dtype=object)
        for row in rows.tolist():
            final_obs[row] = self._observation(observations[row].copy())
        mask = np.zeros(self.num_envs, dtype=np.bool_)
        mask[rows] = True
        finals = _select_rows(_without_masks(infos), rows)
        infos = {**infos, "final_obs": final_obs, "_final_obs": mask}
        return self._merge_rows(infos, {"final_info": finals}, rows)

    def _merge_rows(
        self, infos: dict[str, Any], batched: dict[str, Any], rows: IntArray
    ) -> dict[str, Any]:
        """What ``_add_info`` would build from each row's info, for many rows at once.
        Rows that are every sub-env, in order, into empty infos (one group stepped them
        all: the common case) take the batched arrays themselves, with no copy."""
        if not infos and rows.size == self.num_envs:  # rows are distinct and sorted
            return _as_vector_infos(batched, self.num_envs)
        for key, value in batched.items():
            array: Any
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


class BearingSLAMDiscreteVectorEnv(BearingSLAMVectorEnv):
    """``BearingSLAMDiscrete-v1`` batched: :class:`BearingSLAMVectorEnv` with the
    :class:`~bearing_env.envs.bearing_slam_discrete.BearingSLAMDiscreteEnv` action space
    (actions are an array of ``num_envs`` discrete action indices)."""

    single_env_class = BearingSLAMDiscreteEnv
    action_spec: ClassVar[ActionSpec] = DISCRETE


#: Sub-env attributes the vector env serves itself (see ``_row_attribute``).
_ROW_ATTRIBUTES = frozenset({"n_landmarks", "slam", "world", "observation_space", "action_space"})


def _as_vector_infos(batched: dict[str, Any], num_envs: int) -> dict[str, Any]:
    """Batched infos of every sub-env as vector infos: the arrays themselves, each key
    with an all-True ``_key`` mask (nested dicts included)."""
    infos: dict[str, Any] = {}
    for key, value in batched.items():
        infos[key] = _as_vector_infos(value, num_envs) if isinstance(value, dict) else value
        infos[f"_{key}"] = np.ones(num_envs, dtype=np.bool_)
    return infos


def _without_masks(infos: dict[str, Any]) -> dict[str, Any]:
    """Vector infos without their ``_key`` masks (nested dicts included)."""
    return {
        key: _without_masks(value) if isinstance(value, dict) else value
        for key, value in infos.items()
        if not key.startswith("_")
    }


def _select_rows(batched: dict[str, Any], rows: IntArray) -> dict[str, Any]:
    """Batched infos restricted to some of their rows (nested dicts included)."""
    return {
        key: _select_rows(value, rows) if isinstance(value, dict) else value[rows]
        for key, value in batched.items()
    }


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
