"""Every figure the project draws labels both axes of every panel, log axes read as plain
numbers, and the long figures show a progress bar."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from bearing_env.train.studies import figures, generalisation
from tests.extras import skip_module_without

skip_module_without("train")

SEEDS = [1_000_000, 1_000_001]


class Drawn:
    """The axes of the figures saved while it records: (file name, x label, y label,
    y tick labels of a log axis)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.panels: list[tuple[str, str, str, list[str]]] = []
        save_and_close = figures.save_and_close

        def recording(figure: Any, path: Path, rect: Any = None) -> Path:
            figure.canvas.draw()  # tick labels exist once drawn
            for axes in figure.axes:
                log_ticks = (
                    [t.get_text() for t in axes.get_yticklabels(which="both")]
                    if axes.get_yscale() == "log"
                    else []
                )
                self.panels.append((path.name, axes.get_xlabel(), axes.get_ylabel(), log_ticks))
            return save_and_close(figure, path, rect)

        monkeypatch.setattr(figures, "save_and_close", recording)

    def unlabelled(self) -> list[str]:
        return [
            f"{name} panel {i}"
            for i, (name, x, y, _) in enumerate(self.panels)
            if not (x.strip() and y.strip())
        ]


class CountingBar:
    """A stand-in for ``progress_bar``: records each bar's total and its updates."""

    def __init__(self) -> None:
        self.bars: list[dict[str, Any]] = []

    def __call__(self, total: int, *, desc: str, unit: str, enabled: bool, **_: Any) -> Any:
        record = {"total": total, "desc": desc, "updates": 0, "enabled": enabled}
        self.bars.append(record)

        class Bar:
            def __enter__(self) -> Bar:
                return self

            def __exit__(self, *exc_info: object) -> None:
                return None

            def update(self, n: int = 1) -> None:
                record["updates"] += n

        return Bar()


def test_every_panel_of_every_figure_labels_both_axes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    drawn = Drawn(monkeypatch)
    figures.figure7(tmp_path)
    figures.figure10(tmp_path, SEEDS, moves=4)
    figures.figure11(tmp_path, SEEDS, epsilons=(2.0, 4.0), moves=4)
    figures.figure_robustness(tmp_path, SEEDS, moves=4)

    def figures_of(median: float) -> dict[str, float]:
        return {"median": median, "p90": 2 * median, "worst5_mean": 3 * median}

    results = {
        "a": {
            count: {
                "a": figures_of(a),
                "greedy_one_step": figures_of(g),
                "lookahead": figures_of(h),
            }
            for count, (a, g, h) in {3: (1.0, 0.5, 0.4), 5: (2.0, 1.5, 1.2)}.items()
        }
    }
    generalisation.plot_medians(results, {"a": (3, 4)}, tmp_path / "generalisation.png")
    names = {name for name, *_ in drawn.panels}
    assert names == {
        "fig7_polygons.png",
        "fig10_khepera.png",
        "fig11_epsilon.png",
        "fig_robust.png",
        "generalisation.png",
    }
    assert drawn.unlabelled() == []


def test_the_robustness_figure_has_plain_log_tick_labels(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    drawn = Drawn(monkeypatch)
    figures.figure_robustness(tmp_path, SEEDS, moves=4)
    log_ticks = [tick for *_, ticks in drawn.panels for tick in ticks if tick]
    assert log_ticks, "the area panels are log axes with labelled ticks"
    # matplotlib's default over a narrow range: "$\\mathdefault{2\\times10^{0}}$".
    assert not [tick for tick in log_ticks if "times" in tick or "^" in tick or "$" in tick]
    assert all(float(tick) > 0 for tick in log_ticks)


def test_the_figures_show_one_bar_each_over_their_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bars = CountingBar()
    monkeypatch.setattr(figures, "progress_bar", bars)
    figures.figure10(tmp_path, SEEDS, moves=3, progress=True)
    figures.figure11(tmp_path, SEEDS, epsilons=(2.0, 4.0), moves=3, progress=True)
    figures.figure_robustness(tmp_path, SEEDS, moves=3, progress=True)
    robust_runs = (
        (len(figures.ROBUST_OUTLIER_RATES) + len(figures.ROBUST_NOISE_FACTORS))
        * len(figures.ROBUST_FUSIONS)
        * len(SEEDS)
    )
    assert [(b["desc"], b["total"], b["updates"], b["enabled"]) for b in bars.bars] == [
        ("fig. 10", 2, 2, True),
        ("fig. 11", 4, 4, True),
        ("robustness", robust_runs, robust_runs, True),
    ]


def test_the_figures_command_turns_the_bars_off_with_no_progress(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bars = CountingBar()
    monkeypatch.setattr(figures, "progress_bar", bars)
    figures.main(["--only", "10", "--seeds", "2", "--out", str(tmp_path), "--no-progress"])
    assert [b["enabled"] for b in bars.bars] == [False]
