"""``bearing-env train --export DIR/NAME``: copy a run's best model (else its final
one) to ``DIR/NAME.zip``, its VecNormalize statistics to ``DIR/NAME_vecnormalize.pkl`` and
a description to ``DIR/NAME.json``, the layout of the shipped models
(``bearing_env.agents``' ``pretrained/``).
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path

from bearing_env.agents.sb3 import load_model
from bearing_env.train.common.files import atomic_path, write_json_atomically
from bearing_env.train.sb3.callbacks import (
    BEST_MODEL_NAME,
    BEST_SUMMARY_NAME,
    BEST_VECNORMALIZE_NAME,
)
from bearing_env.train.sb3.run_folder import RunFiles, read_run_record

EXPORT_VECNORMALIZE_SUFFIX = "_vecnormalize.pkl"

@dataclass(frozen=True)
class ExportedModel:
    model_path: Path
    vecnormalize_path: Path | None
    metadata_path: Path
    source: str

def export_run(run_dir: Path, destination: Path) -> ExportedModel:
    """Copy a run's best model (or its final model) to ``destination``: ``<dest>.zip``,
    ``<dest>_vecnormalize.pkl`` (when the run normalised) and ``<dest>.json``."""
    record = read_run_record(run_dir)
    files = RunFiles(run_dir)
    best_model = files.best / BEST_MODEL_NAME
    if best_model.is_file():
        source, model_path = "best", best_model
        stats_path: Path | None = files.best / BEST_VECNORMALIZE_NAME
        summary_path = files.best / BEST_SUMMARY_NAME
        validation = json.loads(summary_path.read_text()) if summary_path.is_file() else None
    elif files.final_model.is_file():
        source, model_path, stats_path, validation = (
            "final",
            files.final_model,
            files.final_vecnormalize,
            None,
        )
    else:
        raise FileNotFoundError(
            f"{run_dir} has neither {best_model} nor {files.final_model}: train it further first"
        )
    model = load_model(model_path, record["algo"])  # refuses a corrupt file before copying
    normalizes = record["hyperparams"].get("normalize") not in (None, False)
    if normalizes and (stats_path is None or not stats_path.is_file()):
        raise FileNotFoundError(f"the run normalises observations but {stats_path} is missing")
    if not normalizes:
        stats_path = None

    name = destination.name.removesuffix(".zip")
    folder = destination.parent
    folder.mkdir(parents=True, exist_ok=True)
    exported_model = folder / f"{name}.zip"
    exported_stats = folder / f"{name}{EXPORT_VECNORMALIZE_SUFFIX}"
    with atomic_path(exported_model) as temporary:
        shutil.copyfile(model_path, temporary)
    if stats_path is not None:
        with atomic_path(exported_stats) as temporary:
            shutil.copyfile(stats_path, temporary)
    else:
        exported_stats.unlink(missing_ok=True)
    metadata = {
        "name": name,
        "algo": record["algo"],
        "env_id": record["env_id"],
        "env_kwargs": record["env_kwargs"],
        "source": source,
        "num_timesteps": int(model.num_timesteps),
        "run_timesteps": record.get("num_timesteps"),
        "seed": record.get("seed"),
        "validation": validation,
        "validation_seeds": record.get("seeds", {}).get("validation"),
        "hyperparams": record["hyperparams"],
        "versions": record.get("versions"),
        "files": {
            "model": exported_model.name,
            "vecnormalize": exported_stats.name if stats_path is not None else None,
        },
    }
    metadata_path = folder / f"{name}.json"
    write_json_atomically(metadata_path, metadata)
    return ExportedModel(
        model_path=exported_model,
        vecnormalize_path=exported_stats if stats_path is not None else None,
        metadata_path=metadata_path,
        source=source,
    )
