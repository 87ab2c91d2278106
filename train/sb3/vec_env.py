"""Stable-Baselines3 on top of a Gymnasium vector env (``bearing-env train --vec-env batched``).

SB3 and Gymnasium 1.x disagree on what a vectorised env is. SB3's ``VecEnv`` resets a
finished sub-env inside ``step`` and puts its last observation in
``infos[i]["terminal_observation"]``; infos are one dict per sub-env. A Gymnasium
``VectorEnv`` returns ``terminated`` and ``truncated`` separately, and one dict of arrays
whose ``_key`` entries are masks saying which sub-envs reported ``key``. What it does
when a sub-env finishes depends on its autoreset mode. Only ``SAME_STEP`` matches SB3:
the sub-env is reset in the same ``step``, the returned observation is the reset one,
and the last observation and info of the finished episode travel in
``infos["final_obs"]`` and ``infos["final_info"]``. :class:`GymnasiumVecEnv` therefore
accepts only that mode and translates the rest, so any SAME_STEP vector env can train
with SB3: a natively batched one (the point of this module: one batched computation
steps every sub-env, instead of one Python call per sub-env), or Gymnasium's
``SyncVectorEnv``.

:func:`make_batched_vec_env` builds the training env that ``bearing-env train`` uses:
the id's registered ``vector_entry_point`` when it has one, else a ``SyncVectorEnv`` of
the single env, either way behind the adapter and SB3's ``VecMonitor``.
"""

from __future__ import annotations

import copy
import importlib
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import EnvSpec
from gymnasium.vector import AutoresetMode, VectorEnv
from stable_baselines3.common.monitor import Monitor, ResultsWriter
from stable_baselines3.common.vec_env import VecEnv, VecMonitor
from stable_baselines3.common.vec_env.base_vec_env import (
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
)

import bearing_env.registration

#: Keys a SAME_STEP vector env adds to the step infos of the sub-envs that finished.
FINAL_OBS_KEY = "final_obs"
FINAL_INFO_KEY = "final_info"
#: The per-episode info keys SB3's monitors log (``rollout/success_rate``).
MONITOR_INFO_KEYWORDS: tuple[str, ...] = ("is_success",)


def env_spec(env_id: str) -> EnvSpec:
    """The registered spec of ``env_id``, importing ``module`` first for ``module:Id``.

    ``gym.spec`` alone does not understand the ``bearing_env:BearingSLAM-v1`` form that
    ``gym.make`` and ``gym.make_vec`` accept.
    """
    module, _, name = env_id.rpartition(":")
    if module:
        importlib.import_module(module)
    return gym.spec(name)


def has_vector_entry_point(env_id: str) -> bool:
    """Whether ``env_id`` has a natively batched vector env registered (its spec's
    ``vector_entry_point``), i.e. whether ``gym.make_vec`` can build it without
    stepping single envs one by one."""
    bearing_env.registration.register_envs()
    return env_spec(env_id).vector_entry_point is not None


# --------------------------------------------------------------------------------------
# Unbatching Gymnasium's infos
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class _OpaqueInfo:
    """An info value that Gymnasium's ``_add_info`` must store as an opaque object.

    ``SyncVectorEnv`` stacks an array-valued info into one ``(n_envs, *shape)`` array,
    shaped after the first sub-env that reports it. Random layouts with a range of
    landmark counts report arrays of different lengths (``landmark_area`` ...), which
    cannot be stacked. Boxed in this class, each goes into an object array instead, and
    :func:`unbatch_infos` takes it out again unchanged.
    """

    value: Any


def _box_arrays(info: dict[str, Any]) -> dict[str, Any]:
    return {
        key: (
            _box_arrays(value)
            if isinstance(value, dict)
            else _OpaqueInfo(value)
            if isinstance(value, np.ndarray)
            else value
        )
        for key, value in info.items()
    }


class OpaqueArrayInfo(gym.Wrapper[Any, Any, Any, Any]):
    """Boxes the array values of a single env's infos (see :class:`_OpaqueInfo`), so that a
    ``SyncVectorEnv`` of envs with different info array lengths does not fail. Only
    :class:`GymnasiumVecEnv` unboxes them: use it for vector envs fed to the adapter."""

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        observation, info = self.env.reset(seed=seed, options=options)
        return observation, _box_arrays(info)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        observation, reward, terminated, truncated, info = self.env.step(action)
        return observation, reward, terminated, truncated, _box_arrays(info)


