"""``bearing-env docs-tables``: every table of measured figures in the README and the docs,
written from a results file kept in the repo.

A page holds a generated block between two comment lines::

    <!-- docs-tables: bench-env -->
    ...the Markdown this module writes...
    <!-- /docs-tables -->

:data:`BLOCKS` names each block's results file and the function that writes it. The
command rewrites every block of :data:`PAGES` from the files (and the task cards from
``docs/tasks/results/``, through :mod:`~bearing_env.train.compare.task_cards`);
``--check`` changes nothing and exits with status 1 naming each block whose text is not
what its file gives, which is what ``tests/tools/test_doc_tables.py`` runs. So a figure
has one home, its results file: after a new measurement (``bearing-env bench --json
benchmarks/results/bench_env.json``, ``bearing-env suite``, ``bearing-env figures``),
``bearing-env docs-tables`` updates the pages that show it.

    bearing-env docs-tables            # rewrite the blocks and the cards
    bearing-env docs-tables --check    # exit 1 on a block that differs from its file
"""

from __future__ import annotations

import argparse
import importlib
import json
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bearing_env.tasks import versioned_id
from bearing_env.train.common.cli_parser import command_parser
from bearing_env.train.common.provenance import measured_sentence

#: The files whose blocks are generated (relative to the repository's root).
PAGES: tuple[str, ...] = ("README.md", "docs/*.md", "docs/tasks/index.md")
BLOCK = re.compile(
    r"(?P<open><!-- docs-tables: (?P<name>[\w-]+) -->\n)(?P<body>.*?)"
    r"(?P<close><!-- /docs-tables -->)",
    re.DOTALL,
)


@dataclass(frozen=True)
class Block:
    """A generated block: its results file (relative to the root) and its writer, a
    function of the file's JSON, or ``"module:function"`` (the benchmarks' writers are
    named so: the tools never import the benchmarks, which may import the tools)."""

    source: str
    render: Callable[[Any], str] | str

    def write(self, data: Any) -> str:
        if callable(self.render):
            return self.render(data)
        module, _, name = self.render.partition(":")
        function: Callable[[Any], str] = getattr(importlib.import_module(module), name)
        return function(data)


def _load(root: Path, source: str) -> Any:
    """A results file's JSON; for a pattern (``agents/pretrained/*.json``), each file's
    JSON by its name without the suffix, in name order."""
    if "*" in source:
        paths = sorted(root.glob(source))
        return {path.stem: _load(root, str(path.relative_to(root))) for path in paths}
    return json.loads((root / source).read_text(encoding="utf-8"))


def shipped_models(records: Mapping[str, Any]) -> str:
    """The shipped models' table, from their records (``agents/pretrained/*.json``): what
    each was trained on, its checkpoint, and its validation evaluation, the mean return
    beside the total area it stands for."""
    rows = []
    for name, record in records.items():
        kwargs = record.get("env_kwargs") or {}
        settings = ", ".join(f"{key}={json.dumps(value)}" for key, value in kwargs.items())
        task = f"`{record['env_id']}`" + (f" `{settings}`" if settings else "")
        policy = str(record["hyperparams"].get("policy", "")).rpartition(".")[2]
        validation = record["validation"]
        rows.append(
            (
                f"`{name}`",
                task,
                f"`{policy}`, {record['hyperparams'].get('n_envs')} envs",
                f"{record['num_timesteps']:,} of {record['run_timesteps']:,}",
                f"{validation['mean_reward']:.2f}",
                f"{validation['median_total_area_10']:.3g}",
                f"{validation['median_total_area_final']:.3g}",
            )
        )
    header = (
        "model", "trained on", "policy", "checkpoint (steps of the run)",
        "validation mean return", "median total area after 10 moves", "after the last move",
    )  # fmt: skip
    return markdown_table(header, rows)


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def compare_medians(summary: Mapping[str, Any]) -> str:
    """A comparison's median table, from its ``summary.json`` (``bearing-env compare``
    writes it in ``--out``; the docs keep a copy under ``docs/compare/results/``)."""
    from bearing_env.train.compare.report import area_median_rows
    from bearing_env.train.compare.task_cards import config_of

    config = config_of(summary)
    seeds = config.seeds
    kwargs = ", ".join(f"{key}={value!r}" for key, value in config.env_kwargs.items())
    header, rows = area_median_rows(summary, config)
    return (
        f"Median total area, {config.episodes} evaluation episodes per policy (seeds "
        f"{seeds[0]}..{seeds[-1]}), `{config.env_id.rpartition(':')[2]}` with `{kwargs}`:"
        "\n\n" + markdown_table(header, rows)
    )


