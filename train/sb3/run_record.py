"""``run.json``, the record of a training run: what a run writes into it (settings,
seeds, versions, segments) and, on ``--resume``, what is checked against it and how the
segment of a killed process is closed. Where the file is and how it is read back:
:mod:`bearing_env.train.sb3.run_folder`.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np

import bearing_env
from bearing_env.train.common.cli_values import json_safe
from bearing_env.train.common.seeds import TRAINING_SEED_LIMIT, VALIDATION_SEED_START
from bearing_env.train.sb3.callbacks import Checkpoint, CheckpointStore
from bearing_env.train.sb3.run_folder import RunFiles, read_run_record
from bearing_env.train.sb3.zoo import read_hyperparameters

if TYPE_CHECKING:
    from bearing_env.train.sb3.train import TrainSettings

RUN_FORMAT_VERSION = 1


def versions() -> dict[str, str]:
    """The versions a run records (the training stack and Python)."""
    import stable_baselines3
    import torch

    return {
        "bearing_env": bearing_env.__version__,
        "stable_baselines3": stable_baselines3.__version__,
        "torch": torch.__version__,
        "gymnasium": gym.__version__,
        "numpy": np.__version__,
        "python": sys.version.split()[0],
    }


def new_run_record(
    settings: TrainSettings,
    hyperparams: Mapping[str, Any],
    env_kwargs: Mapping[str, Any],
    n_envs: int,
    vec_env_kind: str,
    target_timesteps: int,
    num_timesteps: int,
    segments: list[dict[str, Any]],
) -> dict[str, Any]:
    """The record of a run starting (or resuming) at ``num_timesteps``, status "running";
    ``hyperparams`` is the raw entry actually used, ``segments`` the earlier ones."""
    return {
        "format": RUN_FORMAT_VERSION,
        "algo": settings.algo,
        "env_id": settings.env_id,
        "env_kwargs": json_safe(dict(env_kwargs)),
        "hyperparams": json_safe(dict(hyperparams)),
        "n_envs": n_envs,
        "seed": settings.seed,
        "init_from": str(settings.init_from) if settings.init_from is not None else None,
        "vec_env": vec_env_kind,
        "target_timesteps": target_timesteps,
        "num_timesteps": num_timesteps,
        "status": "running",
        "seeds": {
            "training_first_reset": "env i of a segment starting at timestep t: "
            f"(seed + t) mod {TRAINING_SEED_LIMIT - n_envs} + i",
            "validation": [
                VALIDATION_SEED_START,
                VALIDATION_SEED_START + settings.eval_episodes,
            ],
        },
        "segments": segments,
        "versions": versions(),
    }


def running_segment(start_timesteps: int, n_envs: int, vec_env_kind: str) -> dict[str, Any]:
    """The segment a process adds when it starts training; it updates ``end_timesteps``
    at each checkpoint, so a killed process leaves it "running" at its last checkpoint."""
    return {
        "start_timesteps": start_timesteps,
        "end_timesteps": start_timesteps,
        "n_envs": n_envs,
        "vec_env": vec_env_kind,
        "status": "running",
        "wall_seconds": 0.0,
    }


def changed_settings(given: Mapping[str, Any], saved: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``given`` that differ from ``saved`` once both are JSON (a tuple
    given on the command line equals the list run.json read back)."""
    return {
        key: value for key, value in given.items() if json_safe(saved.get(key)) != json_safe(value)
    }


def resolve_run(settings: TrainSettings) -> tuple[dict[str, Any], Checkpoint | None]:
    """The raw hyperparameter entry and, when resuming, the checkpoint to start from."""
    files = RunFiles(settings.output)
    if not settings.resume:
        if files.record.exists():
            record = read_run_record(settings.output)
            raise FileExistsError(
                f"{settings.output} already holds a run ({record.get('num_timesteps', 0)} "
                "timesteps): pass --resume to continue it, or choose another --output"
            )
        raw = read_hyperparameters(settings.algo, settings.env_id, settings.conf_file)
        raw.update(settings.hyperparam_overrides)
        raw["env_kwargs"] = {**(raw.get("env_kwargs") or {}), **settings.env_kwargs}
        return raw, None

    record = read_run_record(settings.output)
    for key, given in (("algo", settings.algo), ("env_id", settings.env_id)):
        if record.get(key) != given:
            raise ValueError(
                f"cannot resume {settings.output}: it was trained with {key}={record.get(key)!r}, "
                f"not {given!r}"
            )
    raw = dict(record["hyperparams"])
    saved_env_kwargs = raw.get("env_kwargs") or {}
    changed = changed_settings(settings.env_kwargs, saved_env_kwargs)
    if changed:
        raise ValueError(
            f"cannot resume {settings.output} with different env kwargs {changed}; "
            f"it was trained with {saved_env_kwargs}"
        )
    different = changed_settings(settings.hyperparam_overrides, raw)
    if different:
        raise ValueError(
            f"cannot resume {settings.output} with different hyperparameters {different}; "
            "a resumed run keeps its own"
        )
    checkpoint = CheckpointStore(files.checkpoints).latest()
    if checkpoint is None:
        print(f"{settings.output}: no checkpoint yet, starting the run from scratch")
    return raw, checkpoint


def segments_after_a_kill(
    previous_record: dict[str, Any], checkpoint: Checkpoint | None
) -> list[dict[str, Any]]:
    """The segments of the run being resumed, the one a killed process left "running"
    marked "killed" at the timesteps of the checkpoint the run resumes from.

    A record that still says "running" was left by a process that died without finishing
    (SIGKILL, power loss, out of memory). Older records did not list the running segment;
    it is added.
    """
    segments = [dict(item) for item in previous_record.get("segments", [])]
    if previous_record.get("status") != "running":
        return segments
    resumed_at = checkpoint.timesteps if checkpoint is not None else 0
    if segments and segments[-1].get("status") == "running":
        killed = segments[-1]
    else:
        start = int(segments[-1]["end_timesteps"]) if segments else 0
        killed = {
            "start_timesteps": start,
            "n_envs": previous_record.get("n_envs"),
            "vec_env": previous_record.get("vec_env"),
        }
        segments.append(killed)
    killed["status"] = "killed"
    # The steps after its last checkpoint are lost; none of them is counted.
    killed["end_timesteps"] = max(resumed_at, int(killed["start_timesteps"]))
    return segments