def _info_element(value: Any, index: int, num_envs: int) -> Any:
    """Sub-env ``index``'s entry of one batched info value.

    Numpy scalars become Python scalars: Gymnasium stacked the sub-envs' Python ``float``,
    ``int`` and ``bool`` values into numpy arrays, and this gives back what the single env
    returned (and what ``DummyVecEnv`` passes on). Array rows are copied, so that a
    per-env info does not alias the vector env's buffers.
    """
    if not isinstance(value, np.ndarray) or value.ndim == 0 or len(value) != num_envs:
        return value  # not batched: one value shared by every sub-env
    element = value[index]
    if isinstance(element, _OpaqueInfo):
        return element.value
    if isinstance(element, np.ndarray):
        return element.copy()
    if isinstance(element, np.generic):
        return element.item()
    return element


def unbatch_infos(
    infos: Mapping[str, Any], num_envs: int, exclude: Iterable[str] = ()
) -> list[dict[str, Any]]:
    """Gymnasium's batched infos as one dict per sub-env, SB3's convention.

    ``infos[key]`` holds every sub-env's value and ``infos["_" + key]`` says which sub-envs
    actually reported it; nested dicts are batched the same way, recursively. Sub-env
    ``i`` gets ``key`` only where the mask is true. A value without a mask is taken as
    reported by every sub-env. Keys in ``exclude`` (and their masks) are left out.
    """
    excluded = set(exclude)
    per_env: list[dict[str, Any]] = [{} for _ in range(num_envs)]
    for key, value in infos.items():
        if key in excluded:
            continue
        if key.startswith("_") and key[1:] in infos:
            continue  # the mask of infos[key[1:]]
        mask = infos.get(f"_{key}")
        indices = range(num_envs) if mask is None else np.flatnonzero(mask).tolist()
        if isinstance(value, Mapping):
            nested = unbatch_infos(value, num_envs)
            for index in indices:
                per_env[index][key] = nested[index]
        elif (
            isinstance(value, np.ndarray)
            and value.ndim >= 1
            and len(value) == num_envs
            and value.dtype != object
        ):
            # One conversion for all sub-envs (the per-element path costs a millisecond
            # a step with 16 envs): Python scalars from 1-D arrays, rows of one copy else.
            elements = value.tolist() if value.ndim == 1 else list(value.copy())
            for index in indices:
                per_env[index][key] = elements[index]
        else:
            for index in indices:
                per_env[index][key] = _info_element(value, index, num_envs)
    return per_env


# --------------------------------------------------------------------------------------
# The adapter
# --------------------------------------------------------------------------------------


