"""``bearing-env figures``: the paper's Figs. 7, 10 and 11, reproduced in simulation.

All three follow the paper's protocol: the robot moves along a random polygonal line (a
random rotation on the spot, then a straight move), and the map is the paper's polygon
SLAM. By default the figures use the paper's own transfer (``transfer="paper"``, the
convex hull of the vertex-hypothesis images) since they reproduce the paper; pass
``--transfer conservative`` for the env's default transfer.

- **Fig. 7** (``fig7_polygons.png``): the regions A_L3 and A_L4 in FL after 1, 3, 6 and 9
  movements of one random polygonal run in the paper's simulated world (``paper_sim``:
  four landmarks around the centre of a 2 x 2 m square; moves of one FL unit). The run is
  the first seed from ``--fig7-seed`` whose first movement initialises both landmarks
  and whose regions shrink at every panel, as in the paper's illustration (the seed and
  the number of runs skipped are in ``figures.json``).
- **Fig. 10** (``fig10_khepera.png``): area and error of L3 and L4 against movements in
  the Khepera scenario (epsilon 2 degrees, 10 movements of 25 cm), median over the
  evaluation seeds with the interquartile range.
- **Fig. 11** (``fig11_epsilon.png``): the area and error of L3 against movements for
  epsilon = 2..7 degrees, and the final area against epsilon with a least-squares line
  and its R^2. As in the paper ("a same bearing set but different values of epsilon"),
  every epsilon sees the *same* trajectories and the *same* bearings: the true sensor
  noise is uniform within +-2 degrees for all of them (``--fig11-noise same``); only the
  SLAM's epsilon changes. ``--fig11-noise scaled`` instead scales the noise with epsilon
  (uniform within +-epsilon, the same normalised draws for every epsilon).

- **Robustness** (``fig_robust.png``, not in the paper): the share of landmark regions
  that contain the truth after 20 random polygonal moves on the Khepera field, and the
  median total area, against the outlier rate (0-10% of readings replaced by a random
  bearing) and against the true noise bound (1-2 x epsilon), and containment against
  median area (the trade-off), for the strict intersection with
  ``on_inconsistency="restart"`` and ``"keep"``, the relaxed fusion
  (``fusion="relaxed"``) and the robust fusion (``fusion="robust"``: its guaranteed set
  at the default risk 0.05 and at 0.2, and its likely set), on the same seeds;
  conservative transfer.

The numbers behind the plots go to ``figures.json``.

    bearing-env figures --out docs/figures            # all three, 200 seeds
    bearing-env figures --quick --out /tmp/figures    # 12 seeds, for a smoke test
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.extras import MissingExtraError, available
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT, SEED
from bearing_env.train.common.errors import exit_on_output_errors, fail
from bearing_env.train.common.files import atomic_save_figure, atomic_write_text
from bearing_env.train.common.progress import NoProgress, progress_bar
from bearing_env.train.common.seeds import EVAL_SEED_START
from bearing_env.train.compare.runner import make_env

FIG7_MOVEMENTS: tuple[int, ...] = (1, 3, 6, 9)
FIG11_EPSILONS: tuple[float, ...] = (2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
#: The paper's real-robot sensor error; Fig. 11's true noise in the "same bearings" mode.
PAPER_NOISE_DEG = 2.0
#: The paper's final errors on the real robot (Sec. 4): 2 and 3 cm with a 20 cm unit.
PAPER_FINAL_ERRORS = {"L3": 0.10, "L4": 0.15}
#: Moves of 25 cm on the Khepera field (the reference runs of docs/design.md).
KHEPERA_MOVE_LENGTH = 0.25
#: Moves of about one FL unit in the paper's simulated world (L1-L2 = 0.5 m).
PAPER_SIM_MOVE_LENGTH = 0.5
#: The move length of each scenario the paper's figures use.
FIGURE_MOVE_LENGTHS = {"khepera": KHEPERA_MOVE_LENGTH, "paper_sim": PAPER_SIM_MOVE_LENGTH}
DEFAULT_SEEDS = 200
QUICK_SEEDS = 12
FIGURE_DPI = 100
#: Target area (FL units squared) that no region reaches: runs never end early.
NEVER_SUCCEEDS = 1e-12


@dataclass
class Trace:
    """One random polygonal run: per movement (0 = before moving) and per landmark i >= 3."""

    areas: NDArray[np.float64]  # (moves + 1, n - 2); inf if not initialised
    errors: NDArray[np.float64]  # (moves + 1, n - 2); inf if not initialised
    bearings: NDArray[np.float64]  # (moves + 1, n): the readings, for the "same bearings" check
    polygons: list[list[NDArray[np.float64] | None]]  # per movement, per landmark (FL)
    estimates: NDArray[np.float64]  # (moves + 1, n - 2, 2) FL
    contains: NDArray[np.bool_]  # (moves + 1, n - 2): the region holds the true landmark
    truth_fl: NDArray[np.float64]  # (n, 2) true landmark positions in FL
    trajectory_fl: NDArray[np.float64]  # (moves + 1, 2) true robot positions in FL


def figure_env_kwargs(scenario: str, transfer: str, epsilon_deg: float) -> dict[str, Any]:
    """The env kwargs of Figs. 7, 10 and 11's runs: ``scenario`` with its paper move length."""
    return {
        "scenario": scenario,
        "transfer": transfer,
        "epsilon_deg": float(epsilon_deg),
        "move_length": FIGURE_MOVE_LENGTHS[scenario],
    }


