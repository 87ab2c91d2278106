"""``make demo``: the paper's random polygonal exploration in the Khepera scenario.

Runs a few episodes of the random polygonal policy (a random rotation on the spot, then a
straight line of fixed length, as the Khepera robot did in the paper), prints the total
uncertainty area and the mean landmark error after every move, and saves an animation
of the first episode to ``outputs/``. The animation needs pygame (the ``render`` extra);
without it the demo runs, prints its tables, and says how to install it.

    python -m bearing_env.train.studies.demo [--episodes 3] [--moves 10] [--seed 0] [--out outputs]
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.extras import MissingExtraError, available
from bearing_env.train.common.cli_parser import command_parser, doc_summary
from bearing_env.train.common.cli_values import COUNT, SEED
from bearing_env.train.common.errors import fail, write_error_message

#: The paper's Khepera run is 10 movements; docs/design.md's reference runs move 25 cm.
DEFAULT_MOVES = 10
MOVE_LENGTH = 0.25
GIF_FRAME_SECONDS = 0.8


def random_polygonal_action(rng: np.random.Generator) -> NDArray[np.float32]:
    """A uniformly random turn; the length is fixed by the env's ``move_length``."""
    return np.array([rng.uniform(-1.0, 1.0), 1.0], dtype=np.float32)


def rendered_frame(env: gym.Env) -> NDArray[np.uint8]:
    """The env's ``rgb_array`` frame (TypeError if it renders no array)."""
    frame = env.render()
    if not isinstance(frame, np.ndarray):
        raise TypeError(f"expected an rgb_array frame from render(), got {type(frame).__name__}")
    return frame


def run_episode(
    env: gym.Env, seed: int, moves: int, record: bool
) -> tuple[list[dict[str, float]], list[NDArray[np.uint8]]]:
    """One episode; returns per-move metrics and (if ``record``) the rendered frames."""
    policy_rng = np.random.default_rng(seed + 10_000)
    _, info = env.reset(seed=seed)
    frames: list[NDArray[np.uint8]] = [rendered_frame(env)] if record else []
    rows: list[dict[str, float]] = []
    for move in range(1, moves + 1):
        _, reward, terminated, truncated, info = env.step(random_polygonal_action(policy_rng))
        errors = info["landmark_error"]
        rows.append(
            {
                "move": move,
                "reward": float(reward),
                "total_area": info["total_area"],
                "max_area": float(np.max(info["landmark_area"])),
                "mean_error": float(np.mean(errors)) if np.all(np.isfinite(errors)) else math.inf,
                "contains": float(np.mean(info["landmark_contains_truth"])),
                "frame_changed": float(info["frame_changed"]),
            }
        )
        if record:
            frames.append(rendered_frame(env))
        if terminated or truncated:
            break
    return rows, frames


def save_animation(frames: list[NDArray[np.uint8]], path: Path) -> Path:
    """Save frames as a GIF with Pillow (bundled with matplotlib); PNGs if it is absent."""
    try:
        from PIL import Image
    except ImportError:
        folder = path.with_suffix("")
        folder.mkdir(parents=True, exist_ok=True)
        import pygame

        for index, frame in enumerate(frames):
            surface = pygame.surfarray.make_surface(np.transpose(frame, (1, 0, 2)))
            pygame.image.save(surface, str(folder / f"frame_{index:03d}.png"))
        return folder
    images = [Image.fromarray(frame) for frame in frames]
    # Hold the last frame longer so the final map can be read.
    durations = [int(GIF_FRAME_SECONDS * 1000)] * (len(images) - 1) + [3000]
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=durations, loop=0, optimize=True
    )
    return path


def main(argv: list[str] | None = None) -> None:
    parser = command_parser("bearing-env demo", doc_summary(__doc__))
    parser.add_argument(
        "--episodes", type=COUNT, default=3, help="episodes to run (default %(default)s)"
    )
    parser.add_argument(
        "--moves", type=COUNT, default=DEFAULT_MOVES, help="moves per episode (default %(default)s)"
    )
    parser.add_argument(
        "--seed", type=SEED, default=0, help="seed of episode 0; episode i: seed + i (default 0)"
    )
    parser.add_argument(
        "--out", type=Path, default=Path("outputs"), help="animation folder (default %(default)s)"
    )
    args = parser.parse_args(argv)
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    rendering = available("pygame")

    env = gym.make(
        "BearingSLAM-v1",
        scenario="khepera",
        move_length=MOVE_LENGTH,
        max_moves=args.moves,
        render_mode="rgb_array" if rendering else None,
    )
    started = time.perf_counter()
    print(
        "Random polygonal exploration, Khepera scenario (1.05 x 0.68 m, 4 landmarks, "
        f"L1-L2 = 20 cm = 1 FL unit, epsilon = 2 deg, moves of {MOVE_LENGTH * 100:g} cm)"
    )
    finals = []
    frames: list[NDArray[np.uint8]] = []
    for episode in range(args.episodes):
        seed = args.seed + episode
        rows, episode_frames = run_episode(
            env, seed, args.moves, record=rendering and episode == 0
        )
        frames = frames or episode_frames
        print(f"\nepisode {episode} (seed {seed})")
        print(" move  total area  max area  mean error  contains  updated  reward")
        for row in rows:
            print(
                f" {row['move']:4d}  {row['total_area']:10.4f}  {row['max_area']:8.4f}  "
                f"{row['mean_error']:10.4f}  {row['contains']:8.0%}  "
                f"{'yes' if row['frame_changed'] else 'no':>7}  {row['reward']:6.3f}"
            )
        finals.append(rows[-1])
    env.close()

    totals = [row["total_area"] for row in finals]
    errors = [row["mean_error"] for row in finals]
    print(
        f"\nafter {args.moves} moves over {args.episodes} episodes: median total area "
        f"{np.median(totals):.4f} FL units^2, median mean error {np.median(errors):.4f} FL "
        f"units ({np.median(errors) * 20:.1f} cm)"
    )
    if not rendering:
        reason = MissingExtraError("pygame", "the animation", extra="render")
        print(f"no animation: {reason}", file=sys.stderr)
        return
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        saved = save_animation(frames, args.out / "demo_khepera.gif")
    except OSError as error:
        fail("bearing-env demo", write_error_message(error, args.out, "--out"))
    print(f"animation of episode 0: {saved}   ({time.perf_counter() - started:.1f} s)")


if __name__ == "__main__":
    main()
