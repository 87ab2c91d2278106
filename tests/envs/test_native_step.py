"""The native env step (``bearing_env._core``, csrc/env/) against numba's
(:mod:`bearing_env.envs.kernels`), bit for bit.

Each case builds a batch the way :mod:`bearing_env.envs.core` does (reset, groups by
landmark count, output arrays made once per group), copies the whole state (the envs'
``BatchState`` and every map batch), steps one copy through numba's ``step_rows`` (made
and called as core.py did before the switch to the native core: :class:`NumbaGroups`)
and the other through ``_core.step_rows`` (as the switch makes and calls it:
:class:`NativeGroups`), and compares every Report array, every
encoded robot-map array and every state array after each step; finished episodes are
reset in both copies (and their reports after the reset compared too). Then the other
kernels (potentials, decoding, the robot-map codec, the planner's) and bad arguments.
"""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bearing_env import _core
from bearing_env.envs import core, kernels, robot_map
from bearing_env.envs.actions import CONTINUOUS, DISCRETE
from bearing_env.envs.config import AREA_FLOOR, EnvConfig
from bearing_env.envs.core import MapBank
from bearing_env.envs.state import STATE_ARRAYS, BatchState
from bearing_env.obstacles import box
from bearing_env.slam import kernels as slam_kernels
from bearing_env.slam.batch import PARALLEL_MIN_MAPS, BatchedPolygonSLAM
from bearing_env.slam.batch import STATE_ARRAYS as MAP_STATE_ARRAYS

IntArray = np.ndarray


def same(a: Any, b: Any) -> bool:
    """Bit for bit: dtype, shape and bytes (NaN payloads and signed zeros count)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_same_tuple(
    expected: tuple[Any, ...], got: tuple[Any, ...], names: tuple[str, ...], what: str
) -> None:
    assert len(expected) == len(got) == len(names)
    for name, a, b in zip(names, expected, got, strict=True):
        assert same(a, b), f"{what}.{name} differs:\n{a}\n{b}"


def assert_same_dicts(
    expected: dict[str, Any] | None, got: dict[str, Any] | None, what: str
) -> None:
    assert (expected is None) == (got is None), what
    if expected is None or got is None:
        return
    assert list(expected) == list(got), what
    for name in expected:
        assert same(expected[name], got[name]), f"{what}[{name!r}] differs"


def map_state(batch: BatchedPolygonSLAM) -> slam_kernels.State:
    """The batch's arrays as a kernels.State tuple (the same arrays)."""
    return slam_kernels.State(*(batch.__dict__[name] for name in MAP_STATE_ARRAYS))


# ----------------------------------------------------------------------------------------
# The native step, made and called as core.step will call it after the switch
# ----------------------------------------------------------------------------------------


@dataclass
class NativeGroup:
    inputs: Any  #: _core.EnvInputs
    report: tuple[np.ndarray, ...]  #: the report's arrays, every row of the bank
    encoded: robot_map.Buffers | None
    outputs: Any  #: _core.StepOutputs
    batch: BatchedPolygonSLAM
    maps: Any  #: what EnvInputs took as the map state


