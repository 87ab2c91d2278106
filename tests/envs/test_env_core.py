"""The functional core: a batch of rows computes as rows computed one at a time."""

from __future__ import annotations

import numpy as np
import pytest

from bearing_env.envs import core
from bearing_env.envs.actions import CONTINUOUS
from bearing_env.envs.config import EnvConfig
from bearing_env.envs.core import MapBank
from bearing_env.envs.state import INITIAL_TRAJECTORY_SLOTS, STATE_ARRAYS, BatchState


def started_batch(
    config: EnvConfig, num_rows: int, seed: int
) -> tuple[BatchState, MapBank, list[np.random.Generator]]:
    state = BatchState.empty(num_rows, config.max_landmarks)
    maps = MapBank(num_rows)
    rngs = [np.random.default_rng(seed + row) for row in range(num_rows)]
    core.reset_rows(state, np.arange(num_rows), config, rngs, maps)
    return state, maps, rngs


def test_a_batch_steps_as_its_rows_one_at_a_time() -> None:
    config = EnvConfig.create(n_landmarks=6, noise={"kind": "gaussian", "outlier_rate": 0.1})
    n = 5
    batch, batch_maps, _batch_rngs = started_batch(config, n, seed=10)
    singles = [started_batch(config, 1, seed=10 + row) for row in range(n)]
    actions = np.random.default_rng(0).uniform(-1, 1, (6, n, 2))
    all_rows, one = np.arange(n), np.array([0])
    for step_actions in actions:
        turns, lengths = CONTINUOUS.decode(config, step_actions)
        group = batch_maps.group(batch, all_rows, config)
        outcome, _ = core.step(batch, group, turns, lengths)
        for row, (state, maps, _rngs) in enumerate(singles):
            alone = maps.group(state, one, config)
            single, _ = core.step(state, alone, turns[row : row + 1], lengths[row : row + 1])
            assert single.rewards[0] == outcome.rewards[row]
            assert single.frame_changed[0] == outcome.frame_changed[row]
            assert np.array_equal(single.observations[0], outcome.observations[row])
            assert np.array_equal(state.positions[0], batch.positions[row])
    assert np.any(batch.frame_changed)  # the maps really fused movements


def test_a_group_step_leaves_the_other_rows_untouched() -> None:
    config = EnvConfig.create(scenario="khepera")
    state, maps, _rngs = started_batch(config, 4, seed=3)
    arrays = [name for name in STATE_ARRAYS if isinstance(getattr(state, name), np.ndarray)]
    before = {name: np.copy(getattr(state, name)) for name in arrays}
    areas_before = maps.batch(4, config).areas.copy()
    group = np.array([1, 3])
    turns, lengths = CONTINUOUS.decode(config, np.array([[0.3, 1.0], [-0.2, 1.0]]))
    core.step(state, maps.group(state, group, config), turns, lengths)
    others = np.array([0, 2])
    for name in arrays:
        value = getattr(state, name)
        if name == "trajectory":
            continue  # may have grown; the used entries are compared below
        assert np.array_equal(value[others], before[name][others], equal_nan=True), name
    assert np.array_equal(maps.batch(4, config).areas[others], areas_before[others])
    assert np.all(state.moves[group] == 1) and np.all(state.trajectory_length[group] == 2)
    assert np.array_equal(state.trajectory[others, :1], before["trajectory"][others, :1])


def test_the_trajectory_grows_past_its_first_capacity() -> None:
    config = EnvConfig.create(scenario="khepera", max_moves=200, target_area=1e-12)
    state, maps, _rngs = started_batch(config, 2, seed=0)
    rows = np.arange(2)
    visited = [state.positions.copy()]
    steps = 2 * INITIAL_TRAJECTORY_SLOTS + 3
    for action in np.random.default_rng(1).uniform(-1, 1, (steps, 2, 2)):
        turns, lengths = CONTINUOUS.decode(config, action)
        core.step(state, maps.group(state, rows, config), turns, lengths)
        visited.append(state.positions.copy())
    assert np.all(state.trajectory_length == steps + 1)
    assert np.array_equal(state.trajectory[:, : steps + 1], np.stack(visited, axis=1))


