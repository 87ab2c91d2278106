"""Throughput of PolygonSLAM.update() against CartPole-v1 steps, measured in one run.

Absolute times drift on shared machines, so every figure is also given as a ratio to
Gymnasium's CartPole-v1 ``env.step`` rate measured in the same process.

    python benchmarks/bench_slam.py [--seconds 2] [--json out.json]
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Sequence

import gymnasium as gym
import numpy as np

from bearing_env.slam import PolygonSLAM
from bearing_env.train.common.cli_parser import add_json_output, command_parser, doc_summary
from bearing_env.train.common.cli_values import seconds
from bearing_env.train.common.errors import exit_on_output_errors
from bearing_env.train.common.files import atomic_write_text


def cartpole_steps_per_second(seconds: float) -> float:
    env = gym.make("CartPole-v1")
    env.reset(seed=0)
    steps, action = 0, 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        for _ in range(500):
            _, _, terminated, truncated, _ = env.step(action)
            action ^= 1
            if terminated or truncated:
                env.reset()
        steps += 500
    return steps / (time.perf_counter() - start)


def make_readings(n_landmarks: int, n_moves: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Noisy bearing pairs of a random polygonal walk in a 100 x 100 arena."""
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(2.0)
    landmarks = rng.uniform(0, 100, n_landmarks) + 1j * rng.uniform(0, 100, n_landmarks)
    landmarks[1] = landmarks[0] + 20.0
    pos = 50.0 + 50.0j
    readings = []
    for _ in range(n_moves):
        heading = np.exp(1j * rng.uniform(-np.pi, np.pi))
        nxt = pos + 25.0 * heading
        if not (0 < nxt.real < 100 and 0 < nxt.imag < 100):
            nxt, heading = pos - 25.0 * heading, -heading
            if not (0 < nxt.real < 100 and 0 < nxt.imag < 100):
                nxt = pos + 0.5 * (50 + 50j - pos)
                heading = (nxt - pos) / abs(nxt - pos)
        b1 = np.angle((landmarks - pos) / heading) + rng.uniform(-eps, eps, n_landmarks)
        b2 = np.angle((landmarks - nxt) / heading) + rng.uniform(-eps, eps, n_landmarks)
        readings.append((b1, b2))
        pos = nxt
    return readings


#: The landmark counts and transfers measured, in order; the first count is the base rate.
LANDMARK_COUNTS: tuple[int, ...] = (4, 16, 64)
MEASURED_TRANSFERS: tuple[str, ...] = ("conservative", "paper")
#: CartPole steps run before its rate is measured (its first steps build the env's wrappers).
CARTPOLE_WARM_UP_STEPS = 2_000


def warm_up(transfers: Sequence[str], counts: Sequence[int]) -> None:
    """Run, untimed, everything that is timed next: some CartPole steps and one pass of
    each map's readings, so that no first-call cost (a thread's buffers, CartPole's
    wrappers) falls inside a timed window."""
    env = gym.make("CartPole-v1")
    env.reset(seed=0)
    for step in range(CARTPOLE_WARM_UP_STEPS):
        _, _, terminated, truncated, _ = env.step(step % 2)
        if terminated or truncated:
            env.reset()
    env.close()
    for transfer in transfers:
        for n in counts:
            slam = PolygonSLAM(n, np.deg2rad(2.0), transfer=transfer)
            for b1, b2 in make_readings(n, 20, seed=n):
                slam.update(b1, b2)


def updates_per_second(n_landmarks: int, transfer: str, seconds: float) -> float:
    readings = make_readings(n_landmarks, 20, seed=n_landmarks)
    slam = PolygonSLAM(n_landmarks, np.deg2rad(2.0), transfer=transfer)
    count = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        slam.reset()
        for b1, b2 in readings:
            slam.update(b1, b2)
        count += len(readings)
    return count / (time.perf_counter() - start)


def main(argv: Sequence[str] | None = None) -> None:
    parser = command_parser("bearing-env bench-slam", doc_summary(__doc__))
    parser.add_argument(
        "--seconds",
        type=seconds,
        default=2.0,
        help="time per measurement, finite and > 0 (default %(default)s)",
    )
    add_json_output(parser, "the rates")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)

    warm_up(MEASURED_TRANSFERS, LANDMARK_COUNTS)
    cartpole = cartpole_steps_per_second(args.seconds)
    print(f"CartPole-v1 env.step: {cartpole:10.0f} steps/s (reference, same run)")
    results: dict[str, float] = {"cartpole_steps_per_s": cartpole}
    for transfer in MEASURED_TRANSFERS:
        base = None
        for n in LANDMARK_COUNTS:
            rate = updates_per_second(n, transfer, args.seconds)
            base = base or rate
            results[f"{transfer}_{n}_updates_per_s"] = rate
            print(
                f"update() {transfer:>12} {n:3d} landmarks: {rate:8.0f} /s"
                f"  = {rate / cartpole:6.1%} of CartPole   {rate / base:5.2f} x the 4-landmark rate"
            )
    if args.json is not None:
        with exit_on_output_errors(parser, args.json, "--json", refusals=()):
            atomic_write_text(args.json, json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
