"""``bearing-env robust-eval``: the robust fusion against the strict intersection.

For each layout (the Khepera field, random 8-landmark layouts) and policy
(``RandomPolygonal``, ``GreedyOneStep``), episodes of 20 moves on the evaluation seeds
under three bearing errors: clean (uniform within epsilon = 2 degrees), 5% outliers
(uniform within 2 degrees, 5% of readings replaced by a random bearing) and a true
bound of 3 degrees. The fusions are the strict intersection, the relaxed one, the robust
one (its defaults: the noise bound estimated from the data) and the robust one with the
nominal bound throughout. For each case and fusion it prints the containment (the share of
initialised landmark regions holding the truth after the last move) and the median
total area after the last move as a multiple of the strict fusion's on clean data,
then the time of a robust env step over a strict one, measured in turns in this process
(the table's last column is each run's time per env step over the strict run's, policy
time excluded).

    bearing-env robust-eval --episodes 200             # the full table
    bearing-env robust-eval --episodes 10 --no-progress

``--json`` writes every row (with its area over the strict fusion's on clean data), the
step ratio and the command, commit, date and machine that measured them; the results
page's table is written from ``docs/figures/robust_eval.json`` by ``bearing-env
docs-tables`` (:func:`markdown_robust_eval`).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from bearing_env.train.common.cli_parser import add_json_output, add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT
from bearing_env.train.common.doc_tables import markdown_table
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.provenance import measured_here, measured_sentence
from bearing_env.train.common.seeds import EVAL_SEED_START

#: The layouts: label -> env kwargs.
LAYOUTS: dict[str, dict[str, Any]] = {
    "khepera": {"scenario": "khepera"},
    "random-8": {"scenario": "random", "n_landmarks": 8},
}
POLICIES: tuple[str, ...] = ("random", "greedy")
#: The bearing errors: label -> noise (epsilon is 2 degrees throughout).
NOISES: dict[str, dict[str, Any]] = {
    "clean": {"kind": "uniform", "bound_deg": 2.0},
    "outliers 5%": {"kind": "uniform", "bound_deg": 2.0, "outlier_rate": 0.05},
    "bound 3 deg": {"kind": "uniform", "bound_deg": 3.0},
}
#: The fusions compared: label -> env kwargs.
FUSIONS: dict[str, dict[str, Any]] = {
    "strict": {"fusion": "intersect"},
    "relaxed": {"fusion": "relaxed"},
    "robust": {"fusion": "robust"},
    "robust, nominal bound": {"fusion": "robust", "noise_bound": "nominal"},
}
MOVES = 20
#: The containment the robust fusion is held to, by bearing error (the results page
#: shows a case that reaches it in bold).
CONTAINMENT_TARGETS: dict[str, float] = {"outliers 5%": 0.98, "bound 3 deg": 0.95}
#: The most a robust env step may cost, in strict steps.
STEP_RATIO_TARGET = 3.0
#: The results file of the results page's table (``--json``).
RESULTS_FILE = "docs/figures/robust_eval.json"
#: Target area no region reaches: episodes never end early.
NEVER_SUCCEEDS = 1e-12


def final_scores(
    policy_name: str, env_kwargs: dict[str, Any], seeds: Sequence[int], bar: Any
) -> dict[str, float]:
    """Containment, median total area and seconds per env step over ``seeds``."""
    from bearing_env.agents.registry import make_policy
    from bearing_env.train.compare.runner import make_env, run_episode

    kwargs = {"target_area": NEVER_SUCCEEDS, "epsilon_deg": 2.0, **env_kwargs}
    env = make_env("bearing_env:BearingSLAM-v1", {**kwargs, "max_moves": MOVES})
    policy = make_policy(policy_name, env)
    run_episode(policy, env, seeds[0] - 1)  # warm-up: compilation stays out of the time
    held = regions = 0
    areas, policy_seconds, moves = [], 0.0, 0
    started = time.perf_counter()
    for seed in seeds:
        record = run_episode(policy, env, seed)
        initialised = record["n_mapped"] - record["uninitialised"][-1]
        held += record["contained"][-1]
        regions += initialised
        areas.append(record["area"][-1])
        policy_seconds += record["policy_seconds"]
        moves += record["moves"]
        bar.update()
    env.close()
    elapsed = time.perf_counter() - started - policy_seconds
    return {
        "containment": held / regions if regions else float("nan"),
        "median_area": float(np.median(areas)),
        "step_seconds": elapsed / max(moves, 1),
    }


def step_ratio(rounds: int = 5, steps: int = 400) -> float:
    """A robust env step's time over a strict one's (Khepera, 5% outliers, random
    actions), the two timed in turns in this process, ``rounds`` x ``steps`` each, after
    a warm-up: the median of the per-round ratios."""
    import gymnasium as gym

    from bearing_env.train.compare.runner import make_env

    noise = NOISES["outliers 5%"]
    envs: dict[str, gym.Env] = {
        label: make_env(
            "bearing_env:BearingSLAM-v1",
            {"scenario": "khepera", "noise": noise, "max_moves": MOVES, **fusion},
        )
        for label, fusion in FUSIONS.items()
        if label in ("strict", "robust")
    }

    def timed(env: gym.Env, seed: int) -> float:
        env.reset(seed=seed)
        env.action_space.seed(seed)
        started = time.perf_counter()
        for _ in range(steps):
            _, _, terminated, truncated, _ = env.step(env.action_space.sample())
            if terminated or truncated:
                env.reset()
        return time.perf_counter() - started

    for env in envs.values():
        timed(env, 0)
    ratios = [timed(envs["robust"], r) / timed(envs["strict"], r) for r in range(rounds)]
    for env in envs.values():
        env.close()
    return float(np.median(ratios))


def evaluate(
    episodes: int, policies: Sequence[str] = POLICIES, progress: bool = False
) -> list[dict[str, Any]]:
    """One row per layout, policy, bearing error and fusion."""
    seeds = list(range(EVAL_SEED_START, EVAL_SEED_START + episodes))
    runs = len(LAYOUTS) * len(policies) * len(NOISES) * len(FUSIONS) * episodes
    rows = []
    with progress_bar(runs, desc="robust-eval", unit="episode", enabled=progress) as bar:
        for layout, layout_kwargs in LAYOUTS.items():
            for policy in policies:
                for noise, noise_kwargs in NOISES.items():
                    for fusion, fusion_kwargs in FUSIONS.items():
                        kwargs = {**layout_kwargs, **fusion_kwargs, "noise": noise_kwargs}
                        scores = final_scores(policy, kwargs, seeds, bar)
                        rows.append(
                            {
                                "layout": layout,
                                "policy": policy,
                                "noise": noise,
                                "fusion": fusion,
                                **scores,
                            }
                        )
    return rows


def with_area_ratios(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The rows, each with its median area over the strict fusion's on clean data for
    the same layout and policy (``area_over_clean_strict``)."""
    clean_strict = {
        (r["layout"], r["policy"]): r["median_area"]
        for r in rows
        if r["noise"] == "clean" and r["fusion"] == "strict"
    }
    return [
        {
            **row,
            "area_over_clean_strict": row["median_area"]
            / clean_strict[(row["layout"], row["policy"])],
        }
        for row in rows
    ]