def random_polygonal_trace(
    env_kwargs: dict[str, Any], seed: int, moves: int, keep_polygons: bool = False
) -> Trace:
    """Run the random polygonal policy for ``moves`` movements and record the map."""
    from bearing_env.agents import RandomPolygonal
    from bearing_env.agents.env_access import bearing_env_of, world_of
    from bearing_env.envs.observations import BEARING_FEATURES, observation_slices
    from bearing_env.slam import world_to_fl

    # The paper's runs have a fixed number of movements: no early stop on success.
    kwargs = {"target_area": NEVER_SUCCEEDS, **env_kwargs, "max_moves": moves}
    env = make_env("bearing_env:BearingSLAM-v1", kwargs)
    base = bearing_env_of(env)
    policy = RandomPolygonal(env)
    bearing_block = observation_slices(base.config.observations.max_landmarks)["bearings"]
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    world = world_of(env)
    l1, l2 = world.landmarks[0], world.landmarks[1]
    areas, errors, bearings, polygons, estimates, trajectory = [], [], [], [], [], []
    contains = []

    def record(obs: NDArray[np.float32], step_info: dict[str, Any]) -> None:
        areas.append(np.asarray(step_info["landmark_area"], dtype=float).copy())
        errors.append(np.asarray(step_info["landmark_error"], dtype=float).copy())
        contains.append(np.asarray(step_info["landmark_contains_truth"], dtype=bool).copy())
        block = obs[bearing_block].reshape(-1, len(BEARING_FEATURES))[: base.n_landmarks]
        bearings.append(np.arctan2(block[:, 2], block[:, 1]).astype(float))
        slam = base.slam
        assert slam is not None  # the env has been reset
        polygons.append(
            [None if p is None else p.copy() for p in slam.polygons] if keep_polygons else []
        )
        estimates.append(slam.estimates.copy())
        trajectory.append(world_to_fl(world.position, l1, l2))

    record(observation, info)
    for _ in range(moves):
        observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
        record(observation, info)
        if terminated or truncated:
            break
    env.close()
    return Trace(
        areas=np.array(areas),
        errors=np.array(errors),
        bearings=np.array(bearings),
        polygons=polygons,
        estimates=np.array(estimates),
        contains=np.array(contains),
        truth_fl=world_to_fl(world.landmarks, l1, l2),
        trajectory_fl=np.array(trajectory),
    )


def random_polygonal_traces(
    env_kwargs: dict[str, Any], seeds: Sequence[int], moves: int, bar: Any
) -> list[Trace]:
    """One :func:`random_polygonal_trace` per seed, advancing the progress ``bar`` by one
    per run."""
    traces = []
    for seed in seeds:
        traces.append(random_polygonal_trace(env_kwargs, seed, moves))
        bar.update()
    return traces


def linear_fit(x: NDArray[np.float64], y: NDArray[np.float64]) -> dict[str, float]:
    """Least-squares line ``y = slope * x + intercept`` and its coefficient of determination."""
    slope, intercept = np.polyfit(x, y, 1)
    residual = y - (slope * x + intercept)
    total = float(np.sum((y - y.mean()) ** 2))
    r_squared = 1.0 - float(np.sum(residual**2)) / total if total > 0 else 1.0
    return {"slope": float(slope), "intercept": float(intercept), "r_squared": r_squared}


def power_fit(x: NDArray[np.float64], y: NDArray[np.float64]) -> dict[str, float]:
    """``y = c * x**p`` by least squares in log-log; its exponent p and R^2 (in logs)."""
    fit = linear_fit(np.log(x), np.log(y))
    return {
        "exponent": fit["slope"],
        "coefficient": math.exp(fit["intercept"]),
        "r_squared_loglog": fit["r_squared"],
    }


def save_and_close(
    figure: Any, path: Path, rect: tuple[float, float, float, float] | None = None
) -> Path:
    """Lay out a finished figure (``tight_layout`` within ``rect``), write it to ``path``
    atomically and free it."""
    figure.tight_layout(rect=rect)
    atomic_save_figure(figure, path)
    _plt().close(figure)
    return path


def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# --------------------------------------------------------------------------------------
# Fig. 7
# --------------------------------------------------------------------------------------


def shows_shrinking(areas: NDArray[np.float64], movements: Sequence[int]) -> bool:
    """Whether every region is initialised at the first panel and strictly smaller at
    each later one: the run Fig. 7 illustrates (many random runs waste movements that
    cannot change frames, which the paper's illustration does not show)."""
    panels = areas[list(movements)]
    return bool(np.all(np.isfinite(panels[0])) and np.all(np.diff(panels, axis=0) < 0.0))