@pytest.mark.parametrize(
    "noise", [{"kind": "uniform"}, {"kind": "gaussian", "outlier_rate": 0.2, "detection_rate": 0.9}]
)
@pytest.mark.parametrize("moves", [0, 3, 20])
def test_the_noise_drawn_ahead_is_handed_back_unspent(noise: dict[str, object], moves: int) -> None:
    """A row draws its moves' noise ahead, in a block; when the episode ends early (or the
    generator is read), the generator is rewound to where drawing move by move, as the
    readings need it, would have left it: its next draw is the same either way."""
    config = EnvConfig.create(scenario="khepera", noise=noise, max_moves=20, target_area=1e-12)
    state, maps, rngs = started_batch(config, 1, seed=4)
    for action in np.random.default_rng(5).uniform(-1, 1, (moves, 1, 2)):
        turns, lengths = CONTINUOUS.decode(config, action)
        core.step(state, maps.group(state, np.array([0]), config), turns, lengths)
    core.release_noise(state, 0)
    # By hand: the same reset (rewound to the episode's start: nothing spent), then the
    # two readings of 4 bearings of each move, one at a time.
    fresh = BatchState.empty(1, config.max_landmarks)
    by_hand = np.random.default_rng(4)
    core.reset_rows(fresh, np.array([0]), config, [by_hand], MapBank(1))
    fresh.noise_used[0] = 0
    core.release_noise(fresh, 0)
    model = config.sensor.noise
    for _ in range(2 * moves):
        model.draw_rows([by_hand], 4, config.epsilon)
    assert rngs[0].random() == by_hand.random()


@pytest.mark.parametrize("fusion", ["intersect", "relaxed"])
def test_the_robot_map_codec_round_trips_a_map_through_an_info(fusion: str) -> None:
    """encode (the env's side) then decode (the policies') gives the same map state, with
    the per-landmark arrays padded to the env's slots in between."""
    from bearing_env.envs import robot_map
    from bearing_env.slam import PolygonSLAM

    rng = np.random.default_rng(8)
    slam = PolygonSLAM(5, np.deg2rad(3.0), fusion=fusion)
    for _ in range(6):
        slam.update(rng.uniform(-np.pi, np.pi, 5), rng.uniform(-np.pi, np.pi, 5))
    batch = slam.batch
    data = robot_map.encode(batch, np.array([0]), slots=8)
    one_env = {name: values[0] for name, values in data.items()}
    assert one_env["counts"].shape == (8,) and np.all(one_env["counts"][3:] == 0)
    assert np.all(np.isinf(one_env["areas"][3:]))
    back = robot_map.decode(one_env, 5, batch.settings).batch
    assert back.settings == batch.settings and back.fusion == fusion
    for name in batch.state_names:
        np.testing.assert_array_equal(
            np.nan_to_num(getattr(back, name)), np.nan_to_num(getattr(batch, name)), err_msg=name
        )


@pytest.mark.parametrize("env_id", ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"])
def test_the_action_spec_is_the_one_home_of_spaces_decoding_and_encoding(env_id: str) -> None:
    """The env, its vector env and the agents' codec share one action spec: encode gives
    an action of the env's space that decodes to the nearest movement on its grid."""
    import gymnasium as gym

    from bearing_env.agents import ActionCodec
    from bearing_env.envs.bearing_slam_vector import (
        BearingSLAMDiscreteVectorEnv,
        BearingSLAMVectorEnv,
    )

    env = gym.make(env_id, scenario="khepera")
    base = env.unwrapped
    spec = base.action_spec
    vector = BearingSLAMDiscreteVectorEnv if spec.grid_fixed else BearingSLAMVectorEnv
    assert vector.action_spec is spec and ActionCodec(env).spec is spec
    assert env.action_space == spec.space(base.config)
    rng = np.random.default_rng(2)
    lo, hi = base.config.move_length
    for turn, length in zip(rng.uniform(-3.0, 3.0, 20), rng.uniform(lo, hi, 20), strict=True):
        action = spec.encode(base.config, turn, length)
        assert env.action_space.contains(action)
        turns, lengths = spec.decode(base.config, np.asarray([action]))
        gap = abs((turns[0] - turn + np.pi) % (2 * np.pi) - np.pi)
        if spec.grid_fixed:  # the nearest of n_turns turns, of n_move_lengths lengths
            assert gap <= np.pi / base.config.n_turns + 1e-12
            assert abs(lengths[0] - length) <= (hi - lo) / 4 + 1e-12
        else:  # float32 rounding only
            assert gap < 1e-6 and abs(lengths[0] - length) < 1e-6