def compare_settings(summaries: Mapping[str, Any]) -> str:
    """Comparisons on other settings, one row each (``docs/compare/results/settings_*.json``,
    copies of their ``summary.json``): the median total area after 10 moves (random
    polygonal's over each policy's in brackets), then the success rates."""
    from bearing_env.train.compare.task_cards import config_of

    labels: list[str] = []
    for summary in summaries.values():
        labels += [label for label in summary["policies"] if label not in labels]
    medians, successes = [], []
    for summary in summaries.values():
        config = config_of(summary)
        kwargs = ", ".join(f"{key}={value!r}" for key, value in config.env_kwargs.items())
        setting = f"`{config.env_id.rpartition(':')[2]}` `{kwargs}`, {config.episodes} episodes"
        policies = summary["policies"]
        reference = policies.get("random_polygonal", {}).get("area_after", {}).get("10", {})
        median_cells, success_cells = [setting], [setting]
        for label in labels:
            stats = policies.get(label)
            if stats is None:
                median_cells.append("-")
                success_cells.append("-")
                continue
            median = stats["area_after"]["10"]["median"]
            ratio = reference.get("median")
            shown = f"{median:.3g}"
            if ratio and label != "random_polygonal" and median:
                shown += f" ({ratio / median:.1f}x)"
            median_cells.append(shown)
            moves = stats.get("moves_to_success_median")
            success = f"{100 * stats['success_rate']:.0f}%"
            success_cells.append(success + (f" ({moves:g})" if moves is not None else ""))
        medians.append(median_cells)
        successes.append(success_cells)
    return (
        "Median total area after 10 moves (random ÷ policy in brackets):\n\n"
        + markdown_table(["setting", *labels], medians)
        + "\n\nSuccess within the episode (median moves to success in brackets):\n\n"
        + markdown_table(["setting", *labels], successes)
    )


def compare_outcomes(summary: Mapping[str, Any]) -> str:
    """A comparison's medians after 5, 10 and 20 moves, mean after 10 with its 95%
    bootstrap CI, and success rate, one row per policy (its ``summary.json``)."""
    from bearing_env.train.compare.task_cards import config_of

    config = config_of(summary)
    rows = []
    for label, stats in summary["policies"].items():
        after = stats["area_after"]
        ten = after["10"]
        rows.append(
            [
                label,
                *(f"{after[str(k)]['median']:.3g}" for k in (5, 10, 20)),
                f"{ten['mean']:.3g} [{ten['ci_low']:.3g}, {ten['ci_high']:.3g}]",
                f"{100 * stats['success_rate']:.1f}%",
            ]
        )
    header = [
        "policy", "median after 5", "median after 10", "median after 20",
        "mean after 10 [95% CI]", "success",
    ]  # fmt: skip
    return (
        f"Total area, {config.episodes} evaluation episodes per policy, "
        f"`{config.env_id.rpartition(':')[2]}` "
        + ", ".join(f"`{k}={v!r}`" for k, v in config.env_kwargs.items())
        + ":\n\n"
        + markdown_table(header, rows)
    )


#: How the scaling page names the runs of ``benchmarks/bench_compare.py``.
RAY_RUN_LABELS: dict[str, str] = {
    "local, 1 process": "`--workers 1` (this process, env and policies built)",
    "local, 2 processes": "`--workers 2` (new worker processes)",
    "ray, new instance": "`--executor ray`, as run on one machine (starts and stops a local "
    "instance)",
    "ray start-up (ray.init)": "of which `ray.init` alone",
    "ray, running instance": "`--executor ray` on a running 2-CPU instance (new workers)",
    "ray, warm workers": "the same, second run (warm workers)",
    "ray, 1 CPU": "`--executor ray` on a running 1-CPU instance, new workers",
    "ray, 1 CPU, warm": "`--executor ray` on a running 1-CPU instance, warm",
}