def fig7_run(
    env_kwargs: dict[str, Any], first_seed: int, max_tries: int
) -> tuple[int, Trace]:
    """The first seed from ``first_seed`` whose run shrinks both regions at every panel of
    Fig. 7, and its trace; RuntimeError naming the range when none of ``max_tries`` does."""
    moves = max(FIG7_MOVEMENTS)
    for seed in range(first_seed, first_seed + max_tries):
        trace = random_polygonal_trace(env_kwargs, seed, moves, keep_polygons=True)
        if trace.areas.shape[0] > moves and shows_shrinking(trace.areas, FIG7_MOVEMENTS):
            return seed, trace
    raise RuntimeError(
        f"no seed in {first_seed}..{first_seed + max_tries - 1} initialises L3 and L4 on "
        "the first movement and shrinks both at every panel"
    )


def fig7_frame(trace: Trace) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The lower-left and upper-right corners shared by Fig. 7's panels: the landmarks,
    the path and the panels' regions, padded."""
    truth = trace.truth_fl
    points = [truth, trace.trajectory_fl[: max(FIG7_MOVEMENTS) + 1]]
    points += [p for m in FIG7_MOVEMENTS for p in trace.polygons[m] if p is not None]
    cloud = np.concatenate(points)
    # A huge first-movement region must not shrink everything else to a dot.
    limit_low, limit_high = truth.min(axis=0) - 1.5, truth.max(axis=0) + 1.5
    low = np.maximum(cloud.min(axis=0), limit_low) - np.array([0.3, 0.45])
    high = np.minimum(cloud.max(axis=0), limit_high) + 0.3
    return low, high


FIG7_COLOURS = {"L3": "tab:red", "L4": "tab:blue"}


def _draw_fig7_regions(axes: Any, trace: Trace, movement: int) -> None:
    """A_L3 and A_L4 after ``movement`` movements, labelled, with their estimates."""
    for j, name in enumerate(("L3", "L4")):
        polygon = trace.polygons[movement][j]
        if polygon is not None:
            colour = FIG7_COLOURS[name]
            closed = np.vstack([polygon, polygon[:1]])
            axes.fill(closed[:, 0], closed[:, 1], color=colour, alpha=0.12)
            axes.plot(closed[:, 0], closed[:, 1], color=colour, lw=1.3)
            # Label beside the region's right-most vertex, clear of the landmark's name.
            anchor = polygon[int(np.argmax(polygon[:, 0]))]
            axes.annotate(
                f"$A_{{{name}}}$",
                anchor,
                xytext=(4, 0),
                textcoords="offset points",
                color=colour,
                fontsize=10,
                va="center",
            )
        estimate = trace.estimates[movement][j]
        if np.all(np.isfinite(estimate)):
            axes.plot(*estimate, "o", mfc="none", mec="k", ms=7)


def _draw_fig7_panel(
    axes: Any, trace: Trace, movement: int, frame: tuple[NDArray[np.float64], ...]
) -> None:
    """One panel of Fig. 7: the regions, the true landmarks, the path so far, in FL."""
    _draw_fig7_regions(axes, trace, movement)
    truth = trace.truth_fl
    axes.plot(truth[:, 0], truth[:, 1], "k*", ms=11)
    for index, name in enumerate(("L1", "L2", "L3", "L4")):
        axes.annotate(name, truth[index], xytext=(-6, -16), textcoords="offset points", fontsize=10)
    for start, end in itertools.pairwise(trace.trajectory_fl[: movement + 1]):
        axes.annotate("", end, start, arrowprops={"arrowstyle": "->", "color": "0.35", "lw": 1.1})
    low, high = frame
    axes.set_xlim(low[0], high[0])
    axes.set_ylim(low[1], high[1])
    axes.set_aspect("equal")
    axes.tick_params(labelsize=8)
    axes.set_xlabel("x in FL (FL units)", fontsize=8)
    axes.set_ylabel("y in FL (FL units)", fontsize=8)
    title = "initial movement" if movement == 1 else f"{movement} movements"
    axes.set_title(f"Estimated uncertainty after {title}", fontsize=10)


def figure7(
    out: Path,
    first_seed: int = 0,
    transfer: str = "paper",
    epsilon_deg: float = 2.0,
    max_tries: int = 200,
) -> tuple[Path, dict[str, Any]]:
    """The regions of L3 and L4 after 1, 3, 6 and 9 movements of one run (4 panels)."""
    env_kwargs = figure_env_kwargs("paper_sim", transfer, epsilon_deg)
    seed, trace = fig7_run(env_kwargs, first_seed, max_tries)
    plt = _plt()
    figure, axes_grid = plt.subplots(2, 2, figsize=(8.0, 7.6), dpi=FIGURE_DPI)
    frame = fig7_frame(trace)
    for axes, movement in zip(axes_grid.ravel(), FIG7_MOVEMENTS, strict=True):
        _draw_fig7_panel(axes, trace, movement, frame)
    handles = [
        plt.Line2D([], [], ls="none", marker="*", color="k", ms=10, label="actual position"),
        plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="k", label="estimated position"),
        plt.Line2D([], [], color="0.35", label="robot movements (arrows)"),
    ]
    figure.legend(handles=handles, loc="lower center", ncol=3, fontsize=9, frameon=False)
    figure.suptitle(
        f"Fig. 7 (simulation): $A_{{L3}}$ and $A_{{L4}}$ shrink as movements accumulate\n"
        f"paper_sim world, random polygonal run (seed {seed}), ε = {epsilon_deg:g}°, "
        f"{transfer} transfer, FL frame (L1 = 0, L2 = 1)",
        fontsize=10,
    )
    path = save_and_close(figure, out / "fig7_polygons.png", rect=(0, 0.04, 1, 0.94))
    data = {
        "seed": seed,
        "runs_skipped": seed - first_seed,
        "env_kwargs": env_kwargs,
        "areas": {str(m): trace.areas[m].tolist() for m in FIG7_MOVEMENTS},
    }
    return path, data