class GymnasiumVecEnv(VecEnv):
    """An SB3 ``VecEnv`` running a Gymnasium ``VectorEnv`` in ``SAME_STEP`` autoreset mode.

    It behaves like a ``DummyVecEnv`` of the vector env's sub-envs:

    - ``reset()`` passes the seeds set by :meth:`seed` (env ``i`` gets ``seed + i``, as in
      every SB3 vec env) and the options set by ``set_options`` to the vector env's
      ``reset``, then forgets them, so later episodes continue each sub-env's own
      random stream. Per-env reset infos go to ``reset_infos``.
    - ``step`` returns float32 rewards and ``dones = terminated | truncated``. A finished
      sub-env's info is its *final* step info (``infos["final_info"]``), with
      ``terminal_observation`` (from ``infos["final_obs"]``) and ``is_success``; its
      returned observation is the first of the next episode, and the reset info goes to
      ``reset_infos``. Every info carries ``TimeLimit.truncated = truncated and not
      terminated``, which SB3 uses to bootstrap the value of time-limited episodes.
    - ``get_attr``, ``set_attr`` and ``env_method`` reach the sub-envs through the vector
      env's own ``get_attr``/``set_attr``/``call`` (Gymnasium's ``SyncVectorEnv`` and
      ``AsyncVectorEnv`` have them), else the vector env's attribute or method itself,
      which then stands for every sub-env. Requests that would touch sub-envs outside
      ``indices`` raise ``ValueError`` instead of silently touching them.

    Args:
        vector_env: A Gymnasium vector env with ``metadata["autoreset_mode"] ==
            AutoresetMode.SAME_STEP``; the adapter closes it on :meth:`close`.
        success_on_termination: Report ``info["is_success"] = terminated`` at the end of
            every episode, as ``bearing_env.train.sb3.training_envs.SuccessInfo`` does for single
            envs (here termination is success), unless the final info already has
            ``is_success``.

    Raises:
        TypeError: ``vector_env`` is not a Gymnasium ``VectorEnv``.
        ValueError: its autoreset mode is not ``SAME_STEP`` (or is not declared).
    """

    def __init__(
        self, vector_env: VectorEnv[Any, Any, Any], success_on_termination: bool = True
    ) -> None:
        if not isinstance(vector_env, VectorEnv):
            raise TypeError(
                f"GymnasiumVecEnv wraps a gymnasium.vector.VectorEnv, got {type(vector_env)!r}"
            )
        mode = vector_env.metadata.get("autoreset_mode")
        try:
            mode = AutoresetMode(mode)
        except (ValueError, TypeError):
            pass  # reported below with the value as given
        if mode is not AutoresetMode.SAME_STEP:
            raise ValueError(
                f"GymnasiumVecEnv needs a vector env in AutoresetMode.SAME_STEP, got "
                f"metadata['autoreset_mode']={mode!r}: SB3 expects a finished sub-env to be "
                "reset within the same step. Build it with gym.make_vec(..., "
                "vectorization_mode='sync', vector_kwargs={'autoreset_mode': "
                "AutoresetMode.SAME_STEP}), or autoreset_mode=AutoresetMode.SAME_STEP for "
                "a vector_entry_point env"
            )
        self.vector_env = vector_env
        self.success_on_termination = success_on_termination
        self._actions: np.ndarray | None = None
        super().__init__(
            vector_env.num_envs,
            vector_env.single_observation_space,
            vector_env.single_action_space,
        )
        # As DummyVecEnv, which exposes its first env's metadata (render_fps, ...).
        self.metadata = dict(vector_env.metadata)

    @property
    def spec(self) -> EnvSpec | None:
        """The vector env's spec; SB3's ``VecMonitor`` writes its id into the CSV header."""
        return self.vector_env.spec

    # ---- reset and step ---------------------------------------------------------------

    def _shared_options(self) -> dict[str, Any] | None:
        """``set_options``'s per-env options as the one dict a Gymnasium vector reset takes."""
        first = self._options[0]
        for options in self._options[1:]:
            try:
                same = options is first or bool(options == first)
            except Exception:  # e.g. arrays whose comparison has no single truth value
                same = False
            if not same:
                raise ValueError(
                    "GymnasiumVecEnv cannot reset sub-envs with different options: a "
                    "Gymnasium vector env's reset takes one options dict for all of them "
                    f"(got {self._options!r})"
                )
        return dict(first) if first else None

    def reset(self) -> VecEnvObs:
        seeds = list(self._seeds)
        seed: list[int | None] | None = None if all(s is None for s in seeds) else seeds
        # Vector envs take one seed per sub-env; gymnasium types the argument as one int.
        observations, infos = self.vector_env.reset(
            seed=seed,  # type: ignore[arg-type]
            options=self._shared_options(),
        )
        self.reset_infos = unbatch_infos(infos, self.num_envs)
        # Seeds and options are used once, as in DummyVecEnv: later episodes run on.
        self._reset_seeds()
        self._reset_options()
        return self._observations(observations)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self) -> VecEnvStepReturn:
        if self._actions is None:
            raise RuntimeError("step_wait() without a step_async() before it")
        actions, self._actions = self._actions, None
        observations, rewards, terminated, truncated, infos = self.vector_env.step(actions)
        terminated = np.asarray(terminated, dtype=bool)
        truncated = np.asarray(truncated, dtype=bool)
        dones = terminated | truncated
        step_infos = unbatch_infos(infos, self.num_envs, exclude=(FINAL_OBS_KEY, FINAL_INFO_KEY))
        finished = np.flatnonzero(dones).tolist()
        if finished:
            final_observations = infos.get(FINAL_OBS_KEY)
            reported = self._reported(infos, FINAL_OBS_KEY) & self._reported(infos, FINAL_INFO_KEY)
            final_infos = unbatch_infos(infos.get(FINAL_INFO_KEY, {}), self.num_envs)
            for index in finished:
                if final_observations is None or not reported[index]:
                    raise RuntimeError(
                        f"sub-env {index} finished but the vector env did not report its "
                        f"infos['{FINAL_OBS_KEY}'] and infos['{FINAL_INFO_KEY}'], as SAME_STEP "
                        "autoreset requires"
                    )
                # Gymnasium's step info of a reset sub-env is its reset info; SB3 wants the
                # finished episode's last step info, and keeps the reset info apart.
                self.reset_infos[index] = step_infos[index]
                info = final_infos[index]
                info["terminal_observation"] = copy.deepcopy(final_observations[index])
                if self.success_on_termination:
                    info.setdefault("is_success", bool(terminated[index]))
                step_infos[index] = info
        for index, info in enumerate(step_infos):
            info["TimeLimit.truncated"] = bool(truncated[index] and not terminated[index])
        return (
            self._observations(observations),
            np.asarray(rewards, dtype=np.float32),
            dones,
            step_infos,
        )

    def _reported(self, infos: Mapping[str, Any], key: str) -> np.ndarray:
        """Which sub-envs reported ``infos[key]`` (its mask; all of them without a mask)."""
        if key not in infos:
            return np.zeros(self.num_envs, dtype=bool)
        mask = infos.get(f"_{key}")
        return np.ones(self.num_envs, dtype=bool) if mask is None else np.asarray(mask, bool)

    def _observations(self, observations: Any) -> VecEnvObs:
        """A copy in the observation space's dtype, as DummyVecEnv's buffers give: the vector
        env may reuse its observation buffer at the next step."""
        if isinstance(observations, np.ndarray):
            return np.array(observations, dtype=self.observation_space.dtype)
        return copy.deepcopy(observations)  # Dict and Tuple spaces: dicts/tuples of arrays

    def close(self) -> None:
        self.vector_env.close()

    # ---- attributes and methods -------------------------------------------------------

    def _index_list(self, indices: VecEnvIndices) -> list[int]:
        return [int(index) for index in self._get_indices(indices)]

    def _require_all(self, indices: list[int], what: str) -> None:
        if sorted(indices) != list(range(self.num_envs)):
            raise ValueError(
                f"GymnasiumVecEnv cannot {what} for sub-envs {indices} only: the wrapped "
                f"{type(self.vector_env).__name__} can only do it for all {self.num_envs} "
                "sub-envs at once"
            )

    def _sub_env_accessor(self, name: str) -> Any:
        accessor = getattr(self.vector_env, name, None)
        return accessor if callable(accessor) else None

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """Per sub-env through the vector env's ``get_attr`` when it has one and the
        sub-envs have the attribute; else the vector env's own attribute, for each index."""
        targets = self._index_list(indices)
        per_env_getter = self._sub_env_accessor("get_attr")
        if per_env_getter is not None:
            try:
                values = list(per_env_getter(attr_name))
            except AttributeError:
                pass
            else:
                return [values[index] for index in targets]
        if not hasattr(self.vector_env, attr_name):
            raise AttributeError(
                f"neither {type(self.vector_env).__name__} nor its sub-envs have an attribute "
                f"{attr_name!r}"
            )
        value = getattr(self.vector_env, attr_name)
        return [value for _ in targets]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Through the vector env's ``set_attr`` (per sub-env; a subset keeps the others'
        current values), else on the vector env itself, which must then mean all sub-envs."""
        targets = self._index_list(indices)
        everyone = sorted(targets) == list(range(self.num_envs))
        per_env_getter = self._sub_env_accessor("get_attr")
        per_env_setter = self._sub_env_accessor("set_attr")
        if per_env_setter is None or (not everyone and per_env_getter is None):
            self._require_all(targets, f"set {attr_name!r}")
        if per_env_setter is None:
            setattr(self.vector_env, attr_name, value)
            return
        if everyone:
            values = [value for _ in range(self.num_envs)]
        else:
            values = list(per_env_getter(attr_name))
            for index in targets:
                values[index] = value
        per_env_setter(attr_name, values)  # a list: one value per sub-env

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        """Calls the method on every sub-env through the vector env's ``call`` (when the
        sub-envs have it), else the vector env's own method once, its result standing for
        every sub-env. Either way all sub-envs are affected, so ``indices`` must be all."""
        targets = self._index_list(indices)
        self._require_all(targets, f"call {method_name!r}")
        caller = self._sub_env_accessor("call")
        if caller is not None:
            try:
                results = list(caller(method_name, *method_args, **method_kwargs))
            except AttributeError:
                pass  # the sub-envs lack it; the vector env itself may have it
            else:
                return [results[index] for index in targets]
        method = getattr(self.vector_env, method_name, None)
        if not callable(method):
            raise AttributeError(
                f"neither {type(self.vector_env).__name__} nor its sub-envs have a method "
                f"{method_name!r}"
            )
        result = method(*method_args, **method_kwargs)
        return [result for _ in targets]

    def env_is_wrapped(
        self, wrapper_class: type[gym.Wrapper[Any, Any, Any, Any]], indices: VecEnvIndices = None
    ) -> list[bool]:
        """Always False: the sub-envs of a batched vector env are not Gymnasium envs that
        could be wrapped (SB3 asks to know whether a ``Monitor`` is present; it is not,
        ``VecMonitor`` does that job)."""
        return [False for _ in self._index_list(indices)]

    # ---- rendering ----------------------------------------------------------------------

    def get_images(self) -> Sequence[np.ndarray | None]:
        """The vector env's frames, one per sub-env (``rgb_array`` render mode only)."""
        if self.render_mode != "rgb_array":
            return [None for _ in range(self.num_envs)]
        frames = self.vector_env.render()
        if frames is None:
            return [None for _ in range(self.num_envs)]
        return [np.asarray(frame) for frame in frames]

    def render(self, mode: str | None = None) -> np.ndarray | None:
        """SB3's rendering: the frames of :meth:`get_images` tiled into one image for
        ``rgb_array``; the vector env's own ``render()`` for ``human``; else None."""
        return super().render(mode=mode)