@dataclass
class NativeGroups:
    """Per (landmark count, config): the native inputs and outputs, made once (where
    core.MapBank.group and core._outputs make numba's)."""

    #: How the map state is handed over: native (MapState and Params), tuple (the numba
    #: State and Params namedtuples) or batch (the BatchedPolygonSLAM, native Params).
    maps_form: str = "native"
    groups: dict[tuple[int, EnvConfig], NativeGroup] = field(default_factory=dict)

    def group(
        self, state: BatchState, maps: MapBank, rows: IntArray, config: EnvConfig
    ) -> NativeGroup:
        n = int(state.n_landmarks[rows[0]])
        kept = self.groups.get((n, config))
        if kept is None:
            batch = maps.batch(n, config)
            # The native Params, or (with the State tuple) the numba namedtuple it mirrors.
            params: Any = batch._kernel_params(True)
            if self.maps_form != "tuple":
                params = _core.Params(*params)
            if self.maps_form == "native":
                map_arg: Any = _core.MapState(map_state(batch))
            elif self.maps_form == "tuple":
                map_arg = map_state(batch)
            else:
                map_arg = batch
            inputs = _core.EnvInputs(core.kernel_settings(n, config), params, map_arg, state)
            every_row = np.arange(batch.num_maps)
            report = _core.new_report(every_row.size, inputs)
            encoded = None
            if config.observations.robot_map_info:
                slots = max(config.observations.max_landmarks - 2, n - 2)
                encoded = robot_map.buffers(_core.encode_map(map_arg, every_row, slots))
            outputs = _core.StepOutputs(inputs, report, None if encoded is None else encoded.kernel)
            kept = self.groups[n, config] = NativeGroup(
                inputs, report, encoded, outputs, batch, map_arg
            )
        return kept

    def step(
        self,
        state: BatchState,
        maps: MapBank,
        rows: IntArray,
        config: EnvConfig,
        turns: np.ndarray,
        lengths: np.ndarray,
        threads: int,
    ) -> tuple[kernels.Report, dict[str, Any] | None]:
        group = self.group(state, maps, rows, config)
        n = int(state.n_landmarks[rows[0]])
        while True:
            status = _core.step_rows(
                rows,
                turns,
                lengths,
                group.inputs,
                state.trajectory,
                threads,
                group.outputs,
                group.encoded is not None,
            )
            if status == _core.STEP_DONE:
                break
            if status == _core.STEP_NEEDS_NOISE:
                spent = state.noise_used[rows] + 2 * n > state.noise_filled[rows]
                core.fill_noise(state, rows[spent], config)
            else:
                assert status == _core.STEP_NEEDS_TRAJECTORY
                state.grow_trajectory()
        report = kernels.Report._make(values[: rows.size] for values in group.report)
        info = None
        if group.encoded is not None:
            info = self.with_fusion_arrays(
                group, dict(group.encoded.rows(rows.size).info), rows, config, n
            )
        return report, info

    def report(
        self, state: BatchState, maps: MapBank, rows: IntArray, config: EnvConfig
    ) -> tuple[kernels.Report, dict[str, Any] | None]:
        group = self.group(state, maps, rows, config)
        slots = config.observations.max_landmarks - 2
        arrays, encoded = _core.report_rows(rows, group.inputs, slots)
        report = kernels.Report._make(arrays)
        if not config.observations.robot_map_info:
            return report, None
        n = int(state.n_landmarks[rows[0]])
        info = robot_map.as_info(robot_map.MAP_ARRAYS, encoded)
        return report, self.with_fusion_arrays(group, info, rows, config, n)

    @staticmethod
    def with_fusion_arrays(
        group: NativeGroup, info: dict[str, Any], rows: IntArray, config: EnvConfig, n: int
    ) -> dict[str, Any]:
        batch = group.batch
        if batch.fusion == "intersect":
            return info
        slots = max(config.observations.max_landmarks - 2, n - 2)
        if batch.fusion == "relaxed":
            more = _core.encode_window(group.maps, rows, slots)
        else:
            more = _core.encode_levels(group.maps, rows, slots)
        names = batch.state_names[len(robot_map.MAP_ARRAYS) :]
        return {**info, **robot_map.as_info(names, more)}


@dataclass
class NumbaGroup:
    inputs: Any  #: kernels.InputsRef
    report: kernels.Report  #: the report's arrays, every row of the bank
    encoded: robot_map.Buffers | None
    batch: BatchedPolygonSLAM