# --------------------------------------------------------------------------------------
# Fig. 10
# --------------------------------------------------------------------------------------


def _clip_first_movements(axes: Any, medians: NDArray[np.float64], skip: int) -> None:
    """Linear y axis from 0 to a little above the medians after the first ``skip``
    movements, as in the paper's plots: a first movement whose region is still huge (or
    unbounded) runs off the top instead of flattening every other point."""
    later = medians[skip:]
    later = later[np.isfinite(later)]
    if later.size:
        axes.set_ylim(0.0, 1.25 * float(later.max()))
        if np.any(~np.isfinite(medians[:skip]) | (medians[:skip] > 1.25 * later.max())):
            text = "first movement" if skip == 1 else f"first {skip} movements"
            axes.annotate(
                f"{text}: off scale",
                (0.02, 0.97),
                xycoords="axes fraction",
                va="top",
                fontsize=7,
                color="0.4",
            )


def _quantiles(values: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """Median and interquartile range over axis 0 (inf = not initialised counts as large)."""
    with np.errstate(invalid="ignore"):  # inf - inf between two uninitialised runs
        q1, median, q3 = np.percentile(values, [25, 50, 75], axis=0, method="linear")
    return median, q1, q3


def figure10(
    out: Path,
    seeds: Sequence[int],
    transfer: str = "paper",
    epsilon_deg: float = 2.0,
    moves: int = 10,
    progress: bool = False,
) -> tuple[Path, dict[str, Any]]:
    """Area and error of L3 and L4 against movements, Khepera, median over ``seeds``."""
    env_kwargs = figure_env_kwargs("khepera", transfer, epsilon_deg)
    with progress_bar(len(seeds), desc="fig. 10", unit="run", enabled=progress) as bar:
        traces = random_polygonal_traces(env_kwargs, seeds, moves, bar)
    areas = np.stack([t.areas[: moves + 1] for t in traces])  # (seeds, moves+1, 2)
    errors = np.stack([t.errors[: moves + 1] for t in traces])
    plt = _plt()
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 6.6), dpi=FIGURE_DPI, sharex=True)
    x = np.arange(1, moves + 1)
    colours = {"L3": "tab:red", "L4": "tab:blue"}
    data: dict[str, Any] = {"env_kwargs": env_kwargs, "seeds": [seeds[0], seeds[-1]]}
    for j, name in enumerate(("L3", "L4")):
        for axes, values, key in ((top, areas, "area"), (bottom, errors, "error")):
            median, q1, q3 = _quantiles(values[:, 1:, j])
            shown = np.where(np.isfinite(median), median, np.nan)
            axes.plot(x, shown, "-o", color=colours[name], ms=4, label=f"$L_{name[1]}$ median")
            axes.fill_between(
                x,
                np.where(np.isfinite(q1), q1, np.nan),
                np.where(np.isfinite(q3), q3, np.nan),
                color=colours[name],
                alpha=0.15,
                lw=0,
            )
            data[f"{key}_{name}_median"] = [_json_float(v) for v in median]
            data[f"{name}_initialised_rate"] = np.isfinite(values[:, 1:, j]).mean(0).tolist()
        bottom.axhline(
            PAPER_FINAL_ERRORS[name],
            color=colours[name],
            ls=":",
            lw=1.2,
            label=f"paper, real robot: $L_{name[1]}$ {PAPER_FINAL_ERRORS[name]:.2f}",
        )
    top.set_ylabel("Area of polygon (FL units²)")
    bottom.set_ylabel("Distance from estimated\nto actual landmark (FL units)")
    for axes in (top, bottom):  # the panels share x; both say what it is
        axes.set_xlabel("Movements")
        axes.tick_params(labelbottom=True)
    for axes, values in ((top, areas), (bottom, errors)):
        _clip_first_movements(axes, np.median(values[:, 1:, :], axis=0), skip=1)
    for axes in (top, bottom):
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
    top.set_title(
        f"Fig. 10 (simulation): Khepera field, ε = {epsilon_deg:g}°, {len(seeds)} random "
        f"polygonal runs of {moves} x {KHEPERA_MOVE_LENGTH * 100:.0f} cm\n"
        f"median, band: interquartile range; {transfer} transfer; 1 unit = 20 cm",
        fontsize=9,
    )
    return save_and_close(figure, out / "fig10_khepera.png"), data