def _range(values: Sequence[float] | None, digits: int, unit: str = "") -> str:
    """``low–high`` with ``digits`` decimals and the unit; "1" for the baseline itself;
    empty where the results file has no figure."""
    if values is None:
        return ""
    low, high = values
    if low == high == 1:
        return "1"
    return f"{low:.{digits}f}\u2013{high:.{digits}f}{unit}"


def compare_on_ray(results: Mapping[str, Any]) -> str:
    """The scaling page's table (``benchmarks/results/bench_compare.json``): each way of
    running one comparison, its wall time and its speed-ups over ``--workers 1`` and
    ``--workers 2`` (min–max over the repeats, a speed-up taken within a repeat), then
    Ray's overhead per episode and where the figures were measured."""
    episodes = results["episodes"]
    labels = [label.replace("_", " ") for label in results["policies"]]
    policies = ", ".join(labels[:-1]) + f" and {labels[-1]}" if len(labels) > 1 else labels[0]
    rows = []
    for run in results["runs"]:
        seconds = _range(run["seconds"], 1, " s")
        if run["run"] == "local, 1 process":
            low, high = (1000 * value / episodes for value in run["seconds"])
            seconds += f" ({low:.0f}\u2013{high:.0f} ms an episode)"
        rows.append(
            (
                RAY_RUN_LABELS.get(run["run"], run["run"]),
                seconds,
                _range(run["over_workers_1"], 2, "\u00d7"),
                _range(run["over_workers_2"], 2, "\u00d7"),
            )
        )
    header = ("run", "wall time", "over `--workers 1`", "over `--workers 2`")
    overhead = results["ray_overhead_ms_per_episode"]
    base = next(run["seconds"] for run in results["runs"] if run["run"] == "local, 1 process")
    episode_ms = [1000 * value / episodes for value in base]
    share = (100 * overhead[0] / episode_ms[1], 100 * overhead[1] / episode_ms[0])
    return (
        f"{episodes} episodes ({episodes // len(labels)} each of {policies}, Khepera, 20 "
        f"moves), {results['repeats']} repeats: every figure is a range over the repeats, and "
        "a speed-up is taken within a repeat. "
        + measured_sentence(results["measured"], "benchmarks/results/bench_compare.json")
        + "\n\n"
        + markdown_table(header, rows)
        + "\n\nRay's overhead per episode (as many empty tasks as episodes, each sending an "
        "episode's task and returning a real record, on one CPU) was "
        f"{_range(overhead, 2, ' ms')}, {share[0]:.0f}\u2013{share[1]:.0f}% of an episode here."
    )


def transfer_tightness(records: Mapping[str, Any]) -> str:
    """Single-movement regions against the exact transferred sets, one row per transfer
    (``benchmarks/results/transfer_tightness_*.json``, ``bearing-env transfer-tightness
    --transfer T --json``)."""
    rows = []
    sentences = []
    for record in records.values():
        settings, figures = record["settings"], record["summary"]
        rows.append(
            (
                f"`{settings['transfer']}`",
                f"{settings['edge_samples']}",
                f"{figures['regions']}",
                f"{figures['ratio_median']:.3g}\u00d7",
                f"{figures['ratio_p95']:.3g}\u00d7",
                f"{figures['ratio_max']:.3g}\u00d7",
                f"{figures['ratio_to_reference_median']:.3g}\u00d7",
                f"{100 * figures['contains_both']:.1f}%",
            )
        )
        sentences.append(
            measured_sentence(
                record["measured"],
                f"benchmarks/results/transfer_tightness_{settings['transfer']}.json",
            )
        )
    first = next(iter(records.values()))["settings"]
    fixed = [
        f"{record['summary']['fixed_directions'][k]['ratio_median']:.3g}\u00d7 with K = {k} "
        f"({record['summary']['fixed_directions'][k]['ratio_p95']:.3g}\u00d7)"
        for record in records.values()
        if record["settings"]["transfer"] == "conservative"
        for k in record["summary"].get("fixed_directions", {})
    ]
    header = (
        "transfer", "samples per edge", "regions", "area \u00f7 exact, median", "95th pct",
        "max", "area \u00f7 dense hull, median", "hold E and the hull",
    )  # fmt: skip
    return (
        " ".join(sentences)
        + f" Layouts {', '.join(first['layouts'])}; E on a {first['resolution']}\u00d7"
        f"{first['resolution']} grid; the dense hull uses {first['reference_samples_per_edge']}"
        " samples per edge.\n\n"
        + markdown_table(header, rows)
        + (
            "\n\nThe same `conservative` regions kept as K support values in fixed FL "
            "directions (each region's circumscribed K-gon) would be, over the exact set, "
            f"median (95th percentile): {'; '.join(fixed)}."
            if fixed
            else ""
        )
    )


