"""A ``--gym-packages`` module for the rl-zoo3 runs of ``test_zoo_commands.py``: it records
the settings of every env rl-zoo3 builds, so the test can compare the evaluation (and
``enjoy``) envs with the training envs as they were really made, not as the arguments
say they should be.

Each env rl-zoo3 builds appends one JSON line to the file named by :data:`PROBE_VARIABLE`:
its role (``train``, ``eval`` or ``enjoy``) and the ``repr`` of each sub-env's
``EnvConfig``. rl-zoo3 imports ``--gym-packages`` modules inside its ``train()`` /
``enjoy()``, before it builds any env, so the wrappers installed here are in place.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable
from typing import Any

import bearing_env  # noqa: F401  (registers the ids, as --gym-packages bearing_env does)

#: The environment variable naming the JSON-lines file the envs are recorded in.
PROBE_VARIABLE = "BEARING_ENV_ZOO_PROBE"


def record(role: str, vec_env: Any) -> None:
    """Append the settings of ``vec_env``'s sub-envs under ``role``."""
    configs = [repr(config) for config in vec_env.get_attr("config")]
    with open(os.environ[PROBE_VARIABLE], "a", encoding="utf-8") as probe:
        probe.write(json.dumps({"role": role, "configs": configs}) + "\n")


def _install() -> None:
    from rl_zoo3.exp_manager import ExperimentManager

    create_envs = ExperimentManager.create_envs

    def recorded_create_envs(
        self: Any, n_envs: int, eval_env: bool = False, no_log: bool = False
    ) -> Any:
        vec_env = create_envs(self, n_envs, eval_env=eval_env, no_log=no_log)
        record("eval" if eval_env else "train", vec_env)
        return vec_env

    ExperimentManager.create_envs = recorded_create_envs  # type: ignore[method-assign]
    # `python -m rl_zoo3.enjoy` runs enjoy.py as __main__, which looks up its imported
    # create_test_env there at call time.
    main = sys.modules["__main__"]
    create_test_env: Callable[..., Any] | None = getattr(main, "create_test_env", None)
    if create_test_env is not None:
        original = create_test_env

        def recorded_create_test_env(*args: Any, **kwargs: Any) -> Any:
            vec_env = original(*args, **kwargs)
            record("enjoy", vec_env)
            return vec_env

        main.create_test_env = recorded_create_test_env  # type: ignore[attr-defined]


if PROBE_VARIABLE in os.environ:
    _install()
