"""``bearing-env curves``: learning curves of one run or of several training seeds, from what
``bearing-env train`` logs at each periodic evaluation (the fixed validation episodes):

- the validation return of every episode, ``best/evaluations.npz`` (SB3's
  ``EvalCallback`` file);
- the median total area after 10 moves, ``eval/median_total_area_10`` in the run's
  TensorBoard logs (read when the ``tensorboard`` package and the logs are there).

Each panel shows the IQM over the runs (and, for the return, over the episodes) at each
evaluation, with its stratified bootstrap 95% CI (:mod:`~bearing_env.train.compare.aggregate`),
and each run as a thin line. Runs are aligned on the evaluations they all have.

    bearing-env curves runs/ppo_khepera --out outputs/curves.png
    bearing-env curves 'runs/ppo_khepera/seed*' --json outputs/curves.json
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from bearing_env.train.common.cli_parser import add_json_output, command_parser
from bearing_env.train.common.errors import exit_on_missing_extra, fail
from bearing_env.train.common.files import atomic_save_figure, write_json_atomically
from bearing_env.train.compare.aggregate import (
    DEFAULT_BOOTSTRAP_SEED,
    DEFAULT_RESAMPLES,
    iqm_intervals,
)
from bearing_env.train.compare.evaluate import RUN_RECORD, ModelError

PROG = "bearing-env curves"
EVALUATIONS = Path("best") / "evaluations.npz"
AREA_TAG = "eval/median_total_area_10"


@dataclass(frozen=True)
class RunCurves:
    """One run's evaluations: env steps, the returns ``(evaluations, episodes)`` and the
    median area after 10 moves per evaluation (None without TensorBoard logs)."""

    folder: Path
    timesteps: NDArray[np.int64]
    returns: NDArray[np.float64]
    median_area: NDArray[np.float64] | None


def run_folders(arguments: Sequence[str]) -> list[Path]:
    """The run folders the arguments name: run folders, folders of run folders, globs."""
    import glob

    folders: list[Path] = []
    for argument in arguments:
        matches = [Path(m) for m in sorted(glob.glob(argument))] or [Path(argument)]
        for path in matches:
            if (path / RUN_RECORD).is_file():
                folders.append(path)
            elif path.is_dir() and any((c / RUN_RECORD).is_file() for c in path.iterdir()):
                folders += sorted(c for c in path.iterdir() if (c / RUN_RECORD).is_file())
            elif not path.name.endswith(".log"):
                raise ModelError(f"{argument!r}: {path} is not a bearing-env train run folder")
    if not folders:
        raise ModelError("no run folder given")
    return folders


def _tensorboard_scalars(folder: Path, tag: str) -> NDArray[np.float64] | None:
    """The values of ``tag`` over the run's TensorBoard logs (every segment, in order)."""
    try:
        from tensorboard.backend.event_processing.event_accumulator import EventAccumulator
    except ImportError:
        return None
    values: list[tuple[int, float]] = []
    for logs in sorted((folder / "tensorboard").glob("*")):
        accumulator = EventAccumulator(str(logs), size_guidance={"scalars": 0})
        accumulator.Reload()
        if tag in accumulator.Tags().get("scalars", []):
            values += [(event.step, event.value) for event in accumulator.Scalars(tag)]
    return np.array([value for _, value in sorted(values)]) if values else None


def read_run(folder: Path) -> RunCurves:
    path = folder / EVALUATIONS
    if not path.is_file():
        raise ModelError(
            f"{folder} has no evaluations yet ({EVALUATIONS}); train with --eval-freq > 0"
        )
    with np.load(path) as history:
        timesteps = np.asarray(history["timesteps"], dtype=np.int64)
        returns = np.asarray(history["results"], dtype=np.float64)
    return RunCurves(folder, timesteps, returns, _tensorboard_scalars(folder, AREA_TAG))


def common_evaluations(runs: Sequence[RunCurves]) -> NDArray[np.int64]:
    """The env steps at which every run was evaluated."""
    shared = set(runs[0].timesteps.tolist())
    for run in runs[1:]:
        shared &= set(run.timesteps.tolist())
    if not shared:
        raise ModelError("the runs share no evaluation step (were they evaluated as often?)")
    return np.array(sorted(shared), dtype=np.int64)


