"""Obstacles and the limited sensor in the envs: settings, files, scenarios, blocked
moves, missed readings, and the vector env bit for bit on the new tasks."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from bearing_env.envs.config import EnvConfig
from bearing_env.obstacles import random_obstacles
from bearing_env.sensing import clearance
from bearing_env.world import SCENARIOS
from tests.envs.test_env_vector import assert_pair_agrees, make_pair
from tests.extras import needs

BOX = [[0.4, 0.3], [0.6, 0.3], [0.6, 0.45], [0.4, 0.45]]


@pytest.mark.parametrize(
    ("settings", "error", "match"),
    [
        ({"field_of_view_deg": 0}, ValueError, "field_of_view_deg"),
        ({"field_of_view_deg": 361}, ValueError, "field_of_view_deg"),
        ({"field_of_view_deg": "wide"}, TypeError, "field_of_view_deg"),
        ({"max_range": 0.0}, ValueError, "max_range"),
        ({"max_range": math.nan}, ValueError, "max_range"),
        ({"max_range": "far"}, TypeError, "max_range"),
        ({"sensor_info": "yes"}, TypeError, "sensor_info"),
        ({"obstacles": 3}, TypeError, "obstacles must be"),
        ({"obstacles": [[[0, 0], [1, 1]]]}, ValueError, "obstacle 0 must have >= 3"),
        ({"obstacles": [[[0, 0], [1, 1], [1, 0], [0, 1]]]}, ValueError, "simple polygon"),
        ({"obstacles": [[[0.9, 0.1], [1.2, 0.1], [1.0, 0.3]]]}, ValueError, "leaves the arena"),
        ({"obstacles": [BOX, BOX]}, ValueError, "obstacles 0 and 1 overlap"),
        ({"obstacles": {"random": 2}}, ValueError, "random obstacles"),
        ({"obstacles": {"random": 2, "seed": -1}}, ValueError, "seed"),
        ({"obstacles": "walls.txt"}, ValueError, "must end in one of"),
        ({"obstacles": "missing.json"}, ValueError, "cannot read"),
    ],
)
def test_invalid_sensor_and_obstacle_settings_raise_naming_the_value(
    settings: dict[str, Any], error: type[Exception], match: str
) -> None:
    with pytest.raises(error, match=match):
        EnvConfig.create(scenario="khepera", **settings)


def test_a_landmark_inside_an_obstacle_is_refused() -> None:
    around_l1 = [[0.4, 0.1], [0.5, 0.1], [0.5, 0.2], [0.4, 0.2]]
    with pytest.raises(ValueError, match=r"landmark \(0.425, 0.16\) lies inside"):
        EnvConfig.create(scenario="khepera", obstacles=[around_l1])


CRATE = [[0.8, 0.5], [0.9, 0.5], [0.85, 0.6]]


def test_obstacle_files_json(tmp_path: Path) -> None:
    data = {"obstacles": [BOX, {"name": "crate", "vertices": CRATE}]}
    (tmp_path / "room.json").write_text(json.dumps(data))
    from_json = EnvConfig.create(scenario="khepera", obstacles=str(tmp_path / "room.json"))
    inline = EnvConfig.create(scenario="khepera", obstacles=[BOX, CRATE])
    assert from_json == inline and len(inline.obstacles) == 2
    (tmp_path / "bad.json").write_text(json.dumps({"walls": []}))
    with pytest.raises(ValueError, match="'obstacles' list"):
        EnvConfig.create(scenario="khepera", obstacles=tmp_path / "bad.json")
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(ValueError, match="not valid JSON"):
        EnvConfig.create(scenario="khepera", obstacles=tmp_path / "broken.json")


@needs("train", "yaml")
def test_obstacle_files_yaml(tmp_path: Path) -> None:
    (tmp_path / "room.yaml").write_text(
        "obstacles:\n  - [[0.4, 0.3], [0.6, 0.3], [0.6, 0.45], [0.4, 0.45]]\n"
        "  - name: crate\n    vertices: [[0.8, 0.5], [0.9, 0.5], [0.85, 0.6]]\n"
    )
    from_yaml = EnvConfig.create(scenario="khepera", obstacles=tmp_path / "room.yaml")
    assert from_yaml == EnvConfig.create(scenario="khepera", obstacles=[BOX, CRATE])
    (tmp_path / "broken.yml").write_text("obstacles: [[[0, 0]")
    with pytest.raises(ValueError, match="not valid YAML"):
        EnvConfig.create(scenario="khepera", obstacles=tmp_path / "broken.yml")


def test_random_obstacles_are_seeded_and_apart() -> None:
    first = EnvConfig.create(scenario="random", obstacles={"random": 5, "seed": 7}).obstacles
    again = EnvConfig.create(scenario="random", obstacles={"random": 5, "seed": 7}).obstacles
    other = random_obstacles(np.random.default_rng(8), 1.05, 0.68, 5)
    assert first == again and first != other and 1 <= len(first) <= 5


@pytest.mark.parametrize("scenario", ["furnished_room", "l_corridor"])
def test_scenarios_keep_landmarks_and_starts_out_of_the_obstacles(scenario: str) -> None:
    config = EnvConfig.create(scenario=scenario)
    assert config.obstacles == SCENARIOS[scenario].obstacles and config.obstacles
    vertices, starts = config.layout.packed_obstacles
    env = gym.make("BearingSLAM-v1", scenario=scenario)
    margin = config.arena.wall_margin
    for seed in range(30):
        env.reset(seed=seed)
        world = env.unwrapped.world  # type: ignore[attr-defined]
        assert clearance(*world.position, vertices, starts) >= 2 * margin
        for landmark in world.landmarks:
            assert clearance(*landmark, vertices, starts) > 0.0
    env.close()


def test_random_layouts_avoid_random_obstacles() -> None:
    settings: dict[str, Any] = {"n_landmarks": 8, "obstacles": {"random": 6, "seed": 1}}
    vertices, starts = EnvConfig.create(scenario="random", **settings).layout.packed_obstacles
    env = gym.make("BearingSLAM-v1", scenario="random", **settings)
    for seed in range(20):
        env.reset(seed=seed)
        for landmark in env.unwrapped.world.landmarks:  # type: ignore[attr-defined]
            assert clearance(*landmark, vertices, starts) > 0.0
    env.close()


def test_a_move_into_an_obstacle_is_blocked_and_the_info_says_so() -> None:
    env = gym.make("BearingSLAM-v1", scenario="l_corridor", sensor_info=True)
    vertices, starts = env.unwrapped.config.layout.packed_obstacles  # type: ignore[attr-defined]
    margin = env.unwrapped.config.arena.wall_margin  # type: ignore[attr-defined]
    blocked = 0
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(300):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        position = env.unwrapped.world.position  # type: ignore[attr-defined]
        # Never inside the block, never closer than the margin (up to rounding).
        assert clearance(*position, vertices, starts) >= margin - 1e-9
        blocked += bool(info["blocked"])
        assert info["blocked"] == (env.unwrapped._state.blocked[0])  # type: ignore[attr-defined]
        if terminated or truncated:
            env.reset()
    assert blocked > 10
    env.close()


def test_missed_readings_are_the_ones_out_of_view_range_or_sight() -> None:
    """With a 90 deg camera, a range and the furnished room, a reading misses exactly the
    landmarks the geometry hides (no noise misses: detection_rate 1)."""
    from bearing_env.sensing import visible

    env = gym.make(
        "BearingSLAM-v1",
        scenario="furnished_room",
        field_of_view_deg=90,
        max_range=1.2,
        sensor_info=True,
    )
    config = env.unwrapped.config  # type: ignore[attr-defined]
    vertices, starts = config.layout.packed_obstacles
    _, info = env.reset(seed=0)
    env.action_space.seed(0)
    counts = np.zeros(2, dtype=int)
    for _ in range(100):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        world = env.unwrapped.world  # type: ignore[attr-defined]
        expected = [
            visible(*world.position, world.heading, *landmark, config.sensor.half_fov,
                    1.2, vertices, starts)
            for landmark in world.landmarks
        ]  # fmt: skip
        assert list(info["seen"]) == expected
        counts += np.bincount(np.asarray(expected, dtype=int), minlength=2)
        if terminated or truncated:
            _, info = env.reset()
    assert counts.min() > 20  # both seen and missed landmarks were checked
    env.close()


def test_the_defaults_keep_the_panoramic_sensor_and_the_infos() -> None:
    config = EnvConfig.create()
    assert config.field_of_view_deg == 360.0 and config.max_range == math.inf
    assert config.obstacles == () and not config.sensor_info
    env = gym.make("BearingSLAM-v1")
    _, info = env.reset(seed=0)
    assert "seen" not in info and "blocked" not in info
    env.close()


@pytest.mark.parametrize(
    "task_id",
    ["BearingSLAM-Khepera-Camera90-v1", "BearingSLAM-Khepera-Camera180-v1",
     "BearingSLAM-FurnishedRoom-v1"],
)  # fmt: skip
def test_the_vector_env_is_bit_exact_on_the_new_tasks(task_id: str) -> None:
    pair = make_pair(task_id, 3, gym.vector.AutoresetMode.NEXT_STEP, sensor_info=True)
    assert_pair_agrees(*pair, seed=21, steps=45, action_seed=4)


@needs("render")
def test_the_frame_shows_the_obstacles_the_field_of_view_and_the_missed_landmarks() -> None:
    from bearing_env.rendering import MISSED, OBSTACLE, FieldLayout

    env = gym.make("BearingSLAM-v1", scenario="furnished_room", field_of_view_deg=90,
                   render_mode="rgb_array")  # fmt: skip
    env.reset(seed=2)
    env.action_space.seed(2)
    world = env.unwrapped.world  # type: ignore[attr-defined]
    for _ in range(20):  # until a reading has seen some landmarks and missed others
        env.step(env.action_space.sample())
        missed = np.isnan(env.unwrapped._state.latest_bearings[0, : world.n_landmarks])  # type: ignore[attr-defined]
        if missed.any() and not missed.all():
            break
    assert missed.any() and not missed.all()
    frame = env.render()
    assert frame is not None
    layout = FieldLayout.for_arena(env.unwrapped.config.arena)  # type: ignore[attr-defined]
    x, y = layout.to_pixels(np.array([1.0, 0.7])).astype(int)  # the table's centre
    assert tuple(frame[y, x]) == OBSTACLE
    for landmark, is_missed in zip(world.landmarks, missed, strict=True):
        px, py = layout.to_pixels(landmark).astype(int)
        assert (tuple(frame[py, px]) == MISSED) == is_missed
    panoramic = gym.make("BearingSLAM-v1", scenario="furnished_room", render_mode="rgb_array")
    panoramic.reset(seed=2)
    # The yellow wedge tints the field ahead of the camera only with a limited one.
    assert not np.array_equal(frame, panoramic.render())
    env.close()
    panoramic.close()