# --------------------------------------------------------------------------------------
# Fig. 11
# --------------------------------------------------------------------------------------


def fig11_runs(
    seeds: Sequence[int],
    transfer: str,
    noise_mode: str,
    epsilons: Sequence[float],
    moves: int,
    bar: Any,
) -> dict[float, dict[str, NDArray[np.float64]]]:
    """Per epsilon, the area and error of L3 per run (rows) and movement (columns); with
    ``noise_mode="same"``, AssertionError unless every epsilon saw the very same readings
    (the protocol's premise). ``bar`` advances by one per run."""
    if noise_mode not in ("same", "scaled"):
        raise ValueError(f"noise_mode must be 'same' or 'scaled', got {noise_mode!r}")
    per_epsilon: dict[float, dict[str, NDArray[np.float64]]] = {}
    reference_bearings: list[NDArray[np.float64]] | None = None
    for epsilon in epsilons:
        env_kwargs = figure_env_kwargs("khepera", transfer, epsilon)
        if noise_mode == "same":
            env_kwargs["noise"] = {"kind": "uniform", "bound_deg": PAPER_NOISE_DEG}
        traces = random_polygonal_traces(env_kwargs, seeds, moves, bar)
        if noise_mode == "same":
            bearings = [t.bearings for t in traces]
            if reference_bearings is None:
                reference_bearings = bearings
            elif not all(
                np.array_equal(a, b) for a, b in zip(bearings, reference_bearings, strict=True)
            ):
                raise AssertionError("the bearing sets differ between epsilons")
        per_epsilon[float(epsilon)] = {
            "area": np.stack([t.areas[: moves + 1, 0] for t in traces]),
            "error": np.stack([t.errors[: moves + 1, 0] for t in traces]),
        }
    return per_epsilon


def fig11_fits(
    x_eps: NDArray[np.float64], final_median: NDArray[np.float64]
) -> dict[str, dict[str, float]]:
    """The final median area against epsilon: its least-squares line, power law, and the
    line of the region's linear size sqrt(area); empty fits with fewer than two finite
    medians."""
    finite = np.isfinite(final_median)
    if finite.sum() < 2:
        return {"linear_fit": {}, "power_fit": {}, "sqrt_area_linear_fit": {}}
    x, y = x_eps[finite], final_median[finite]
    return {
        "linear_fit": linear_fit(x, y),
        "power_fit": power_fit(x, y),
        "sqrt_area_linear_fit": linear_fit(x, np.sqrt(y)),
    }


def _plot_fig11_movements(
    axes: Any, per_epsilon: dict[float, dict[str, NDArray[np.float64]]], moves: int
) -> None:
    """The left two panels: median area and error of L3 against movements, per epsilon,
    on log axes (across epsilons the areas span three decades, and a linear axis would
    flatten the small-epsilon curves onto zero)."""
    x_eps = np.array(list(per_epsilon))
    colours = _plt().get_cmap("viridis")(np.linspace(0.0, 0.9, len(x_eps)))
    x = np.arange(1, moves + 1)
    panels = ((axes[0], "area"), (axes[1], "error"))
    for colour, epsilon in zip(colours[::-1], x_eps[::-1], strict=True):
        for panel, key in panels:
            median = np.median(per_epsilon[epsilon][key][:, 1:], axis=0)
            shown = np.where(np.isfinite(median), median, np.nan)
            panel.plot(x, shown, "-o", ms=3, color=colour, label=f"ε={epsilon:g}")
    for panel, key in panels:
        panel.set_yscale("log")
        medians = np.stack([np.median(per_epsilon[e][key][:, 1:], axis=0) for e in x_eps])
        later = medians[:, 2:][np.isfinite(medians[:, 2:])]
        if later.size:
            # The first two movements can be unbounded-scale for large epsilon.
            panel.set_ylim(0.7 * float(later.min()), 3.0 * float(later.max()))
        panel.set_xlabel("Movements")
        panel.grid(alpha=0.3, which="both")
        panel.legend(fontsize=7, ncol=2)
    axes[0].set_title("Area of polygon of the third landmark", fontsize=10)
    axes[0].set_ylabel("median area (FL units², log)")
    axes[1].set_title(
        "Distance from estimated to actual\nlandmark of the third landmark", fontsize=10
    )
    axes[1].set_ylabel("median error (FL units, log)")


