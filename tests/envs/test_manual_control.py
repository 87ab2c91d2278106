"""Manual control (``bearing-env play``) under the dummy video driver: synthetic pygame
events posted to the queue move, turn and reset the env, and quit the loop."""

from __future__ import annotations

import math
import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

from collections.abc import Iterator
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs.manual_control import (
    AIM,
    KEY_HELP,
    LENGTH_STEPS,
    PANEL_HEIGHT,
    TURN_STEP_DEG,
    ChangeLength,
    ManualControl,
    Move,
    MoveToward,
    Quit,
    Reset,
    Turn,
    command_for,
    next_length,
    next_turn,
)
from bearing_env.numerics import wrap
from tests.extras import skip_module_without

skip_module_without("render")

DOCS = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "play.md")


@pytest.fixture(scope="module")
def pygame() -> Any:
    import pygame

    return pygame


def make_control(env_id: str = "BearingSLAM-v1", seed: int = 0, **settings: Any) -> ManualControl:
    settings.setdefault("scenario", "khepera")
    env = gym.make(env_id, render_mode="rgb_array", **settings)
    return ManualControl(env, seed=seed)


@pytest.fixture
def control() -> Iterator[ManualControl]:
    with make_control() as made:
        yield made


def key(pygame: Any, name: str) -> Any:
    return pygame.event.Event(pygame.KEYDOWN, key=getattr(pygame, name), mod=0, unicode="")


def click(pygame: Any, pixel: tuple[int, int], button: int = 1) -> Any:
    return pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=pixel, button=button)


def play(pygame: Any, control: ManualControl, events: list[Any]) -> None:
    """Post ``events`` and a QUIT, and run the loop until it ends."""
    pygame.event.clear()
    for event in [*events, pygame.event.Event(pygame.QUIT)]:
        pygame.event.post(event)
    control.run()
    assert not control.running


def pixel_of(control: ManualControl, point: np.ndarray) -> tuple[int, int]:
    x, y = np.rint(control.layout.to_pixels(point)).astype(int)
    return int(x), int(y)


# -- events -> commands (pure) ------------------------------------------------------------


def test_events_map_to_commands(pygame: Any) -> None:
    assert command_for(key(pygame, "K_LEFT")) == Turn(+1)
    assert command_for(key(pygame, "K_RIGHT")) == Turn(-1)
    assert command_for(key(pygame, "K_UP")) == ChangeLength(+1)
    assert command_for(key(pygame, "K_DOWN")) == ChangeLength(-1)
    for name in ("K_SPACE", "K_RETURN", "K_KP_ENTER"):
        assert command_for(key(pygame, name)) == Move()
    assert command_for(key(pygame, "K_r")) == Reset()
    assert command_for(key(pygame, "K_ESCAPE")) == Quit()
    assert command_for(pygame.event.Event(pygame.QUIT)) == Quit()
    assert command_for(click(pygame, (120, 80))) == MoveToward((120, 80))
    # Other keys, other buttons and other events ask for nothing.
    assert command_for(key(pygame, "K_x")) is None
    assert command_for(click(pygame, (120, 80), button=3)) is None
    assert command_for(pygame.event.Event(pygame.MOUSEMOTION, pos=(1, 2), rel=(0, 0))) is None


def test_table_steps_wrap_turns_and_stop_lengths_at_the_ends() -> None:
    turns = np.radians([0.0, 90.0, -180.0, -90.0])
    assert next_turn(turns, 0.0, +1) == pytest.approx(math.pi / 2)
    assert next_turn(turns, 0.0, -1) == pytest.approx(-math.pi / 2)
    assert next_turn(turns, -math.pi / 2, +1) == pytest.approx(0.0)
    assert next_turn(turns, 0.3, -1) == pytest.approx(0.0)  # off the table: the next one
    assert next_turn(np.array([0.0]), 0.0, +1) == 0.0  # one turn: stays
    lengths = np.array([0.1, 0.2, 0.3])
    assert next_length(lengths, 0.2, +1) == pytest.approx(0.3)
    assert next_length(lengths, 0.3, +1) == pytest.approx(0.3)
    assert next_length(lengths, 0.1, -1) == pytest.approx(0.1)
    assert next_length(lengths, 0.25, -1) == pytest.approx(0.2)


# -- the loop over posted events ----------------------------------------------------------


