"""What one ``bearing-env compare`` runs: the policies, the env and the evaluation episodes
(:class:`CompareConfig`, written to ``config.json``), and report labels for policy specs.

The evaluation seeds come from :mod:`bearing_env.train.common.seeds` (``EVAL_SEED_START`` and up).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from bearing_env.train.common.seeds import EVAL_SEED_START, evaluation_seeds

#: Evaluation episodes per policy.
DEFAULT_EPISODES = 200
DEFAULT_ENV_ID = "bearing_env:BearingSLAM-v1"

DEFAULT_ENV_KWARGS: dict[str, Any] = {"scenario": "khepera"}

DEFAULT_BOOTSTRAP = 2000

DEFAULT_BOOTSTRAP_SEED = 20050101

FORMAT_VERSION = 1


def json_normalised(value: Any) -> Any:
    """The value as it reads back from JSON (tuples become lists), for comparisons."""
    return json.loads(json.dumps(value))


@dataclass(frozen=True)
class CompareConfig:
    """One comparison: which policies, which env, which episodes.

    ``policies`` maps each report label to its policy spec string (``bearing_env.agents.registry``).
    """

    policies: dict[str, str]
    env_id: str = DEFAULT_ENV_ID
    env_kwargs: dict[str, Any] = field(default_factory=lambda: dict(DEFAULT_ENV_KWARGS))
    episodes: int = DEFAULT_EPISODES
    seed_start: int = EVAL_SEED_START
    bootstrap: int = DEFAULT_BOOTSTRAP
    bootstrap_seed: int = DEFAULT_BOOTSTRAP_SEED

    @property
    def seeds(self) -> list[int]:
        return evaluation_seeds(self.episodes, self.seed_start)

    def to_json(self) -> dict[str, Any]:
        return {
            "format_version": FORMAT_VERSION,
            "env_id": self.env_id,
            "env_kwargs": json_normalised(self.env_kwargs),
            "policies": dict(self.policies),
            "episodes": self.episodes,
            "seed_start": self.seed_start,
            "bootstrap": self.bootstrap,
            "bootstrap_seed": self.bootstrap_seed,
        }


def policies_from_specs(specs: Sequence[str]) -> dict[str, str]:
    """Report labels for policy spec strings (unique; duplicates get ``#2``, ``#3``...)."""
    from bearing_env.agents.registry import parse_policy_spec

    labelled: dict[str, str] = {}
    for spec in specs:
        parsed = parse_policy_spec(spec)
        label = parsed.display_name()
        candidate, count = label, 1
        while candidate in labelled:
            count += 1
            candidate = f"{label}#{count}"
        labelled[candidate] = parsed.to_string()
    return labelled