def _plot_fig11_final_area(
    panel: Any,
    x_eps: NDArray[np.float64],
    final_median: NDArray[np.float64],
    fits: dict[str, dict[str, float]],
    moves: int,
) -> None:
    """The right panel: the final median area against epsilon, with the fitted line and
    power law."""
    panel.plot(x_eps, final_median, "ko", label=f"median area after {moves} movements")
    fit, power = fits["linear_fit"], fits["power_fit"]
    if fit:
        panel.plot(
            x_eps,
            fit["slope"] * x_eps + fit["intercept"],
            "r-",
            label=f"linear fit: {fit['slope']:.3g} ε {fit['intercept']:+.3g}\n"
            f"$R^2$ = {fit['r_squared']:.3f}",
        )
        grid = np.linspace(x_eps.min(), x_eps.max(), 100)
        size_r_squared = fits["sqrt_area_linear_fit"]["r_squared"]
        panel.plot(
            grid,
            power["coefficient"] * grid ** power["exponent"],
            "b--",
            lw=1,
            label=f"power law: ∝ ε^{power['exponent']:.2f}\n"
            f"(√area vs ε: linear, $R^2$ = {size_r_squared:.3f})",
        )
    panel.set_xlabel("ε (degrees)")
    panel.set_ylabel("area of L3 (FL units²)")
    panel.set_title("Final area against ε", fontsize=10)
    panel.grid(alpha=0.3)
    panel.legend(fontsize=8)


def figure11(
    out: Path,
    seeds: Sequence[int],
    transfer: str = "paper",
    noise_mode: str = "same",
    epsilons: Sequence[float] = FIG11_EPSILONS,
    moves: int = 10,
    progress: bool = False,
) -> tuple[Path, dict[str, Any]]:
    """Area (and error) of L3 against movements for each epsilon, and the final area
    against epsilon with a linear fit: same trajectories and bearings for every epsilon."""
    runs = len(epsilons) * len(seeds)
    with progress_bar(runs, desc="fig. 11", unit="run", enabled=progress) as bar:
        per_epsilon = fig11_runs(seeds, transfer, noise_mode, epsilons, moves, bar)
    x_eps = np.array([float(e) for e in epsilons])
    final_median = np.array([np.median(per_epsilon[e]["area"][:, -1]) for e in x_eps])
    fits = fig11_fits(x_eps, final_median)
    figure, axes = _plt().subplots(1, 3, figsize=(13.5, 4.3), dpi=FIGURE_DPI)
    _plot_fig11_movements(axes, per_epsilon, moves)
    _plot_fig11_final_area(axes[2], x_eps, final_median, fits, moves)
    noise_text = (
        f"same bearings for every ε (true noise uniform ±{PAPER_NOISE_DEG:g}°)"
        if noise_mode == "same"
        else "noise uniform ±ε, same normalised draws"
    )
    figure.suptitle(
        f"Fig. 11 (simulation): Khepera field, {len(seeds)} random polygonal runs of "
        f"{moves} x {KHEPERA_MOVE_LENGTH * 100:.0f} cm, {noise_text}, {transfer} transfer; "
        "median over runs",
        fontsize=10,
    )
    path = save_and_close(figure, out / "fig11_epsilon.png", rect=(0, 0, 1, 0.94))
    data = {
        "noise_mode": noise_mode,
        "transfer": transfer,
        "epsilons": x_eps.tolist(),
        "final_area_median": [_json_float(v) for v in final_median],
        "final_initialised_rate": [
            float(np.isfinite(per_epsilon[e]["area"][:, -1]).mean()) for e in x_eps
        ],
        **fits,
    }
    return path, data


# --------------------------------------------------------------------------------------
# Robustness to outliers and to noise beyond epsilon
# --------------------------------------------------------------------------------------

#: The map settings the robustness figure compares: label -> env kwargs.
ROBUST_FUSIONS: dict[str, dict[str, Any]] = {
    "intersect, restart": {"fusion": "intersect", "on_inconsistency": "restart"},
    "intersect, keep": {"fusion": "intersect", "on_inconsistency": "keep"},
    "relaxed": {"fusion": "relaxed"},
    "robust (risk 0.05)": {"fusion": "robust"},
    "robust (risk 0.2)": {"fusion": "robust", "risk": 0.2},
    "robust, likely set": {"fusion": "robust", "robust_set": "likely"},
    "robust, nominal bound": {"fusion": "robust", "noise_bound": "nominal"},
}
ROBUST_OUTLIER_RATES: tuple[float, ...] = (0.0, 0.01, 0.05, 0.1)
#: True noise bounds, as multiples of epsilon.
ROBUST_NOISE_FACTORS: tuple[float, ...] = (1.0, 1.5, 2.0)


def robustness_point(
    env_kwargs: dict[str, Any], seeds: Sequence[int], moves: int, bar: Any = None
) -> dict[str, float]:
    """Containment (share of initialised regions holding the truth) and median total
    area after ``moves`` random polygonal moves, over ``seeds`` (``bar``, if given,
    advances by one per run)."""
    held, total_areas = [], []
    for trace in random_polygonal_traces(env_kwargs, seeds, moves, bar or NoProgress()):
        initialised = np.isfinite(trace.areas[-1])
        held.extend(trace.contains[-1][initialised].tolist())
        total_areas.append(float(np.sum(np.where(initialised, trace.areas[-1], 0.0))))
    return {
        "containment": float(np.mean(held)) if held else math.nan,
        "median_total_area": float(np.median(total_areas)),
    }