@dataclass
class NumbaGroups:
    """The numba reference, made and called as core.py made and called it before the
    switch to the native core (kernels.inputs_ref, new_report, step_rows, report_rows and
    robot_map's numba codec), so that the comparison stays one after the switch."""

    groups: dict[tuple[int, EnvConfig], NumbaGroup] = field(default_factory=dict)

    def group(
        self, state: BatchState, maps: MapBank, rows: IntArray, config: EnvConfig
    ) -> NumbaGroup:
        n = int(state.n_landmarks[rows[0]])
        kept = self.groups.get((n, config))
        if kept is None:
            batch = maps.batch(n, config)
            inputs = kernels.inputs_ref(
                kernels.Inputs(
                    core.kernel_settings(n, config),
                    batch._kernel_params(True),
                    batch._kernel_state(),
                    state.kernel_ref(),
                )
            )
            every_row = np.arange(batch.num_maps)
            encoded = None
            if config.observations.robot_map_info:
                slots = max(config.observations.max_landmarks - 2, n - 2)
                encoded = robot_map.buffers(
                    robot_map.encode_map(batch._kernel_state(), every_row, slots)
                )
            report = kernels.new_report(every_row.size, inputs)
            kept = self.groups[n, config] = NumbaGroup(inputs, report, encoded, batch)
        return kept

    def step(
        self,
        state: BatchState,
        maps: MapBank,
        rows: IntArray,
        config: EnvConfig,
        turns: np.ndarray,
        lengths: np.ndarray,
    ) -> tuple[kernels.Report, dict[str, Any] | None]:
        group = self.group(state, maps, rows, config)
        n, size = int(state.n_landmarks[rows[0]]), rows.size
        report, encoded = group.report, group.encoded
        if size != report.rewards.size:
            report = kernels.Report._make(values[:size] for values in report)
            encoded = None if encoded is None else encoded.rows(size)
        threads = slam_kernels.threads() if size >= PARALLEL_MIN_MAPS else 1
        while True:
            args = (rows, turns, lengths, group.inputs, state.trajectory, threads, report)
            if encoded is not None:
                status = kernels.step_rows(*args, encoded.kernel)
            else:
                status = kernels.step_rows_bare(*args)
            if status == kernels.STEP_DONE:
                break
            if status == kernels.STEP_NEEDS_NOISE:
                spent = state.noise_used[rows] + 2 * n > state.noise_filled[rows]
                core.fill_noise(state, rows[spent], config)
            else:
                state.grow_trajectory()
        if encoded is None:
            return report, None
        return report, self.with_fusion_arrays(group, dict(encoded.info), rows, config, n)

    def report(
        self, state: BatchState, maps: MapBank, rows: IntArray, config: EnvConfig
    ) -> tuple[kernels.Report, dict[str, Any] | None]:
        group = self.group(state, maps, rows, config)
        slots = config.observations.max_landmarks - 2
        report, encoded = kernels.report_rows(rows, group.inputs, slots)
        if not config.observations.robot_map_info:
            return report, None
        n = int(state.n_landmarks[rows[0]])
        info = robot_map.as_info(robot_map.MAP_ARRAYS, encoded)
        return report, self.with_fusion_arrays(group, info, rows, config, n)

    @staticmethod
    def with_fusion_arrays(
        group: NumbaGroup, info: dict[str, Any], rows: IntArray, config: EnvConfig, n: int
    ) -> dict[str, Any]:
        batch = group.batch
        if batch.fusion == "intersect":
            return info
        slots = max(config.observations.max_landmarks - 2, n - 2)
        if batch.fusion == "relaxed":
            more = robot_map.encode_window(batch._kernel_state(), rows, slots)
        else:
            more = robot_map.encode_levels(batch._kernel_state(), rows, slots)
        names = batch.state_names[len(robot_map.MAP_ARRAYS) :]
        return {**info, **robot_map.as_info(names, more)}


# ----------------------------------------------------------------------------------------
# Twin batches
# ----------------------------------------------------------------------------------------


def assert_same_state(
    reference: tuple[BatchState, MapBank], native: tuple[BatchState, MapBank], what: str
) -> None:
    (state, maps), (other, other_maps) = reference, native
    for name in STATE_ARRAYS:
        value = getattr(state, name)
        if isinstance(value, np.ndarray):
            assert same(value, getattr(other, name)), f"{what}: state.{name} differs"
    assert list(maps.batches) == list(other_maps.batches)
    for key, batch in maps.batches.items():
        for name in MAP_STATE_ARRAYS:
            assert same(getattr(batch, name), getattr(other_maps.batches[key], name)), (
                f"{what}: maps {key[0]}.{name} differs"
            )