# --------------------------------------------------------------------------------------
# The training env
# --------------------------------------------------------------------------------------


def monitor_csv_path(path: str) -> str:
    """The file SB3's ``ResultsWriter`` writes for ``path`` (it appends ``.monitor.csv``)."""
    if path.endswith(Monitor.EXT):
        return path
    if os.path.isdir(path):
        return os.path.join(path, Monitor.EXT)
    return f"{path}.{Monitor.EXT}"


def make_batched_vec_env(
    env_id: str,
    env_kwargs: Mapping[str, Any],
    n_envs: int,
    monitor_path: str | None,
) -> VecEnv:
    """``n_envs`` training envs in one Gymnasium vector env, for SB3.

    The vector env is the id's registered ``vector_entry_point`` (a natively batched
    env), made with ``autoreset_mode=SAME_STEP``. An id without one falls back to a
    ``SyncVectorEnv`` of single envs, so this works for any id, and switches to the
    batched env by itself once it is registered. The envs' ``max_moves`` is their one
    episode cap.

    Episodes are logged by SB3's ``VecMonitor`` (return, length, ``is_success``) to
    ``<monitor_path>.monitor.csv``, which a resumed run extends instead of overwriting.
    """
    if n_envs < 1:
        raise ValueError(f"n_envs must be >= 1, got {n_envs}")
    bearing_env.registration.register_envs()
    kwargs = dict(env_kwargs)
    if env_spec(env_id).vector_entry_point is not None:
        vector_env = gym.make_vec(
            env_id,
            num_envs=n_envs,
            vectorization_mode="vector_entry_point",
            autoreset_mode=AutoresetMode.SAME_STEP,
            **kwargs,
        )
    else:
        vector_env = gym.make_vec(
            env_id,
            num_envs=n_envs,
            vectorization_mode="sync",
            vector_kwargs={"autoreset_mode": AutoresetMode.SAME_STEP},
            wrappers=[OpaqueArrayInfo],
            **kwargs,
        )
    try:
        venv: VecEnv = GymnasiumVecEnv(vector_env)
    except Exception:
        vector_env.close()
        raise
    return _vec_monitor(venv, monitor_path)


def _vec_monitor(venv: VecEnv, monitor_path: str | None) -> VecMonitor:
    """``VecMonitor`` logging ``is_success``; appends to an existing log (a resumed run)."""
    if monitor_path is None or not os.path.isfile(monitor_csv_path(monitor_path)):
        return VecMonitor(venv, filename=monitor_path, info_keywords=MONITOR_INFO_KEYWORDS)
    # VecMonitor always truncates its file; reopen it in append mode, without a second header.
    monitor = VecMonitor(venv, filename=None, info_keywords=MONITOR_INFO_KEYWORDS)
    monitor.results_writer = ResultsWriter(
        monitor_path, extra_keys=MONITOR_INFO_KEYWORDS, override_existing=False
    )
    return monitor