def table(rows: list[dict[str, Any]]) -> str:
    """The rows as a text table, areas over the strict fusion's on clean data."""
    step_strict = {
        (r["layout"], r["policy"], r["noise"]): r["step_seconds"]
        for r in rows
        if r["fusion"] == "strict"
    }
    lines = [
        f"{'layout':9} {'policy':7} {'noise':12} {'fusion':21} {'contained':>9} "
        f"{'area/clean strict':>17} {'step/strict':>11}"
    ]
    for r in with_area_ratios(rows):
        step = r["step_seconds"] / step_strict[(r["layout"], r["policy"], r["noise"])]
        lines.append(
            f"{r['layout']:9} {r['policy']:7} {r['noise']:12} {r['fusion']:21} "
            f"{100 * r['containment']:8.1f}% {r['area_over_clean_strict']:17.2f} {step:11.2f}"
        )
    return "\n".join(lines)


#: The results page's columns: (bearing error, fusion, heading).
PAGE_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("clean", "robust", "clean: robust"),
    ("outliers 5%", "strict", "5% outliers: strict"),
    ("outliers 5%", "relaxed", "relaxed"),
    ("outliers 5%", "robust", "robust"),
    ("outliers 5%", "robust, nominal bound", "robust, nominal bound"),
    ("bound 3 deg", "strict", "3°: strict"),
    ("bound 3 deg", "relaxed", "relaxed"),
    ("bound 3 deg", "robust", "robust"),
    ("bound 3 deg", "robust, nominal bound", "robust, nominal bound"),
)
#: The pages' multiplication sign (ruff would take a literal one for a mistyped x).
TIMES = "\u00d7"
#: How the page names the layouts and the policies.
LAYOUT_NAMES = {"khepera": "Khepera", "random-8": "random 8"}
POLICY_NAMES = {"random": "RandomPolygonal", "greedy": "GreedyOneStep"}


