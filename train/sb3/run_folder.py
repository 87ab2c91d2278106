"""The layout of a training run folder (``--output``): where ``run.json``, the final
model, the best model, the checkpoints, the monitor logs and TensorBoard's logs are, and
reading ``run.json`` back with errors that name it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

RUN_RECORD_NAME = "run.json"

FINAL_MODEL_NAME = "model.zip"

FINAL_VECNORMALIZE_NAME = "vecnormalize.pkl"

@dataclass(frozen=True)
class RunFiles:
    """Paths inside a run folder."""

    root: Path

    @property
    def record(self) -> Path:
        return self.root / RUN_RECORD_NAME

    @property
    def final_model(self) -> Path:
        return self.root / FINAL_MODEL_NAME

    @property
    def final_vecnormalize(self) -> Path:
        return self.root / FINAL_VECNORMALIZE_NAME

    @property
    def best(self) -> Path:
        return self.root / "best"

    @property
    def checkpoints(self) -> Path:
        return self.root / "checkpoints"

    @property
    def monitor(self) -> Path:
        return self.root / "monitor"

    @property
    def tensorboard(self) -> Path:
        return self.root / "tensorboard"

def read_run_record(run_dir: Path) -> dict[str, Any]:
    path = RunFiles(run_dir).record
    if not path.is_file():
        raise FileNotFoundError(f"no run to resume: {path} does not exist")
    try:
        record = json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise ValueError(f"run record {path} is corrupt: {error}") from error
    if not isinstance(record, dict):
        raise ValueError(f"run record {path} is corrupt: not a JSON object")
    return record