def draw_actions(
    config: EnvConfig, kind: str, size: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    if kind == "discrete":
        n_actions = config.actions.n_turns * config.actions.n_move_lengths
        turns, lengths = DISCRETE.decode(config, rng.integers(0, n_actions, size))
    else:
        turns, lengths = CONTINUOUS.decode(config, rng.uniform(-1.0, 1.0, (size, 2)))
    lengths = lengths.copy()
    # Some moves too short to change frames (the map update sees a subset of the rows).
    short = rng.random(size) < 0.15
    lengths[short] = rng.choice([0.0, 1e-6, 1e-4], int(short.sum()))
    return np.ascontiguousarray(turns, dtype=np.float64), lengths


def run_twins(
    config: EnvConfig,
    num_rows: int,
    steps: int,
    seed: int,
    threads: int,
    actions: str = "continuous",
    maps_form: str = "native",
) -> dict[str, int]:
    """Steps a batch twice (numba, native) from one reset; returns counts of what happened."""
    state = BatchState.empty(num_rows, config.max_landmarks)
    maps = MapBank(num_rows)
    rngs = [np.random.default_rng(1000 * seed + row) for row in range(num_rows)]
    core.reset_rows(state, np.arange(num_rows), config, rngs, maps)
    reference = (state, maps)
    native = copy.deepcopy(reference)
    natives, numbas = NativeGroups(maps_form), NumbaGroups()
    rng = np.random.default_rng(seed)
    counts = {"steps": 0, "frame_changed": 0, "terminated": 0, "truncated": 0, "resets": 0}
    all_rows = np.arange(num_rows)
    for step in range(steps):
        # Sometimes a part of the batch steps (a vector env with some envs waiting).
        rows = (
            all_rows
            if rng.random() < 0.7
            else np.sort(rng.choice(all_rows, int(rng.integers(1, num_rows + 1)), replace=False))
        )
        for _n, group_rows in core.group_rows(state, rows):
            group_rows = np.ascontiguousarray(group_rows, dtype=np.int64)
            turns, lengths = draw_actions(config, actions, group_rows.size, rng)
            expected, expected_map = numbas.step(*reference, group_rows, config, turns, lengths)
            got, got_map = natives.step(*native, group_rows, config, turns, lengths, threads)
            what = f"step {step}, rows {group_rows.tolist()}"
            assert_same_tuple(tuple(expected), tuple(got), kernels.Report._fields, what)
            assert_same_dicts(expected_map, got_map, what + " robot_map")
            counts["steps"] += 1
            counts["frame_changed"] += int(expected.frame_changed.sum())
            counts["terminated"] += int(expected.terminated.sum())
            counts["truncated"] += int(expected.truncated.sum())
        assert_same_state(reference, native, f"after step {step}")
        done = np.flatnonzero(state.done)
        if done.size:
            counts["resets"] += int(done.size)
            for twin in (reference, native):
                twin_state, twin_maps = twin
                generators = [twin_state.noise_generators[row] for row in done]
                core.reset_rows(twin_state, done, config, generators, twin_maps)
            assert_same_state(reference, native, f"after the resets of step {step}")
            for _n, group_rows in core.group_rows(state, done):
                expected, expected_map = numbas.report(*reference, group_rows, config)
                got, got_map = natives.report(*native, group_rows, config)
                what = f"report after reset, step {step}"
                assert_same_tuple(tuple(expected), tuple(got), kernels.Report._fields, what)
                assert_same_dicts(expected_map, got_map, what + " robot_map")
    return counts


#: Configs covering every observation kind, fusion, transfer and policy, fields of view,
#: ranges, obstacles, landmark count ranges, noise kinds, rewards and episode ends.
CONFIGS: dict[str, dict[str, Any]] = {
    "flat": {"n_landmarks": 6, "noise": {"kind": "gaussian", "outlier_rate": 0.1}},
    "khepera_area_reward": {
        "scenario": "khepera",
        "reward": "area",
        "path_cost": 0.5,
        "move_cost": 0.01,
        "max_moves": 8,
    },
    "furnished_shapes_fov": {
        "scenario": "furnished_room",
        "observation": "shapes",
        "field_of_view_deg": 250.0,
        "max_range": 1.6,
    },
    "corridor_relaxed_entities": {
        "scenario": "l_corridor",
        "fusion": "relaxed",
        "observation": "entities",
        "field_of_view_deg": 200.0,
    },
    "counts_robust": {
        "n_landmarks": (3, 7),
        "fusion": "robust",
        "max_landmarks": 8,
        "noise": {"kind": "uniform", "detection_rate": 0.8},
    },
    "robust_likely_fixed": {
        "n_landmarks": 5,
        "fusion": "robust",
        "robust_set": "likely",
        "noise_bound": "nominal",
        "observation": "shapes",
    },
    "paper_keep_no_map": {
        "n_landmarks": 7,
        "transfer": "paper",
        "on_inconsistency": "keep",
        "robot_map_info": False,
        "noise": {"kind": "none"},
        "max_range": 0.5,
    },
    "easy_success": {
        "n_landmarks": 4,
        "target_area": 5.0,
        "max_moves": 6,
        "observation": "shapes",
        "max_landmarks": 9,
    },
    "relaxed_counts_obstacles": {
        "obstacles": (box(0.4, 0.3, 0.6, 0.45),),
        "fusion": "relaxed",
        "max_outliers": 1,
        "n_landmarks": (3, 5),
        "noise": {"kind": "uniform", "bound_deg": 4.0, "outlier_rate": 0.2},
    },
}


@pytest.mark.parametrize("name", list(CONFIGS))
@pytest.mark.parametrize(("num_rows", "threads"), [(1, 1), (16, 2)])
def test_the_native_step_matches_numba(name: str, num_rows: int, threads: int) -> None:
    config = EnvConfig.create(**CONFIGS[name])
    seed = sorted(CONFIGS).index(name) + 10 * num_rows
    steps = 12 if num_rows == 1 else 5
    kind = "discrete" if seed % 2 else "continuous"
    counts = run_twins(config, num_rows, steps, seed, threads, kind)
    assert counts["steps"] >= steps


def test_a_batch_of_40_on_two_threads_and_one() -> None:
    """40 rows: the map update runs in blocks on 2 threads (PARALLEL_MIN_MAPS = 32)."""
    config = EnvConfig.create(n_landmarks=5, max_moves=6, observation="shapes")
    for threads in (1, 2):
        counts = run_twins(config, 40, 8, seed=7, threads=threads)
        assert counts["frame_changed"] > 0 and counts["resets"] > 0


@pytest.mark.parametrize("maps_form", ["tuple", "batch"])
def test_the_map_state_may_be_handed_over_as_a_tuple_or_the_batch(maps_form: str) -> None:
    config = EnvConfig.create(n_landmarks=5, fusion="relaxed")
    run_twins(config, 3, 6, seed=3, threads=1, maps_form=maps_form)


def test_episode_ends_are_exercised() -> None:
    counts = run_twins(EnvConfig.create(**CONFIGS["easy_success"]), 8, 14, seed=5, threads=1)
    assert counts["terminated"] > 0 and counts["truncated"] > 0 and counts["resets"] > 0


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CONFIGS))
@pytest.mark.parametrize(("num_rows", "threads"), [(1, 1), (16, 1), (16, 2), (40, 2)])
def test_the_native_step_matches_numba_at_length(name: str, num_rows: int, threads: int) -> None:
    config = EnvConfig.create(**CONFIGS[name])
    for seed in range(3):
        for kind in ("continuous", "discrete"):
            run_twins(config, num_rows, 40, 100 + seed, threads, kind)