def transfer_fused_area(summaries: Mapping[str, Any]) -> str:
    """The fused total area after 10 and 20 moves under each transfer, per policy, from
    comparisons on the same episodes (``docs/compare/results/transfer_*.json``, copies of
    ``bearing-env compare``'s ``summary.json``); the last row's ratio is to the first."""
    from bearing_env.train.compare.task_cards import config_of

    configs = {name: config_of(summary) for name, summary in summaries.items()}
    names = list(summaries)
    base = names[0]
    rows = []
    for label in summaries[base]["policies"]:
        for moves in ("10", "20"):
            after = [summaries[n]["policies"][label]["area_after"][moves] for n in names]
            medians = [entry["median"] for entry in after]
            means = [entry["mean"] for entry in after]
            rows.append(
                (
                    label,
                    moves,
                    *(f"{median:.4g}" for median in medians),
                    f"{medians[-1] / medians[0]:.3f}",
                    f"{means[-1] / means[0]:.3f}",
                )
            )
    columns = [f"`{configs[n].env_id.rpartition(':')[2]}`, median" for n in names]
    header = ("policy", "after moves", *columns, "median ratio", "mean ratio")
    config = configs[base]
    sentences = [
        measured_sentence(summary["measured"], f"docs/compare/results/{name}.json")
        for name, summary in summaries.items()
        if "measured" in summary
    ]
    return (
        "".join(f"{sentence} " for sentence in sentences)
        + f"Total area of the fused map, {config.episodes} evaluation episodes per policy "
        f"(seeds {config.seeds[0]}..{config.seeds[-1]}, the same for every id):\n\n"
        + markdown_table(header, rows)
    )


#: ``bearing-env evaluate``'s results for the shipped Khepera model's training seeds.
KHEPERA_SEEDS = "docs/compare/results/seeds_ppo_khepera.json"


def khepera_seeds(results: Mapping[str, Any]) -> str:
    """The shipped Khepera model's training seeds against the baselines
    (``bearing-env evaluate``'s tables, without the page heading)."""
    from bearing_env.train.compare.evaluation_report import evaluation_markdown

    return evaluation_markdown(results, KHEPERA_SEEDS, heading=False)


#: The learned exploration designs on the planner features, one ``bearing-env evaluate``
#: results file each.
PLANNER_DESIGNS = "docs/compare/results/planner_*.json"


def planner_designs(results: Mapping[str, Any]) -> str:
    """Each design's training seeds against the baselines on its task (``bearing-env
    evaluate``'s tables under a heading per design, from ``PLANNER_DESIGNS``)."""
    from bearing_env.train.compare.evaluation_report import evaluation_markdown

    sections = []
    for name, evaluation in results.items():
        source = PLANNER_DESIGNS.replace("*", name.removeprefix("planner_"))
        body = evaluation_markdown(evaluation, source, heading=False)
        sections.append(f"### `{evaluation['model']['name']}`\n\n{body.rstrip()}\n")
    return "\n".join(sections)


