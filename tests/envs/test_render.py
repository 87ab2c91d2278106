# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""Rendering: headless rgb_array frames, the human window, RecordVideo."""

from __future__ import annotations

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest

from tests.extras import skip_module_without

skip_module_without("render")

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs import BearingSLAMEnv
from bearing_env.rendering import FIELD, Renderer, landmark_colour

ENV_IDS = ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"]


def frame_after(env: gym.Env, moves: int, seed: int = 0) -> np.ndarray:
    env.action_space.seed(seed)
    env.reset(seed=seed)
    for _ in range(moves):
        env.step(env.action_space.sample())
    return env.render()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_array_frame_has_the_right_shape_and_content(env_id: str) -> None:
    env = gym.make(env_id, scenario="khepera", render_mode="rgb_array")
    frame = frame_after(env, moves=6)
    renderer = env.unwrapped._renderer
    width, height = renderer.size
    assert frame.shape == (height, width, 3) and frame.dtype == np.uint8
    # The Khepera field is 1.05 x 0.68: the frame is wider than tall.
    assert width > height
    # Not blank: many colours, and the field, the landmark colours and the robot appear.
    colours = np.unique(frame.reshape(-1, 3), axis=0)
    assert len(colours) > 100
    assert frame.std() > 20
    pixels = {tuple(c) for c in colours.tolist()}
    assert FIELD in pixels
    for index in range(4):
        assert landmark_colour(index) in pixels, f"landmark L{index + 1} not drawn"
    env.close()


def test_frames_change_as_the_robot_moves() -> None:
    env = gym.make("BearingSLAM-v1", render_mode="rgb_array")
    env.reset(seed=1)
    first = env.render()
    env.step(np.array([0.3, 0.5], dtype=np.float32))
    second = env.render()
    assert first.shape == second.shape
    assert np.mean(np.any(first != second, axis=-1)) > 0.01
    env.close()


def test_frame_size_is_constant_over_episodes_and_layouts() -> None:
    # RecordVideo and GIF writers need one frame size per env.
    env = gym.make("BearingSLAM-v1", n_landmarks=12, render_mode="rgb_array")
    shapes = {frame_after(env, moves=moves, seed=seed).shape for seed, moves in [(0, 0), (1, 9)]}
    assert len(shapes) == 1
    env.close()


def test_huge_regions_and_many_landmarks_render() -> None:
    # A large epsilon gives regions far bigger than the arena; they are clipped, not lost.
    env = BearingSLAMEnv(n_landmarks=16, epsilon_deg=25.0, render_mode="rgb_array")
    frame = frame_after(env, moves=4)
    assert frame.shape[2] == 3 and frame.std() > 10
    env.close()


def test_human_mode_draws_a_window_and_returns_none() -> None:
    env = gym.make("BearingSLAM-v1", render_mode="human")
    env.action_space.seed(0)
    env.reset(seed=0)  # human mode renders on reset and step
    env.step(env.action_space.sample())
    assert env.render() is None
    renderer = env.unwrapped._renderer
    assert renderer is not None and renderer._window is not None
    env.close()
    env.close()  # closing twice is allowed
    assert env.unwrapped._renderer is None


def test_render_without_mode_warns_and_returns_none() -> None:
    env = BearingSLAMEnv()
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None


def test_renderer_world_to_pixel_mapping() -> None:
    renderer = Renderer("rgb_array", BearingSLAMEnv(scenario="khepera").arena, fps=4)
    rect = renderer.field_rect
    np.testing.assert_allclose(renderer.to_pixels(np.array([0.0, 0.0])), [rect.left, rect.bottom])
    np.testing.assert_allclose(
        renderer.to_pixels(np.array([1.05, 0.68])), [rect.right, rect.top], atol=1.0
    )


def test_record_video(tmp_path: os.PathLike[str]) -> None:
    # moviepy is in the dev extra, so this runs wherever the tests do.
    from gymnasium.wrappers import RecordVideo

    env = gym.make("BearingSLAM-v1", scenario="khepera", render_mode="rgb_array")
    folder = os.path.join(tmp_path, "videos")
    env = RecordVideo(env, folder, episode_trigger=lambda episode: episode == 0)
    env.action_space.seed(0)
    env.reset(seed=0)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        done = terminated or truncated
    env.close()
    videos = [name for name in os.listdir(folder) if name.endswith(".mp4")]
    assert videos
    assert all(os.path.getsize(os.path.join(folder, name)) > 1000 for name in videos)


def test_the_field_layout_maps_pixels_back_to_the_world() -> None:
    from bearing_env.rendering import FieldLayout

    env = gym.make("BearingSLAM-v1", scenario="khepera", render_mode="rgb_array")
    env.reset(seed=0)
    env.render()
    renderer = env.unwrapped._renderer
    layout = FieldLayout.for_arena(env.unwrapped.arena)
    assert layout == renderer.layout and layout.size == renderer.size
    corners = np.array([[0.0, 0.0], [1.05, 0.68]])
    left, top, width, height = layout.field_box
    # The field's height in pixels is rounded: the far corner is within half a pixel.
    expected = [[left, top + height], [left + width, top]]
    np.testing.assert_allclose(layout.to_pixels(corners), expected, atol=0.5)
    points = np.random.default_rng(0).uniform([0, 0], [1.05, 0.68], size=(20, 2))
    np.testing.assert_allclose(layout.to_world(layout.to_pixels(points)), points, atol=1e-12)
    assert layout.in_field((left, top)) and not layout.in_field((left - 1, top))
    env.close()