# ----------------------------------------------------------------------------------------
# The other kernels
# ----------------------------------------------------------------------------------------


def started(config: EnvConfig, num_rows: int, seed: int) -> tuple[BatchState, MapBank]:
    state = BatchState.empty(num_rows, config.max_landmarks)
    maps = MapBank(num_rows)
    rngs = [np.random.default_rng(seed + row) for row in range(num_rows)]
    core.reset_rows(state, np.arange(num_rows), config, rngs, maps)
    return state, maps


def stepped(config: EnvConfig, num_rows: int, seed: int, steps: int) -> tuple[BatchState, MapBank]:
    state, maps = started(config, num_rows, seed)
    rng = np.random.default_rng(seed)
    rows = np.arange(num_rows)
    for _ in range(steps):
        if state.done.any():
            done = np.flatnonzero(state.done)
            core.reset_rows(state, done, config, [state.noise_generators[r] for r in done], maps)
        for _n, group in core.group_rows(state, rows):
            turns, lengths = CONTINUOUS.decode(config, rng.uniform(-1, 1, (group.size, 2)))
            core.step(state, maps.group(state, group, config), turns, lengths)
    return state, maps


@pytest.mark.parametrize("fusion", ["intersect", "relaxed", "robust"])
def test_potentials_and_the_robot_map_codec(fusion: str) -> None:
    config = EnvConfig.create(n_landmarks=6, fusion=fusion, max_landmarks=9)
    state, maps = stepped(config, 6, seed=21, steps=7)
    rows = np.array([4, 0, 3])
    group = NumbaGroups().group(state, maps, rows, config)
    batch = group.batch
    tuple_state = map_state(batch)
    native_maps = _core.MapState(tuple_state)
    inputs = _core.EnvInputs(
        core.kernel_settings(6, config),
        _core.Params(*batch._kernel_params(True)),
        native_maps,
        state,
    )
    expected, got = np.empty(3), np.empty(3)
    kernels.potentials(rows, group.inputs, expected)
    _core.potentials(rows, inputs, got)
    assert same(expected, got)
    ref_state = batch._kernel_state()
    for slots in (4, 7):
        assert_same_tuple(
            robot_map.encode_map(ref_state, rows, slots),
            _core.encode_map(native_maps, rows, slots),
            robot_map.MAP_ARRAYS,
            "encode_map",
        )
        assert_same_tuple(
            robot_map.encode_window(ref_state, rows, slots),
            _core.encode_window(tuple_state, rows, slots),
            tuple(map(str, range(10))),
            "encode_window",
        )
        assert_same_tuple(
            robot_map.encode_levels(ref_state, rows, slots),
            _core.encode_levels(batch, rows, slots),
            tuple(map(str, range(13))),
            "encode_levels",
        )
        # an EnvInputs stands for its map state (no arrays checked again)
        assert_same_tuple(
            _core.encode_window(tuple_state, rows, slots),
            _core.encode_window(inputs, rows, slots),
            tuple(map(str, range(10))),
            "encode_window(inputs)",
        )
        assert_same_tuple(
            _core.encode_levels(tuple_state, rows, slots),
            _core.encode_levels(inputs, rows, slots),
            tuple(map(str, range(13))),
            "encode_levels(inputs)",
        )
    # encode_map_into over arrays that held something else
    encoded = tuple(np.full_like(a, 7) for a in robot_map.encode_map(ref_state, rows, 5))
    native = tuple(a.copy() for a in encoded)
    robot_map.encode_map_into(ref_state, rows, encoded)
    _core.encode_map_into(native_maps, rows, native)
    assert_same_tuple(encoded, native, robot_map.MAP_ARRAYS, "encode_map_into")
    # report_rows and new_report
    expected_report, expected_encoded = kernels.report_rows(rows, group.inputs, 5)
    got_report, got_encoded = _core.report_rows(rows, inputs, 5)
    assert_same_tuple(tuple(expected_report), got_report, kernels.Report._fields, "report_rows")
    assert_same_tuple(expected_encoded, got_encoded, robot_map.MAP_ARRAYS, "report_rows map")
    fresh = kernels.new_report(4, group.inputs)
    native_fresh = _core.new_report(4, inputs)
    for name, a, b in zip(kernels.Report._fields, fresh, native_fresh, strict=True):
        assert a.dtype == b.dtype and a.shape == b.shape, name
        if name in kernels.Report._fields[:10]:
            assert same(a, b), name