def _blocks() -> dict[str, Block]:
    from bearing_env.train.compare import task_cards
    from bearing_env.train.studies import figures, observability, robust_eval

    bench = "benchmarks/results/bench_env.json"
    report = "bearing_env.benchmarks.bench_report"
    # The Khepera task's card, in the current version.
    khepera = f"docs/tasks/results/{versioned_id('BearingSLAM-Khepera')}.json"
    return {
        "bench-machine": Block(bench, f"{report}:markdown_machine"),
        "bench-goals": Block(bench, f"{report}:markdown_goals"),
        "bench-env": Block(bench, f"{report}:markdown_env_table"),
        "bench-startup": Block(bench, f"{report}:markdown_startup"),
        "bench-throughput": Block(bench, f"{report}:markdown_throughput"),
        "bench-callgrind": Block(
            "benchmarks/results/bench_callgrind.json",
            "bearing_env.benchmarks.bench_callgrind:markdown_callgrind",
        ),
        "khepera-medians": Block(khepera, task_cards.markdown_medians),
        "fig11-fits": Block("docs/figures/figures.json", figures.markdown_fig11),
        "robust-figure": Block("docs/figures/figures.json", figures.markdown_robust),
        "shipped-models": Block("agents/pretrained/*.json", shipped_models),
        "khepera-25cm": Block("docs/compare/results/khepera_25cm.json", compare_medians),
        "other-settings": Block("docs/compare/results/settings_*.json", compare_settings),
        "lookahead": Block("docs/compare/results/lookahead.json", compare_outcomes),
        "observability": Block(observability.RESULTS_FILES, observability.markdown_observability),
        "robust-eval": Block(robust_eval.RESULTS_FILE, robust_eval.markdown_robust_eval),
        "compare-on-ray": Block("benchmarks/results/bench_compare.json", compare_on_ray),
        "transfer-tightness": Block(
            "benchmarks/results/transfer_tightness_*.json", transfer_tightness
        ),
        "transfer-fused-area": Block("docs/compare/results/transfer_*.json", transfer_fused_area),
        "khepera-seeds": Block(KHEPERA_SEEDS, khepera_seeds),
        "planner-designs": Block(PLANNER_DESIGNS, planner_designs),
    }


def pages(root: Path) -> list[Path]:
    found: list[Path] = []
    for pattern in PAGES:
        found += sorted(root.glob(pattern))
    return list(dict.fromkeys(found))


def render_block(name: str, root: Path, blocks: Mapping[str, Block] | None = None) -> str:
    """The Markdown of block ``name`` from its results file under ``root``."""
    block = (blocks or _blocks())[name]
    text = block.write(_load(root, block.source)).rstrip("\n")
    return f"{text}\n"


def regenerate(text: str, root: Path, blocks: Mapping[str, Block] | None = None) -> str:
    """``text`` with every generated block rewritten (KeyError on an unknown block)."""
    known = blocks or _blocks()

    def replace(match: re.Match[str]) -> str:
        body = render_block(match["name"], root, known)
        return f"{match['open']}{body}{match['close']}"

    return BLOCK.sub(replace, text)


def stale(root: Path) -> list[str]:
    """``page: block`` for every generated block (and ``docs/tasks/<card>``) whose text
    is not what its results file gives; empty when all are current."""
    from bearing_env.train.compare.task_cards import published_cards

    blocks = _blocks()
    differing: list[str] = []
    for page in pages(root):
        text = page.read_text(encoding="utf-8")
        for match in BLOCK.finditer(text):
            if render_block(match["name"], root, blocks) != match["body"]:
                differing.append(f"{page.relative_to(root)}: {match['name']}")
    for path, text in published_cards(root / "docs" / "tasks").items():
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            differing.append(f"{path.relative_to(root)}: the card")
    return differing


def write_all(root: Path) -> list[Path]:
    """Rewrite every block and card under ``root``; the files that changed."""
    from bearing_env.train.common.files import atomic_write_text
    from bearing_env.train.compare.task_cards import published_cards

    changed: list[Path] = []
    blocks = _blocks()
    for page in pages(root):
        text = page.read_text(encoding="utf-8")
        new = regenerate(text, root, blocks)
        if new != text:
            atomic_write_text(page, new)
            changed.append(page)
    for path, text in published_cards(root / "docs" / "tasks").items():
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            atomic_write_text(path, text)
            changed.append(path)
    return changed


def build_parser() -> argparse.ArgumentParser:
    parser: argparse.ArgumentParser = command_parser(
        "bearing-env docs-tables",
        "Write every table of measured figures in the README and the docs (and the task "
        "cards) from the results files kept in the repository.",
        "Blocks: " + ", ".join(_blocks()) + ".",
    )
    parser.add_argument("--check", action="store_true", help="change nothing; exit 1 if stale")
    parser.add_argument(
        "--root", type=Path, default=Path("."), help="the repository (default: here)"
    )
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    args = build_parser().parse_args(argv)
    if args.check:
        differing = stale(args.root)
        for entry in differing:
            print(f"stale: {entry}")
        if differing:
            print("run `bearing-env docs-tables` to rewrite them", file=sys.stderr)
            raise SystemExit(1)
        print("every generated table matches its results file")
        return
    for path in write_all(args.root):
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
