"""Golden traces: hashes of what the envs and the shipped policies emit over fixed seeds.

A restructuring must keep behaviour. Each trace runs one setting (an id, a transfer, a
fusion, a noise model, the vector env in an autoreset mode, or a shipped policy) over
fixed seeds and hashes every observation, reward, termination, truncation and info (the
robot's map included) into one sha256. ``tests/golden/traces.json`` holds the hashes
recorded before a change; ``tests/test_golden_traces.py`` compares. Every trace runs on
the ``-v0`` ids (hashes recorded with bearing_env 0.1, which those ids reproduce) and on
the ``-v1`` ids (:func:`version_traces`).

    python -m tests.golden_traces            # print the current hashes, and any changes
    python -m tests.golden_traces --update NAME ...   # record them (new traces, or a
                                                      # deliberate change)

Floats are hashed as float32: bit for bit at the observation's own precision, and blind
to a last-bit difference in a float64 intermediate, which another CPU's fused
multiply-adds can make.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import bearing_env  # noqa: F401  (registers the ids)

TRACES_FILE = Path(__file__).parent / "golden" / "traces.json"


def feed(digest: Any, value: Any, exact: bool = False) -> None:
    """Add ``value`` (arrays, numbers, bools, strings, None, dicts, lists) to ``digest``;
    floats as float32, or with ``exact`` as they are (NaN canonicalised)."""
    if isinstance(value, dict):
        for key in sorted(value):
            digest.update(f"<{key}>".encode())
            feed(digest, value[key], exact)
    elif isinstance(value, (list, tuple)):
        digest.update(f"[{len(value)}".encode())
        for item in value:
            feed(digest, item, exact)
    elif value is None or isinstance(value, str):
        digest.update(repr(value).encode())
    else:
        array = np.asarray(value)
        if array.dtype.kind == "O":  # e.g. the vector env's final observations and infos
            digest.update(f"O{array.shape}".encode())
            for item in array.ravel():
                feed(digest, item, exact)
            return
        if array.dtype.kind == "c":
            array = np.stack([array.real, array.imag], axis=-1)
        if array.dtype.kind == "f" and exact:
            array = np.where(np.isnan(array), np.nan, array).astype(array.dtype)
        elif array.dtype.kind == "f":
            array = array.astype(np.float32)
        elif array.dtype.kind in "biu" and not exact:
            array = array.astype(np.int64)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(np.ascontiguousarray(array).tobytes())


def single_env_stream(env_id: str, episodes: int, seed: int, **kwargs: Any) -> Iterator[Any]:
    env = gym.make(env_id, **kwargs)
    env.action_space.seed(seed)
    for episode in range(episodes):
        yield env.reset(seed=seed + episode)
        done = False
        while not done:
            outcome = env.step(env.action_space.sample())
            done = outcome[2] or outcome[3]
            yield outcome
    env.close()


def vector_env_stream(
    env_id: str, mode: str, steps: int, seed: int, **kwargs: Any
) -> Iterator[Any]:
    envs = gym.make_vec(
        env_id, num_envs=3, vectorization_mode="vector_entry_point",
        autoreset_mode=mode, **kwargs,
    )
    envs.action_space.seed(seed)
    yield envs.reset(seed=seed)
    for step in range(steps):
        outcome = envs.step(envs.action_space.sample())
        yield outcome
        ended = np.logical_or(outcome[2], outcome[3])
        if mode == "disabled" and ended.any():
            yield envs.reset(options={"reset_mask": ended})
        elif mode != "disabled" and step == steps // 2:
            mask = np.array([True, False, True])
            if mode == "next_step":  # a masked reset mid-episode is allowed in every mode
                yield envs.reset(seed=seed + 100, options={"reset_mask": mask})
    envs.close()


def policy_stream(
    env_id: str, spec: str, episodes: int, seed: int, **kwargs: Any
) -> Iterator[Any]:
    from bearing_env.agents.registry import make_policy

    env = gym.make(env_id, **kwargs)
    policy = make_policy(spec, env)
    # A network's actions differ in their last bits between CPUs (torch's kernels for
    # AVX2 and AVX-512 round differently): the trace applies them rounded to 1e-4.
    network = spec.startswith("pretrained:")
    for episode in range(episodes):
        policy.reset(seed=seed + episode)
        observation, info = env.reset(seed=seed + episode)
        yield observation, info
        done = False
        while not done:
            action = policy.act(observation, info)
            if network and isinstance(action, np.ndarray) and action.dtype.kind == "f":
                action = np.round(action, 4).astype(action.dtype)
            observation, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            yield action, observation, reward, terminated, truncated, info
    env.close()


KHEPERA = {"scenario": "khepera"}
FAULTY = {"noise": {"kind": "uniform", "outlier_rate": 0.1, "detection_rate": 0.85}}

def version_traces(version: int) -> dict[str, Callable[[], Iterator[Any]]]:
    """The traces on the ids of ``version``. The ``-v0`` ones keep their names from before
    the ids had versions (their hashes were recorded then, on bearing_env 0.1's transfer,
    which the ``-v0`` ids keep); the others add ``-v<version>`` to them (the vector traces
    name their id already)."""
    suffix = "" if version == 0 else f"-v{version}"
    continuous, discrete = f"BearingSLAM-v{version}", f"BearingSLAMDiscrete-v{version}"
    return {
        f"continuous-khepera-conservative-intersect{suffix}": lambda: single_env_stream(
            continuous, 3, 10, **KHEPERA
        ),
        f"continuous-random-paper-intersect{suffix}": lambda: single_env_stream(
            continuous, 3, 11, scenario="random", n_landmarks=6, transfer="paper"
        ),
        f"continuous-random-relaxed-faulty-entities{suffix}": lambda: single_env_stream(
            continuous, 3, 12, scenario="random", n_landmarks=(3, 8), fusion="relaxed",
            observation="entities", **FAULTY,
        ),
        f"continuous-khepera-gaussian-costs-area{suffix}": lambda: single_env_stream(
            continuous, 2, 13, noise="gaussian", reward="area", path_cost=0.1,
            move_cost=0.01, **KHEPERA,
        ),
        f"discrete-khepera-conservative-intersect{suffix}": lambda: single_env_stream(
            discrete, 3, 14, **KHEPERA
        ),
        f"discrete-random-paper-relaxed-faulty{suffix}": lambda: single_env_stream(
            discrete, 3, 15, scenario="random", n_landmarks=5, transfer="paper",
            fusion="relaxed", n_turns=12, **FAULTY,
        ),
        **{
            f"vector-{env_id}-{mode}": (
                lambda env_id=env_id, mode=mode: vector_env_stream(
                    env_id, mode, 45, 16, scenario="random", n_landmarks=(3, 6), max_moves=8,
                )
            )
            for env_id in (continuous, discrete)
            for mode in ("next_step", "same_step", "disabled")
        },
        **{
            f"policy-{spec}{suffix}": (
                lambda spec=spec: policy_stream(continuous, spec, 2, 17, **KHEPERA)
            )
            for spec in ("random", "parallax", "greedy", "oracle", "pretrained:ppo_khepera")
        },
        f"policy-lookahead{suffix}": lambda: policy_stream(
            continuous, "lookahead", 1, 18, max_moves=4, **KHEPERA
        ),
    }


#: name -> a function that makes the trace's stream: every trace on the ``-v0`` ids and
#: again on the ``-v1`` ids.
TRACES: dict[str, Callable[[], Iterator[Any]]] = {**version_traces(0), **version_traces(1)}


def trace_hash(name: str) -> str:
    digest = hashlib.sha256()
    for item in TRACES[name]():
        feed(digest, item)
    return digest.hexdigest()


def recorded() -> dict[str, str]:
    return dict(json.loads(TRACES_FILE.read_text()))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", action="store_true", help="record the current hashes")
    parser.add_argument("names", nargs="*", help="traces to run (default: all)")
    args = parser.parse_args(argv)
    names = args.names or list(TRACES)
    current = {name: trace_hash(name) for name in names}
    old = recorded() if TRACES_FILE.exists() else {}
    changed = [name for name in names if old.get(name) != current[name]]
    for name in names:
        print(f"{'CHANGED' if name in changed else 'same   '} {name} {current[name]}")
    if args.update:
        TRACES_FILE.parent.mkdir(exist_ok=True)
        TRACES_FILE.write_text(json.dumps({**old, **current}, indent=2, sort_keys=True) + "\n")
    elif changed:
        sys.exit(1)


if __name__ == "__main__":
    main()