def test_move_and_read_and_append_positions() -> None:
    config = EnvConfig.create(scenario="furnished_room", field_of_view_deg=90.0)
    state, maps = started(config, 3, seed=4)
    native_state, native_maps = copy.deepcopy((state, maps))
    group = NumbaGroups().group(state, maps, np.arange(3), config)
    native = NativeGroups().group(native_state, native_maps, np.arange(3), config)
    n = int(state.n_landmarks[0])
    for row, turn, length in ((0, 0.3, 0.2), (2, -2.0, 5.0), (1, 1.0, 0.0)):
        a, b = np.empty(n), np.empty(n)
        c, d = np.empty(n), np.empty(n)
        travelled = kernels.move_and_read(row, turn, length, group.inputs, a, b)
        native_travelled = _core.move_and_read(row, turn, length, native.inputs, c, d)
        assert same(travelled, native_travelled) and same(a, c) and same(b, d)
    assert_same_state((state, maps), (native_state, native_maps), "move_and_read")
    # Until the trajectory is full (then False, nothing written); a repeated row appends
    # twice (numba would write past a full row there: the native kernel raises).
    for rows, times in ((np.array([0, 2]), 40), (np.array([1, 1, 1]), 8)):
        for twin in ((state, kernels), (native_state, _core)):
            twin_state, module = twin
            lengths = twin_state.trajectory_length
            for _ in range(times):
                module.append_positions(rows, twin_state.positions, twin_state.trajectory, lengths)
        assert same(state.trajectory, native_state.trajectory)
        assert same(state.trajectory_length, native_state.trajectory_length)
    assert native_state.trajectory_length[1] == 25
    with pytest.raises(_core.CapacityError):
        _core.append_positions(
            np.array([1] * 8),
            native_state.positions,
            native_state.trajectory,
            native_state.trajectory_length,
        )