def plain_log_ticks(axes: Any, axis: str = "y") -> None:
    """A log ``axis`` ("x" or "y") whose ticks read as plain numbers (0.05, 0.2, 1.5):
    over about a decade matplotlib's default labels read "2×10⁰". Minor ticks are
    labelled all within one decade, at 2 and 5 within two, not at all beyond, so they
    never crowd."""
    from matplotlib.ticker import FuncFormatter

    def minor_label(value: float, _position: int) -> str:
        low, high = axes.get_xlim() if axis == "x" else axes.get_ylim()
        mantissa = round(value / 10 ** math.floor(math.log10(value)), 6)
        span = high / low if low > 0 else math.inf
        shown = span <= 10 or (span <= 100 and mantissa in (2.0, 5.0))
        return f"{value:.3g}" if shown else ""

    scaled = axes.xaxis if axis == "x" else axes.yaxis
    axes.set_xscale("log") if axis == "x" else axes.set_yscale("log")
    scaled.set_major_formatter(FuncFormatter(lambda value, _position: f"{value:.3g}"))
    scaled.set_minor_formatter(FuncFormatter(minor_label))
    axes.tick_params(axis=axis, which="minor", labelsize=7)


def figure_robustness(
    out: Path,
    seeds: Sequence[int],
    epsilon_deg: float = 2.0,
    moves: int = 20,
    progress: bool = False,
) -> tuple[Path, dict[str, Any]]:
    """Containment and median area against the outlier rate and the true noise bound."""
    base = {"scenario": "khepera", "epsilon_deg": epsilon_deg, "transfer": "conservative"}
    sweeps: dict[str, tuple[Sequence[float], Any]] = {
        "outlier_rate": (
            ROBUST_OUTLIER_RATES,
            lambda rate: {"kind": "uniform", "bound_deg": epsilon_deg, "outlier_rate": rate},
        ),
        "noise_factor": (
            ROBUST_NOISE_FACTORS,
            lambda factor: {"kind": "uniform", "bound_deg": factor * epsilon_deg},
        ),
    }
    data: dict[str, Any] = {"env_kwargs": base, "seeds": [seeds[0], seeds[-1]], "moves": moves}
    figure, axes = _plt().subplots(2, 3, figsize=(14.4, 6.6), dpi=FIGURE_DPI)
    runs = sum(len(values) for values, _ in sweeps.values()) * len(ROBUST_FUSIONS) * len(seeds)
    bar_context = progress_bar(runs, desc="robustness", unit="run", enabled=progress)
    with bar_context as bar:
        for column, (sweep, (values, noise_of)) in enumerate(sweeps.items()):
            data[sweep] = {"values": list(values)}
            for label, fusion in ROBUST_FUSIONS.items():
                points = [
                    robustness_point({**base, **fusion, "noise": noise_of(v)}, seeds, moves, bar)
                    for v in values
                ]
                data[sweep][label] = points
                x = [100 * v for v in values] if sweep == "outlier_rate" else list(values)
                contained = [100 * p["containment"] for p in points]
                axes[0, column].plot(x, contained, "-o", label=label)
                areas = [p["median_total_area"] for p in points]
                axes[1, column].plot(x, areas, "-o", label=label)
                # The trade-off: containment against area, one curve per fusion and sweep.
                axes[column, 2].plot(areas, contained, "-o", label=label)
            x_label = "outlier rate (% of readings)" if sweep == "outlier_rate" else (
                "true noise bound / ε"
            )
            for row in (0, 1):
                axes[row, column].set_xlabel(x_label)
                axes[row, column].tick_params(labelbottom=True)
    for column in (0, 1):
        axes[0, column].set_ylabel("regions holding the truth (%)")
        axes[1, column].set_ylabel("median total area (FL units², log)")
        plain_log_ticks(axes[1, column])
        plain_log_ticks(axes[column, 2], axis="x")
        axes[column, 2].set_xlabel("median total area (FL units², log)")
        axes[column, 2].set_ylabel("regions holding the truth (%)")
    axes[0, 2].set_title("trade-off over the outlier rates", fontsize=9)
    axes[1, 2].set_title("trade-off over the true noise bounds", fontsize=9)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    figure.suptitle(
        f"Robustness: Khepera field, ε = {epsilon_deg:g}°, {len(seeds)} random polygonal runs "
        f"of {moves} moves; conservative transfer",
        fontsize=9,
    )
    return save_and_close(figure, out / "fig_robust.png"), data