def curves_json(runs: Sequence[RunCurves], resamples: int, seed: int) -> dict[str, object]:
    """The curves' figures: per evaluation step, the IQM with its CI of the return and,
    when every run logged it, of the median area after 10 moves."""
    steps = common_evaluations(runs)
    positions = [np.searchsorted(run.timesteps, steps) for run in runs]
    returns = np.stack([run.returns[index].T for run, index in zip(runs, positions, strict=True)])
    panels: dict[str, NDArray[np.float64]] = {"return": returns}
    # The area is logged once per evaluation, in order: the k-th value is the k-th step.
    areas = [run.median_area for run in runs]
    logged = zip(areas, runs, strict=True)
    if all(a is not None and len(a) >= len(run.timesteps) for a, run in logged):
        panels["median_total_area_10"] = np.stack(
            [[a[index]] for a, index in zip(areas, positions, strict=True) if a is not None]
        )
    figures: dict[str, object] = {
        "runs": [str(run.folder) for run in runs],
        "timesteps": steps.tolist(),
        "statistics": "IQM over runs x validation episodes (return) or over runs (median "
        "area), 95% stratified bootstrap CI (rliable)",
    }
    for name, values in panels.items():
        intervals = iqm_intervals({name: values}, resamples, seed)[name]
        figures[name] = {
            "iqm": [i.value for i in intervals],
            "ci_low": [i.low for i in intervals],
            "ci_high": [i.high for i in intervals],
            "per_run": [np.median(v, axis=0).tolist() for v in values],
        }
    return figures


def plot_curves(figures: dict[str, object], out: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [
        (key, label)
        for key, label in (
            ("return", "validation return (IQM)"),
            ("median_total_area_10", "median total area after 10 moves (FL units²)"),
        )
        if key in figures
    ]
    figure, axes_list = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 3.8), dpi=110)
    steps = np.asarray(figures["timesteps"], dtype=float)
    for axes, (key, label) in zip(np.atleast_1d(axes_list), panels, strict=True):
        panel = figures[key]
        assert isinstance(panel, dict)
        for run in panel["per_run"]:
            axes.plot(steps, run, color="0.6", lw=0.8)
        axes.plot(steps, panel["iqm"], color="tab:blue", lw=2, label="IQM over runs")
        axes.fill_between(
            steps, panel["ci_low"], panel["ci_high"], color="tab:blue", alpha=0.2, lw=0
        )
        axes.set_xlabel("env steps")
        axes.set_ylabel(label)
        if key == "median_total_area_10":
            axes.set_yscale("log")
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(fontsize=8)
    figure.suptitle(f"{title}\n95% stratified bootstrap CI; grey: each run", fontsize=9)
    figure.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_save_figure(figure, out)
    plt.close(figure)


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(PROG, __doc__.split("\n\n")[0] if __doc__ else PROG)
    parser.add_argument(
        "runs", nargs="+", metavar="RUN", help="run folders, their parent, or a glob"
    )
    parser.add_argument("--out", type=Path, default=Path("outputs/curves.png"), help="the plot")
    parser.add_argument("--title", help="the plot's title (default: the runs' folder)")
    parser.add_argument(
        "--bootstrap", type=int, default=DEFAULT_RESAMPLES, help="bootstrap resamples"
    )
    add_json_output(parser, "the curves' figures")
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    args = build_parser().parse_args(sys.argv[1:] if argv is None else argv)
    with exit_on_missing_extra(PROG):
        try:
            runs = [read_run(folder) for folder in run_folders(args.runs)]
            figures = curves_json(runs, args.bootstrap, DEFAULT_BOOTSTRAP_SEED)
        except (ModelError, OSError, ValueError) as error:
            fail(PROG, str(error))
        title = args.title or f"{runs[0].folder.parent.name}: {len(runs)} run(s)"
        plot_curves(figures, args.out, title)
    if args.json is not None:
        write_json_atomically(args.json, figures)
    print(f"{len(runs)} run(s), {len(figures['timesteps'])} evaluations: {args.out}")  # type: ignore[arg-type]


if __name__ == "__main__":
    main()