finite = st.floats(-1e3, 1e3, allow_nan=False)
special = st.sampled_from([0.0, -0.0, math.nan, math.inf, -math.inf, 1e-320, 1e300])


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.lists(st.one_of(finite, special), min_size=1, max_size=14),
    st.booleans(),
    st.sampled_from([AREA_FLOOR, 0.0, 1e-3]),
    st.sampled_from([10.0, 1.0, math.inf]),
)
def test_potentials_of_areas(areas: list[float], log_area: bool, floor: float, cap: float) -> None:
    values = np.array(areas)
    for count in {0, len(areas) // 2, len(areas)}:
        assert same(
            kernels.potential_of(values, count, log_area, floor, cap),
            _core.potential_of(values, count, log_area, floor, cap),
        )
    assert same(kernels.capped(values[0], floor, cap), _core.capped(values[0], floor, cap))
    from agents.planning import _potentials_of_rows

    rows = np.resize(values, (3, len(areas)))
    expected, got = np.empty(3), np.empty(3)
    _potentials_of_rows(rows, log_area, floor, cap, expected)
    _core._potentials_of_rows(rows, log_area, floor, cap, got)
    assert same(expected, got)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.complex_numbers(allow_nan=True, allow_infinity=True),
    st.lists(st.tuples(st.one_of(finite, special), st.one_of(finite, special)), max_size=8),
)
def test_move_ends_and_known(start: complex, candidates: list[tuple[float, float]]) -> None:
    from agents.planning import _move_ends

    headings = np.array([h for h, _ in candidates], dtype=np.float64)
    distances = np.array([d for _, d in candidates], dtype=np.float64)
    expected = np.empty(len(candidates), np.complex128)
    got = np.empty(len(candidates), np.complex128)
    _move_ends(start, headings, distances, expected)
    _core._move_ends(start, headings, distances, got)
    # numba's LLVM vectorises this loop: where two NaNs meet in a sum, the vector code may
    # keep the other operand's NaN (payload, sign) than the scalar code. Such NaNs compare
    # as "some NaN"; every other value bit for bit.
    parts, native_parts = expected.view(np.float64), got.view(np.float64)
    both_nan = np.isnan(parts) & np.isnan(native_parts)
    assert same(np.where(both_nan, 0.0, parts), np.where(both_nan, 0.0, native_parts))
    assert same(np.complex128(robot_map._known(start)), np.complex128(_core._known(start)))


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    st.lists(st.tuples(st.one_of(finite, special), st.one_of(finite, special)), max_size=6),
    st.sampled_from([np.float32, np.float64]),
    st.sampled_from([(0.0, 0.3), (0.05, 0.05), (-1.0, 2.5)]),
)
def test_decode_continuous(
    actions: list[tuple[float, float]], dtype: Any, bounds: tuple[float, float]
) -> None:
    with np.errstate(over="ignore"):  # 1e300 as float32 is inf
        values = np.array(actions, dtype=dtype).reshape(-1, 2)
    values = (
        np.clip(values, -1.0000009, 1.0000009)
        if values.size and np.all(np.isfinite(values))
        else values
    )
    lo, hi = bounds
    outs = [np.full(values.shape[0], 9.0) for _ in range(4)]
    status = kernels.decode_continuous(values, lo, hi, outs[0], outs[1])
    native = _core.decode_continuous(values, lo, hi, outs[2], outs[3])
    assert status == native
    assert same(outs[0], outs[2]) and same(outs[1], outs[3])


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.lists(st.tuples(finite, finite), min_size=1, max_size=12),
    st.integers(0, 3),
)
def test_write_shape(points: list[tuple[float, float]], j: int) -> None:
    vertices = np.zeros(16, np.complex128)
    vertices[: len(points)] = [complex(x, y) for x, y in points]
    expected = np.zeros(3 * 4, np.float32)
    got = np.zeros(3 * 4, np.float32)
    kernels._write_shape(vertices, len(points), expected, j)
    _core._write_shape(vertices, len(points), got, j)
    assert same(expected, got)


# ----------------------------------------------------------------------------------------
# Bad arguments
# ----------------------------------------------------------------------------------------


