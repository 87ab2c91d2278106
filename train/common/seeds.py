"""The seed ranges, in one place: which env reset seeds training, model selection and
evaluation use, so that no evaluation episode is ever trained on or selected on.

=====================  ===========================  ===================================
range                  used by                      constant
=====================  ===========================  ===================================
0 ... 899,999          training envs                below :data:`TRAINING_SEED_LIMIT`
900,000 ... 999,999    validation (best model)      :data:`VALIDATION_SEED_START` + k
1,000,000 and up       ``bearing-env compare``      :data:`EVAL_SEED_START` + i
=====================  ===========================  ===================================

Training env ``i`` of a segment resumed at timestep ``t`` first resets with seed
:func:`training_seed_start` ``+ i``; validation episode ``k`` (``k <``
:data:`MAX_VALIDATION_EPISODES`) with :func:`validation_seeds`; evaluation episode ``i``
of ``compare`` with ``EVAL_SEED_START + i`` (``--seed-start`` moves it).
"""

from __future__ import annotations

#: Validation episode k (periodic evaluation, best-model selection) resets with seed
#: VALIDATION_SEED_START + k.
VALIDATION_SEED_START = 900_000
#: Training envs keep their reset seeds below this.
TRAINING_SEED_LIMIT = VALIDATION_SEED_START
#: Evaluation (test) episodes of ``bearing-env compare`` use seeds from here up.
EVAL_SEED_START = 1_000_000
#: Validation seeds stay below the evaluation seeds.
MAX_VALIDATION_EPISODES = EVAL_SEED_START - VALIDATION_SEED_START


def validation_seeds(n_episodes: int) -> tuple[int, ...]:
    """The reset seeds of the ``n_episodes`` validation episodes (the same at every
    evaluation)."""
    if not 1 <= n_episodes <= MAX_VALIDATION_EPISODES:
        raise ValueError(
            f"eval episodes must be in [1, {MAX_VALIDATION_EPISODES}], got {n_episodes}"
        )
    return tuple(range(VALIDATION_SEED_START, VALIDATION_SEED_START + n_episodes))


def training_seed_start(seed: int, start_timesteps: int, n_envs: int) -> int:
    """The reset seed of training env 0 in a segment starting at ``start_timesteps``:
    ``(seed + start_timesteps) mod (TRAINING_SEED_LIMIT - n_envs)``, so env ``i``'s seed
    ``+ i`` stays below :data:`TRAINING_SEED_LIMIT`."""
    if not 0 <= seed < TRAINING_SEED_LIMIT - n_envs:
        raise ValueError(f"--seed must be in [0, {TRAINING_SEED_LIMIT - n_envs}), got {seed}")
    return (seed + start_timesteps) % (TRAINING_SEED_LIMIT - n_envs)


def evaluation_seeds(episodes: int, seed_start: int = EVAL_SEED_START) -> list[int]:
    """The reset seeds of ``compare``'s evaluation episodes ``0 .. episodes - 1``."""
    return [seed_start + index for index in range(episodes)]