def _cell(row: Mapping[str, Any]) -> str:
    """Containment (in bold where the robust fusion meets its target) and the area over
    the strict fusion's on clean data, when the results file has it."""
    containment = row["containment"]
    shown = "100%" if containment == 1.0 else f"{100 * containment:.1f}%"
    target = CONTAINMENT_TARGETS.get(row["noise"])
    if row["fusion"] == "robust" and target is not None and containment >= target:
        shown = f"**{shown}**"
    ratio = row.get("area_over_clean_strict")
    return shown if ratio is None else f"{shown} ({ratio:.2f}{TIMES})"


def markdown_robust_eval(results: Mapping[str, Any]) -> str:
    """The results page's table from the ``--json`` file: per layout and policy, the
    containment and relative area of each bearing error and fusion; then the command,
    commit and machine, and the step ratio."""
    rows = {(r["layout"], r["policy"], r["noise"], r["fusion"]): r for r in results["rows"]}
    cases = list(dict.fromkeys((r["layout"], r["policy"]) for r in results["rows"]))
    body = [
        [
            LAYOUT_NAMES.get(layout, layout),
            POLICY_NAMES.get(policy, policy),
            *(
                _cell(rows[(layout, policy, noise, fusion)])
                if (layout, policy, noise, fusion) in rows
                else "-"
                for noise, fusion, _ in PAGE_COLUMNS
            ),
        ]
        for layout, policy in cases
    ]
    header = ["layout", "policy", *(heading for _, _, heading in PAGE_COLUMNS)]
    step = results["robust_step_over_strict"]
    return (
        markdown_table(header, body)
        + "\n\n"
        + measured_sentence(results["measured"], RESULTS_FILE)
        + f" A robust env step costs {step:.2f}{TIMES} a strict one (Khepera, 5% outliers, random "
        f"actions, the two timed in turns in one process; target ≤ {STEP_RATIO_TARGET:g}{TIMES})."
    )


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env robust-eval",
        "The robust fusion against the strict intersection: containment, median area "
        "and step time under outliers and an underestimated noise bound.",
    )
    parser.add_argument(
        "--episodes", type=COUNT, default=200, help="evaluation episodes per case (default 200)"
    )
    parser.add_argument(
        "--policies",
        nargs="+",
        choices=POLICIES,
        default=list(POLICIES),
        help="policies to run (default: random greedy)",
    )
    add_json_output(parser, f"the rows and the step ratio (the results page's: {RESULTS_FILE})")
    add_no_progress(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    arguments = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(arguments)
    rows = evaluate(args.episodes, args.policies, progress=not args.no_progress)
    print(table(rows))
    ratio = step_ratio()
    print(
        f"robust step / strict step (Khepera, 5% outliers, random actions, in turns): {ratio:.2f}"
    )
    if args.json is not None:
        results = {
            "measured": measured_here(parser.prog, arguments),
            "episodes": args.episodes,
            "rows": with_area_ratios(rows),
            "robust_step_over_strict": ratio,
        }
        write_json_atomically(args.json, results)
        print(f"wrote {args.json}")