def test_bad_arguments_are_refused_naming_them() -> None:
    config = EnvConfig.create(n_landmarks=5)
    state, maps = started(config, 4, seed=1)
    native = NativeGroups().group(state, maps, np.arange(4), config)
    inputs, outputs = native.inputs, native.outputs
    rows, turns, lengths = np.arange(2), np.zeros(2), np.full(2, 0.1)
    settings_ = core.kernel_settings(5, config)
    params = _core.Params(*native.batch._kernel_params(True))
    with pytest.raises(
        ValueError, match=re.escape("maps hold 3 mapped landmarks, settings.n - 2 is 2")
    ):
        _core.EnvInputs(settings_._replace(n=4), params, native.maps, state)
    with pytest.raises(TypeError, match="obstacle_vertices must have dtype float64"):
        bad = settings_._replace(obstacle_vertices=np.zeros((0, 2), np.float32))
        _core.EnvInputs(bad, params, native.maps, state)
    with pytest.raises(TypeError, match="'n_landmarks'"):
        _core.EnvInputs(settings_, params, native.maps, object())
    with pytest.raises(ValueError, match="positions has axis 1"):
        broken = copy.copy(state)
        broken.positions = np.zeros((4, 3))
        _core.EnvInputs(settings_, params, native.maps, broken)
    with pytest.raises(ValueError, match=re.escape("maps.counts has")):
        tuple_state = map_state(native.batch)._replace(counts=np.zeros((4, 2), np.int64))
        _core.EnvInputs(settings_, params, tuple_state, state)
    with pytest.raises(TypeError, match="rows must have dtype int64"):
        _core.step_rows(
            rows.astype(np.int32), turns, lengths, inputs, state.trajectory, 1, outputs, True
        )
    with pytest.raises(ValueError, match="rows holds 4, outside"):
        _core.step_rows(
            np.array([0, 4]), turns, lengths, inputs, state.trajectory, 1, outputs, True
        )
    with pytest.raises(ValueError, match="must not repeat"):
        _core.step_rows(
            np.array([1, 1]), turns, lengths, inputs, state.trajectory, 1, outputs, True
        )
    with pytest.raises(ValueError, match="turns has axis 0"):
        _core.step_rows(rows, np.zeros(3), lengths, inputs, state.trajectory, 1, outputs, True)
    with pytest.raises(ValueError, match="trajectory has axis 2"):
        _core.step_rows(rows, turns, lengths, inputs, np.zeros((4, 8, 3)), 1, outputs, True)
    with pytest.raises(TypeError, match="outputs"):
        _core.step_rows(rows, turns, lengths, inputs, state.trajectory, 1, None, True)
    other = NativeGroups().group(state, maps, np.arange(4), config)
    with pytest.raises(ValueError, match="outputs were made for other inputs"):
        _core.step_rows(rows, turns, lengths, inputs, state.trajectory, 1, other.outputs, True)
    bare = _core.StepOutputs(inputs, _core.new_report(4, inputs))
    with pytest.raises(ValueError, match="with_map needs outputs made with the encoded"):
        _core.step_rows(rows, turns, lengths, inputs, state.trajectory, 1, bare, True)
    small = _core.StepOutputs(inputs, _core.new_report(1, inputs))
    with pytest.raises(ValueError, match="rows has 2 rows, outputs hold 1"):
        _core.step_rows(rows, turns, lengths, inputs, state.trajectory, 1, small, False)
    report = list(_core.new_report(4, inputs))
    report[3] = np.zeros(4)
    with pytest.raises(TypeError, match=re.escape("report.truncated must have dtype bool")):
        _core.StepOutputs(inputs, tuple(report))
    report = list(_core.new_report(4, inputs))
    report[0] = np.zeros((4, 5), np.float32)
    with pytest.raises(ValueError, match=re.escape("report.observations has axis 1")):
        _core.StepOutputs(inputs, tuple(report))
    with pytest.raises(ValueError, match="report must hold 16 arrays"):
        _core.StepOutputs(inputs, tuple(report[:5]))
    encoded = list(_core.encode_map(native.maps, np.arange(4), 3))
    encoded[0] = np.zeros((4, 2, encoded[0].shape[2]), np.complex128)
    with pytest.raises(ValueError, match=re.escape("encoded.vertices has 2 landmark slots")):
        _core.StepOutputs(inputs, _core.new_report(4, inputs), tuple(encoded))
    with pytest.raises(ValueError, match="slots"):
        _core.encode_map(native.maps, np.arange(4), 2)
    with pytest.raises(ValueError, match="n_mapped"):
        _core.potential_of(np.zeros(3), 4, True, 1e-10, 10.0)
    with pytest.raises(ValueError, match="shape block"):
        _core._write_shape(np.zeros(4, np.complex128), 3, np.zeros(3, np.float32), 1)
    with pytest.raises(TypeError, match="actions must have dtype float64"):
        _core.decode_continuous(np.zeros((2, 2), np.int64), 0.0, 1.0, np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="lengths has axis 0"):
        _core.decode_continuous(np.zeros((2, 2)), 0.0, 1.0, np.zeros(2), np.zeros(3))
    # A corrupt noise count raises instead of reading past the noise buffers.
    state.noise_filled[0] = state.noise_offsets.shape[1] + 100
    state.noise_used[0] = state.noise_offsets.shape[1]
    with pytest.raises(_core.CapacityError):
        _core.step_rows(rows, turns, lengths, inputs, state.trajectory, 1, outputs, True)