def test_keys_turn_lengthen_and_move(pygame: Any, control: ManualControl) -> None:
    env = control.env.unwrapped
    lo, hi = env.move_length
    heading, position = env.world.heading, env.world.position.copy()
    start_length = control.aim.length
    events = [key(pygame, "K_LEFT"), key(pygame, "K_LEFT"), key(pygame, "K_RIGHT")]
    events += [key(pygame, "K_UP"), key(pygame, "K_UP"), key(pygame, "K_DOWN")]
    play(pygame, control, events)
    assert control.moves == 0  # aiming does not move
    assert control.aim.turn == pytest.approx(math.radians(TURN_STEP_DEG), abs=1e-6)
    assert control.aim.length == pytest.approx(start_length + (hi - lo) / LENGTH_STEPS, abs=1e-6)
    wanted = control.aim

    control.running = True
    play(pygame, control, [key(pygame, "K_SPACE")])
    assert control.moves == 1
    assert env.world.heading == pytest.approx(wrap(heading + wanted.turn), abs=1e-6)
    moved = env.world.position - position
    assert np.hypot(*moved) == pytest.approx(min(wanted.length, control.info["path_length"]))
    assert np.hypot(*moved) == pytest.approx(wanted.length, abs=1e-6)  # no wall on this seed
    assert control.episode_return == pytest.approx(control.last_reward)
    assert control.aim.turn == 0.0 and control.aim.length == pytest.approx(wanted.length)


def test_lengths_stay_within_the_move_length_range(pygame: Any, control: ManualControl) -> None:
    lo, hi = control.env.unwrapped.move_length
    play(pygame, control, [key(pygame, "K_UP")] * (LENGTH_STEPS + 3))
    assert control.aim.length == pytest.approx(hi, abs=1e-6)
    control.running = True
    play(pygame, control, [key(pygame, "K_DOWN")] * (2 * LENGTH_STEPS + 3))
    assert control.aim.length == pytest.approx(lo, abs=1e-6)


def test_a_click_moves_the_robot_to_the_point(pygame: Any, control: ManualControl) -> None:
    env = control.env.unwrapped
    lo, hi = env.move_length
    position = env.world.position.copy()
    centre = 0.5 * np.array([env.arena.width, env.arena.height])
    toward = (centre - position) / np.hypot(*(centre - position))
    target = position + 0.6 * (lo + hi) * toward
    pixel = pixel_of(control, target)
    play(pygame, control, [click(pygame, pixel)])
    assert control.moves == 1
    # One pixel is 1/pixels_per_metre metres: the robot ends on the clicked pixel.
    reached = control.layout.to_world(pixel)
    assert np.hypot(*(env.world.position - reached)) < 1e-4


def test_a_far_click_moves_the_longest_allowed_length_toward_it(
    pygame: Any, control: ManualControl
) -> None:
    env = control.env.unwrapped
    _, hi = env.move_length
    position = env.world.position.copy()
    far = np.array([env.arena.width, env.arena.height]) - position  # the far corner side
    target = position + 0.9 * far
    assert np.hypot(*(target - position)) > hi
    play(pygame, control, [click(pygame, pixel_of(control, target))])
    moved = env.world.position - position
    assert np.hypot(*moved) == pytest.approx(hi, abs=1e-6)
    aim = control.layout.to_world(pixel_of(control, target)) - position
    cosine = np.dot(moved, aim) / (np.hypot(*moved) * np.hypot(*aim))
    assert cosine == pytest.approx(1.0, abs=1e-9)


