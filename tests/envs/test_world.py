"""World and sensor simulation: arena, motion, bearings, noise, layouts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_env.world import (
    KHEPERA_ARENA_SIZE,
    SCENARIOS,
    Arena,
    NoiseModel,
    World,
    random_layout,
    random_start,
    wrap_angle,
)

KHEPERA = Arena(*KHEPERA_ARENA_SIZE)


def make_world(
    position: tuple[float, float] = (0.5, 0.3),
    heading: float = 0.0,
    noise: NoiseModel | None = None,
    epsilon: float = math.radians(2.0),
) -> World:
    landmarks = np.array(SCENARIOS["khepera"].landmarks)
    return World(KHEPERA, landmarks, position, heading, noise or NoiseModel(), epsilon)


@pytest.mark.parametrize(
    ("width", "height", "error"),
    [
        (0.0, 1.0, ValueError),
        (-1.0, 1.0, ValueError),
        (1.0, math.nan, ValueError),
        (1.0, math.inf, ValueError),
        (True, 1.0, TypeError),
        ("1", 1.0, TypeError),
    ],
)
def test_arena_rejects_bad_sizes(width: object, height: object, error: type) -> None:
    with pytest.raises(error, match="arena"):
        Arena(width, height)  # type: ignore[arg-type]


def test_khepera_scenario_matches_the_paper() -> None:
    scenario = SCENARIOS["khepera"]
    assert scenario.arena_size == (1.05, 0.68)
    assert scenario.n_landmarks == 4
    landmarks = np.array(scenario.landmarks)
    assert np.hypot(*(landmarks[1] - landmarks[0])) == pytest.approx(0.20)
    assert np.all(Arena(*scenario.arena_size).contains(landmarks))


def test_paper_sim_has_four_landmarks_around_the_centre() -> None:
    scenario = SCENARIOS["paper_sim"]
    landmarks = np.array(scenario.landmarks)
    centre = np.array(scenario.arena_size) / 2
    assert landmarks.shape == (4, 2)
    # Around the centre: the landmarks' angles about the centre cover all four quadrants.
    angles = np.arctan2(*(landmarks - centre).T[::-1])
    assert len(set(np.floor(angles / (np.pi / 2)).astype(int).tolist())) == 4


def test_wrap_angle_range() -> None:
    angles = np.linspace(-20, 20, 1001)
    wrapped = wrap_angle(angles)
    assert np.all(wrapped >= -np.pi) and np.all(wrapped < np.pi)
    np.testing.assert_allclose(np.cos(wrapped), np.cos(angles), atol=1e-12)
    np.testing.assert_allclose(np.sin(wrapped), np.sin(angles), atol=1e-12)


def test_free_distance_to_each_wall() -> None:
    arena = Arena(2.0, 1.0)
    assert arena.free_distance((0.5, 0.5), 0.0, 0.1) == pytest.approx(1.4)
    assert arena.free_distance((0.5, 0.5), math.pi, 0.1) == pytest.approx(0.4)
    assert arena.free_distance((0.5, 0.5), math.pi / 2, 0.1) == pytest.approx(0.4)
    assert arena.free_distance((0.5, 0.5), -math.pi / 2, 0.1) == pytest.approx(0.4)
    # Diagonal: the y wall (0.4 away) is hit first, after 0.4 * sqrt(2).
    assert arena.free_distance((0.5, 0.5), math.pi / 4, 0.1) == pytest.approx(0.4 * math.sqrt(2))
    # At the margin, facing the wall: cannot move.
    assert arena.free_distance((1.9, 0.5), 0.0, 0.1) == 0.0


def test_move_stops_at_the_wall_margin() -> None:
    world = make_world(position=(0.5, 0.3), heading=0.0)
    result = world.move(10.0)
    margin = KHEPERA.wall_margin
    assert result.blocked
    assert result.travelled == pytest.approx(1.05 - margin - 0.5)
    assert world.position[0] == pytest.approx(1.05 - margin)
    assert world.position[1] == pytest.approx(0.3)
    # Facing the wall now: a second move goes nowhere.
    again = world.move(0.1)
    assert again.blocked and again.travelled == 0.0


def test_move_short_of_the_wall_is_exact() -> None:
    world = make_world(position=(0.5, 0.3), heading=math.pi / 2)
    result = world.move(0.1)
    assert not result.blocked
    assert result.travelled == 0.1
    np.testing.assert_allclose(world.position, [0.5, 0.4])


def test_random_moves_never_leave_the_arena() -> None:
    rng = np.random.default_rng(0)
    world = make_world()
    for _ in range(500):
        world.turn(rng.uniform(-np.pi, np.pi))
        world.move(rng.uniform(0.0, 2.0))
        assert KHEPERA.contains(world.position, KHEPERA.wall_margin - 1e-12)


def test_true_bearings_are_ccw_from_the_heading() -> None:
    arena = Arena(2.0, 2.0)
    landmarks = np.array([[1.5, 1.0], [1.0, 1.5], [0.5, 1.0], [1.0, 0.5]])
    world = World(arena, landmarks, (1.0, 1.0), 0.0, NoiseModel("none"), 0.01)
    np.testing.assert_allclose(
        world.true_bearings(), [0.0, np.pi / 2, -np.pi, -np.pi / 2], atol=1e-12
    )
    world.turn(np.pi / 2)
    np.testing.assert_allclose(world.true_bearings(), [-np.pi / 2, 0.0, np.pi / 2, -np.pi])


def test_noiseless_reading_is_exact() -> None:
    world = make_world(noise=NoiseModel("none"))
    np.testing.assert_array_equal(
        world.read_bearings(np.random.default_rng(0)), world.true_bearings()
    )


@pytest.mark.parametrize("bound_deg", [None, 1.0, 5.0])
def test_uniform_noise_stays_within_its_bound(bound_deg: float | None) -> None:
    epsilon = math.radians(2.0)
    noise = NoiseModel("uniform", bound_deg=bound_deg)
    bound = epsilon if bound_deg is None else math.radians(bound_deg)
    truth = np.zeros(20_000)
    errors = noise.corrupt(np.random.default_rng(1), truth, epsilon)
    assert np.max(np.abs(errors)) <= bound
    # It spreads over the whole bound, not a fraction of it.
    assert np.max(np.abs(errors)) > 0.99 * bound


def test_gaussian_noise_has_the_requested_sigma() -> None:
    noise = NoiseModel("gaussian", sigma_deg=1.5)
    errors = noise.corrupt(np.random.default_rng(2), np.zeros(50_000), math.radians(2.0))
    assert np.std(errors) == pytest.approx(math.radians(1.5), rel=0.03)
    default = NoiseModel("gaussian").corrupt(
        np.random.default_rng(2), np.zeros(50_000), math.radians(2.0)
    )
    assert np.std(default) == pytest.approx(math.radians(1.0), rel=0.03)


def test_outliers_occur_at_the_requested_rate() -> None:
    epsilon = math.radians(2.0)
    noise = NoiseModel("uniform", outlier_rate=0.2)
    errors = noise.corrupt(np.random.default_rng(3), np.zeros(50_000), epsilon)
    outside = np.abs(errors) > epsilon
    # An outlier is uniform on the circle, so it lands inside +-epsilon with prob eps/pi.
    expected = 0.2 * (1 - epsilon / np.pi)
    assert np.mean(outside) == pytest.approx(expected, rel=0.05)
    assert np.all(errors >= -np.pi) and np.all(errors < np.pi)


def test_noise_is_deterministic_given_the_generator() -> None:
    noise = NoiseModel("gaussian", outlier_rate=0.1)
    truth = np.linspace(-3, 3, 7)
    a = noise.corrupt(np.random.default_rng(7), truth, 0.03)
    b = noise.corrupt(np.random.default_rng(7), truth, 0.03)
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    ("spec", "error", "fragment"),
    [
        ("laplace", ValueError, "laplace"),
        ({"kind": "uniform", "bound_deg": -1.0}, ValueError, "-1.0"),
        ({"kind": "uniform", "outlier_rate": 1.5}, ValueError, "1.5"),
        ({"kind": "uniform", "sigma": 1.0}, TypeError, "sigma"),
        ({"kind": "gaussian", "sigma_deg": "big"}, TypeError, "big"),
        (3.0, TypeError, "3.0"),
    ],
)
def test_noise_parse_rejects_bad_specs(spec: object, error: type, fragment: str) -> None:
    with pytest.raises(error, match=fragment):
        NoiseModel.parse(spec)  # type: ignore[arg-type]


def test_noise_parse_accepts_all_forms() -> None:
    assert NoiseModel.parse(None) == NoiseModel("uniform")
    assert NoiseModel.parse("gaussian") == NoiseModel("gaussian")
    model = NoiseModel("uniform", bound_deg=3, outlier_rate=0.05)
    assert NoiseModel.parse(model) is model
    assert NoiseModel.parse({"kind": "uniform", "bound_deg": 3, "outlier_rate": 0.05}) == model


@pytest.mark.parametrize("n_landmarks", [3, 4, 8, 16, 64])
def test_random_layout_is_valid(n_landmarks: int) -> None:
    for seed in range(5):
        points = random_layout(np.random.default_rng(seed), KHEPERA, n_landmarks)
        assert points.shape == (n_landmarks, 2)
        assert np.all(KHEPERA.contains(points))
        separation = np.hypot(*(points[:, None] - points[None]).transpose(2, 0, 1))
        np.fill_diagonal(separation, np.inf)
        assert separation.min() > 0.01
        # The frame L1-L2 is well defined: not shorter than a quarter of the short side.
        assert separation[0, 1] >= 0.25 * min(KHEPERA.width, KHEPERA.height) * 0.8**3


def test_random_layout_and_start_are_deterministic() -> None:
    a = random_layout(np.random.default_rng(11), KHEPERA, 6)
    b = random_layout(np.random.default_rng(11), KHEPERA, 6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, random_layout(np.random.default_rng(12), KHEPERA, 6))
    pose_a = random_start(np.random.default_rng(5), KHEPERA, a)
    pose_b = random_start(np.random.default_rng(5), KHEPERA, a)
    np.testing.assert_array_equal(pose_a[0], pose_b[0])
    assert pose_a[1] == pose_b[1]


def test_random_start_is_inside_the_margin_and_clear_of_landmarks() -> None:
    landmarks = np.array(SCENARIOS["khepera"].landmarks)
    for seed in range(50):
        position, heading = random_start(np.random.default_rng(seed), KHEPERA, landmarks)
        assert KHEPERA.contains(position, KHEPERA.wall_margin)
        assert np.min(np.hypot(*(landmarks - position).T)) >= 0.04
        assert -np.pi <= heading < np.pi


def test_default_lengths_scale_with_the_arena() -> None:
    assert KHEPERA.default_move_length == pytest.approx((0.05, 0.30))
    big = Arena(2.1, 2.1)
    assert big.default_move_length == pytest.approx((0.10, 0.60))
    assert big.wall_margin == pytest.approx(2 * KHEPERA.wall_margin)


@pytest.mark.parametrize(
    "noise",
    [
        {"kind": "uniform"},
        {"kind": "gaussian", "sigma_deg": 1.0},
        {"kind": "uniform", "outlier_rate": 0.3},
        {"kind": "none"},
    ],
)
def test_a_block_of_readings_draws_as_the_readings_one_at_a_time(noise):
    # The envs draw a block of an episode's readings at once (into their noise buffer):
    # the block must be the very draws, in order, of that many single readings.
    model = NoiseModel.parse({**noise, "detection_rate": 0.8} if noise["kind"] == "none" else noise)
    rng, again = np.random.default_rng(7), np.random.default_rng(7)
    readings, size = 4, 5
    offsets = np.full((readings, size), -1.0)
    is_outlier = np.ones((readings, size), dtype=bool)
    replacement = np.zeros((readings, size))
    model.draw_readings(rng, 0.03, offsets, is_outlier, replacement)
    for k in range(readings):
        want = model.draw_rows([again], size, 0.03)
        np.testing.assert_array_equal(offsets[k], want.offsets[0])
        if want.is_outlier is None:
            assert not is_outlier[k].any()
        else:
            np.testing.assert_array_equal(is_outlier[k], want.is_outlier[0])
            chosen = want.is_outlier[0]
            np.testing.assert_array_equal(replacement[k][chosen], want.replacement[0][chosen])
    # And the generators end in the same state.
    assert rng.random() == again.random()


def test_a_world_copy_keeps_the_camera_and_the_obstacles() -> None:
    """A copy of a row's ground truth moves and reads as the env does: its moves stop at
    the furniture and its readings miss what the camera cannot see."""
    import gymnasium as gym

    from bearing_env.agents.base import ActionCodec
    from bearing_env.agents.env_access import world_of

    env = gym.make(
        "bearing_env:BearingSLAM-FurnishedRoom-v1", field_of_view_deg=90, sensor_info=True
    )
    codec = ActionCodec(env)
    rng = np.random.default_rng(0)
    stopped = missed = 0
    for seed in range(5):
        env.reset(seed=seed)
        for turn in (0.0, 2.0, -1.0):
            copy = world_of(env).copy()
            assert copy.obstacles and copy.half_fov == pytest.approx(np.pi / 4)
            copy.turn(turn)
            moved = copy.move(codec.max_length)
            _, _, _, _, info = env.step(codec.movement(turn, codec.max_length).action)
            np.testing.assert_allclose(copy.position, world_of(env).position, atol=1e-12)
            assert moved.blocked == info["blocked"]
            seen = ~np.isnan(copy.read_bearings(rng))
            np.testing.assert_array_equal(seen, info["seen"])
            stopped += moved.blocked
            missed += (~seen).sum()
    assert stopped > 0 and missed > 0
    env.close()