def _json_float(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env figures",
        "Reproduce the paper's Figs. 7, 10 and 11 in simulation, and the map's "
        "robustness to outliers (PNG).",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("outputs/figures"),
        help="output folder (default %(default)s)",
    )
    parser.add_argument(
        "--only",
        nargs="+",
        choices=("7", "10", "11", "robust"),
        default=None,
        help="make only these figures (default: all)",
    )
    parser.add_argument(
        "--seeds",
        type=COUNT,
        default=None,
        help=f"runs averaged in Figs. 10 and 11 (default {DEFAULT_SEEDS})",
    )
    parser.add_argument(
        "--seed-start",
        type=SEED,
        default=EVAL_SEED_START,
        help="seed of the first run of Figs. 10 and 11 (default %(default)s)",
    )
    parser.add_argument(
        "--fig7-seed",
        type=SEED,
        default=0,
        help="first seed tried for Fig. 7 (default %(default)s)",
    )
    parser.add_argument(
        "--transfer",
        choices=("paper", "conservative"),
        default="paper",
        help="SLAM transfer (default: the paper's, %(default)s)",
    )
    parser.add_argument(
        "--fig11-noise",
        choices=("same", "scaled"),
        default="same",
        help="Fig. 11 noise: the same bearings for every ε (default) or noise scaled with ε",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help=f"{QUICK_SEEDS} runs instead of {DEFAULT_SEEDS} (a smoke test)",
    )
    add_no_progress(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if not available("matplotlib"):
        fail(parser.prog, str(MissingExtraError("matplotlib", "drawing the figures")))
    n_seeds = args.seeds
    if n_seeds is None:
        n_seeds = QUICK_SEEDS if args.quick else DEFAULT_SEEDS
    seeds = list(range(args.seed_start, args.seed_start + n_seeds))
    wanted = set(args.only or ("7", "10", "11", "robust"))
    # Disk full, no permission, a parent that is a file: one line naming the file.
    with exit_on_output_errors(parser, args.out, "--out", refusals=()):
        make_figures(args, seeds, wanted)


def make_figures(args: argparse.Namespace, seeds: list[int], wanted: set[str]) -> None:
    """Draw the ``wanted`` figures into ``args.out`` and merge their numbers into
    ``figures.json`` there."""
    out: Path = args.out
    progress = not args.no_progress
    out.mkdir(parents=True, exist_ok=True)
    results: dict[str, Any] = {}
    if "7" in wanted:
        path, results["fig7"] = figure7(out, args.fig7_seed, args.transfer)
        print(f"wrote {path}")
    if "10" in wanted:
        path, results["fig10"] = figure10(out, seeds, args.transfer, progress=progress)
        print(f"wrote {path}")
    if "11" in wanted:
        path, results["fig11"] = figure11(
            out, seeds, args.transfer, args.fig11_noise, progress=progress
        )
        fit = results["fig11"]["linear_fit"]
        exponent = results["fig11"]["power_fit"].get("exponent", math.nan)
        print(
            f"wrote {path}: final area against epsilon, linear fit "
            f"R^2 = {fit.get('r_squared', math.nan):.3f}, power-law exponent {exponent:.2f}"
        )
    if "robust" in wanted:
        path, results["robust"] = figure_robustness(out, seeds, progress=progress)
        print(f"wrote {path}")
    summary_path = out / "figures.json"
    previous = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    previous.update(results)
    atomic_write_text(summary_path, json.dumps(previous, indent=1) + "\n")


if __name__ == "__main__":
    main()


def markdown_fig11(figures: dict[str, Any]) -> str:
    """The Fig. 11 fits of ``figures.json`` as a Markdown table (``bearing-env
    docs-tables`` writes the results page's with it)."""
    fig11 = figures["fig11"]
    epsilons, medians = fig11["epsilons"], fig11["final_area_median"]
    rows = [
        ("√area linear in ε: R²", f"{fig11['sqrt_area_linear_fit']['r_squared']:.4f}"),
        ("power law area ∝ ε^k: exponent k", f"{fig11['power_fit']['exponent']:.2f}"),
        ("power law: log-log R²", f"{fig11['power_fit']['r_squared_loglog']:.4f}"),
        ("the paper's linear law, area linear in ε: R²", f"{fig11['linear_fit']['r_squared']:.3f}"),
    ]
    lines = [
        f"Transfer `{fig11['transfer']}`, noise `{fig11['noise_mode']}`; median L3 area after "
        f"10 movements: {medians[0]:.3g} FL units² at ε = {epsilons[0]:g}° to "
        f"{medians[-1]:.3g} at {epsilons[-1]:g}° (`docs/figures/figures.json`).",
        "",
        "| Fig. 11 fit | value |",
        "|---|---|",
        *(f"| {name} | {value} |" for name, value in rows),
    ]
    return "\n".join(lines)


def markdown_robust(figures: dict[str, Any]) -> str:
    """The robustness figure's numbers of ``figures.json`` as two Markdown tables:
    containment (median total area) per fusion setting, against the outlier rate and
    against the true noise bound."""
    robust = figures["robust"]
    parts = []
    def rate(value: float) -> str:
        return f"{100 * value:g}%"

    def bound(value: float) -> str:
        return f"{value:g} ε"

    labels: tuple[tuple[str, str, Callable[[float], str]], ...] = (
        ("outlier_rate", "outlier rate", rate),
        ("noise_factor", "true bound", bound),
    )
    for key, name, label in labels:
        section = robust[key]
        settings = [s for s in section if s != "values"]
        rows = [
            "| " + " | ".join(
                [label(value)]
                + [
                    f"{100 * section[s][i]['containment']:.1f}% "
                    f"({section[s][i]['median_total_area']:.3g})"
                    for s in settings
                ]
            ) + " |"
            for i, value in enumerate(section["values"])
        ]
        parts += [
            "| " + " | ".join([name, *settings]) + " |",
            "|" + "---|" * (len(settings) + 1),
            *rows,
            "",
        ]
    return "\n".join(parts).rstrip("\n")