def test_clicks_off_the_field_do_nothing(pygame: Any, control: ManualControl) -> None:
    position = control.env.unwrapped.world.position.copy()
    below_field = (20, control.layout.size[1] + PANEL_HEIGHT // 2)
    play(pygame, control, [click(pygame, (2, 2)), click(pygame, below_field)])
    assert control.moves == 0
    np.testing.assert_array_equal(control.env.unwrapped.world.position, position)


def test_r_starts_the_next_episode_with_the_next_seed(pygame: Any, control: ManualControl) -> None:
    play(pygame, control, [key(pygame, "K_SPACE"), key(pygame, "K_RETURN"), key(pygame, "K_r")])
    assert control.moves == 0 and control.episode == 1 and control.episode_return == 0.0
    fresh = gym.make("BearingSLAM-v1", scenario="khepera")
    fresh.reset(seed=1)
    world = control.env.unwrapped.world
    np.testing.assert_array_equal(world.position, fresh.unwrapped.world.position)
    assert world.heading == fresh.unwrapped.world.heading


def test_escape_and_window_close_end_the_loop(pygame: Any, control: ManualControl) -> None:
    pygame.event.clear()
    pygame.event.post(key(pygame, "K_ESCAPE"))
    pygame.event.post(key(pygame, "K_SPACE"))  # after the quit: handled, the loop ends anyway
    control.run()
    assert not control.running
    control.running = True
    pygame.event.clear()
    pygame.event.post(pygame.event.Event(pygame.QUIT))
    control.run()
    assert not control.running


def test_an_ended_episode_takes_no_more_moves(pygame: Any) -> None:
    with make_control(max_moves=2) as control:
        play(pygame, control, [key(pygame, "K_SPACE")] * 3)
        assert control.moves == 2 and control.done
        assert "press r" in control.status


def test_the_discrete_env_steps_through_its_tables(pygame: Any) -> None:
    with make_control("BearingSLAMDiscrete-v1", n_turns=8, n_move_lengths=3) as control:
        env = control.env.unwrapped
        heading = env.world.heading
        start = control.aim
        assert start.length == pytest.approx(env.move_lengths[1])  # the middle length
        play(pygame, control, [key(pygame, "K_RIGHT"), key(pygame, "K_UP")])
        assert control.aim.turn == pytest.approx(math.radians(-45.0))
        assert control.aim.length == pytest.approx(env.move_lengths[2])
        control.running = True
        play(pygame, control, [key(pygame, "K_SPACE")])
        assert control.moves == 1
        assert env.world.heading == pytest.approx(wrap(heading - math.pi / 4), abs=1e-9)
        # A click takes the grid's nearest move: a turn and a length of the tables.
        control.running = True
        position = env.world.position.copy()
        centre = 0.5 * np.array([env.arena.width, env.arena.height])
        play(pygame, control, [click(pygame, pixel_of(control, centre))])
        assert control.moves == 2
        assert np.min(np.abs(env.move_lengths - np.hypot(*(env.world.position - position)))) < 1e-9


# -- the window -----------------------------------------------------------------------------


def test_the_window_shows_the_frame_the_aim_and_the_panel(
    pygame: Any, control: ManualControl
) -> None:
    play(pygame, control, [key(pygame, "K_LEFT"), key(pygame, "K_SPACE"), key(pygame, "K_UP")])
    control.draw()
    width, height = control.layout.size
    assert control.window.get_size() == (width, height + PANEL_HEIGHT)
    window = np.transpose(pygame.surfarray.array3d(control.window), (1, 0, 2))
    frame = control.env.render()
    # The field is the env's own frame, except for the dashed aim from the robot.
    differs = np.any(window[:height] != frame, axis=-1)
    assert 0 < differs.mean() < 0.01
    assert np.all(window[:height][differs] == AIM)
    start = np.rint(control.layout.to_pixels(control.env.unwrapped.world.position)).astype(int)
    rows, cols = np.nonzero(differs)
    assert np.min(np.hypot(cols - start[0], rows - start[1])) < 15  # it starts at the robot
    # The panel has text in it.
    assert len(np.unique(window[height:].reshape(-1, 3), axis=0)) > 10


def test_the_panel_reports_areas_reward_return_and_moves_left(
    pygame: Any, control: ManualControl
) -> None:
    play(pygame, control, [key(pygame, "K_SPACE"), key(pygame, "K_SPACE")])
    status, aim, areas, keys = ([text for text, _ in row] for row in control.panel_rows())
    max_moves = control.env.unwrapped.max_moves
    assert f"moves left {max_moves - 2}/{max_moves}" in status
    assert f"last reward {control.last_reward:+.3f}" in status
    assert f"return {control.episode_return:+.3f}" in status
    landmark_areas = control.info["landmark_area"]
    assert len(areas) == 1 + len(landmark_areas)
    for offset, area in enumerate(landmark_areas):
        shown = f"{area:.4f}" if math.isfinite(area) else "not initialised"
        assert areas[1 + offset] == f"L{offset + 3} {shown}"
    assert "next move" in aim[0] and aim[1] == control.status
    assert keys == [f"{keys}: {what}" for keys, what in KEY_HELP]


def test_the_docs_list_every_key() -> None:
    with open(DOCS, encoding="utf-8") as page:
        text = page.read()
    for keys, _ in KEY_HELP:
        assert f"| {keys} |" in text, keys


def test_a_window_needs_an_rgb_array_bearing_env() -> None:
    with pytest.raises(ValueError, match="render_mode='rgb_array'"):
        ManualControl(gym.make("BearingSLAM-v1"))
    with pytest.raises(TypeError, match="CartPoleEnv"):
        ManualControl(gym.make("CartPole-v1", render_mode="rgb_array"))
