"""``bearing-env distill``: DAgger from a planner into a saved SB3 model.

A planner that is too slow to act in training (``LookaheadOracle``: tens of ms per
move) can still *label* states. DAgger (Ross, Gordon & Bagnell 2011) aggregates those
labels over the states the learner itself visits:

1. iteration 0: the teacher acts; every state it visits is labelled with its action;
2. the student's actor is trained to output the teacher's action on all the labels so
   far (a continuous policy: squared error of the Gaussian policy's mean, the turn taken
   as an angle, :func:`action_error`; a discrete one: the cross-entropy of its choice
   against the teacher's action, :func:`choice_error`; the value network and the log
   standard deviation are left as they are, so PPO can fine-tune the result);
3. iterations 1, 2, ...: the *student* acts (deterministically), the teacher labels the
   states it reaches, and step 2 runs again on the grown dataset.

The student is any SB3 actor-critic model (a ``Box`` or ``Discrete`` action) with a
task record (a
``.zip`` that ``bearing-env train --export`` wrote, or ``pretrained:NAME``); its episodes
run in its own task's env, which the teacher sees as well (a privileged teacher reads the
true world). Observations are stored raw and normalised with the student's frozen
``VecNormalize`` statistics.

The output folder holds the student as a shipped model is laid out, so
``bearing-env train --init-from OUTPUT/model.zip`` fine-tunes it and ``compare
--policies sb3:OUTPUT/model.zip`` evaluates it:

    model.zip, model_vecnormalize.pkl, model.json   the student after the last iteration
    dataset.npz     observations, teacher actions, iteration and episode seed per label
    distill.json    the settings, and per iteration: who acted, the seeds, the capped
                    total area after 10 moves and at the end (median), and the loss

Everything is saved after every episode and every training step. Ctrl-C (or SIGTERM)
stops the run once the episode under way is saved (a second Ctrl-C stops at once, losing
that episode), and ``--resume`` continues where the run stopped, with the same settings.
Episode ``e`` of iteration ``i`` resets with seed ``seed_start + i * episodes + e``, in the
training seed range (``bearing_env.train.common.seeds``), so no evaluation episode is
trained on.

    bearing-env distill --student pretrained:ppo_khepera --teacher lookahead_oracle \\
        --iterations 4 --episodes 50 --output runs/distill_khepera
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

from bearing_env.agents.registry import make_policy
from bearing_env.agents.sb3 import SB3Policy
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT, SEED, at_least
from bearing_env.train.common.errors import fail, write_error_message
from bearing_env.train.common.files import atomic_path, write_json_atomically
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.seeds import TRAINING_SEED_LIMIT
from bearing_env.train.compare.runner import capped_total_area
from bearing_env.train.sb3.callbacks import StopRequest
from bearing_env.train.sb3.train import stop_on_signals
from bearing_env.train.sb3.train_cli import EXIT_INTERRUPTED, init_model_path

MODEL_NAME = "model.zip"
VECNORMALIZE_NAME = "model_vecnormalize.pkl"
RECORD_NAME = "model.json"
DATASET_NAME = "dataset.npz"
STATE_NAME = "distill.json"
#: The move after which the per-iteration log reads the total area (and at the end).
AREA_MOVE = 10
#: What Ctrl-C prints: the episode under way is finished and saved first.
STOP_NOTICE = "stopping after this episode"


@dataclass(frozen=True)
class DistillSettings:
    """One distillation run (validated on creation).

    Args:
        student: the model to train: an exported ``.zip`` or ``pretrained:NAME``.
        output: the folder the run writes (see the module doc).
        teacher: the labelling policy, as a policy spec (``lookahead_oracle``,
            ``lookahead:depth=3``, ``greedy``, ...).
        iterations: DAgger iterations; iteration 0 is the teacher's own episodes.
        episodes: episodes per iteration.
        epochs: passes over the whole dataset after each iteration.
        batch_size: labels per gradient step.
        learning_rate: Adam's step size for the actor.
        seed: seeds the minibatch order and torch.
        seed_start: the reset seed of iteration 0's first episode.
        progress: show a progress bar over the episodes.
    """

    student: str
    output: Path
    teacher: str = "lookahead_oracle"
    iterations: int = 4
    episodes: int = 50
    epochs: int = 20
    batch_size: int = 256
    learning_rate: float = 3e-4
    seed: int = 0
    seed_start: int = 600_000
    progress: bool = True

    def __post_init__(self) -> None:
        for name in ("iterations", "episodes", "epochs", "batch_size"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if not self.learning_rate > 0:
            raise ValueError(f"learning_rate must be > 0, got {self.learning_rate}")
        last = self.seed_start + self.iterations * self.episodes
        if self.seed_start < 0 or last > TRAINING_SEED_LIMIT:
            raise ValueError(
                f"the episode seeds {self.seed_start}..{last - 1} must stay in the training "
                f"range [0, {TRAINING_SEED_LIMIT}): lower seed_start, iterations or episodes"
            )

    def episode_seed(self, iteration: int, episode: int) -> int:
        return self.seed_start + iteration * self.episodes + episode

    def as_record(self) -> dict[str, Any]:
        return {**asdict(self), "output": str(self.output)}


@dataclass
class Dataset:
    """The labels so far: observations (raw, by key for a ``Dict`` space), the teacher's
    actions, and the iteration and episode seed of each."""

    observations: dict[str, np.ndarray]
    actions: np.ndarray
    iteration: np.ndarray
    episode_seed: np.ndarray

    @classmethod
    def empty(cls, observation_space: spaces.Space[Any], action_dim: int) -> Dataset:
        shapes = _observation_shapes(observation_space)
        return cls(
            {key: np.zeros((0, *shape), np.float32) for key, shape in shapes.items()},
            np.zeros((0, action_dim), np.float32),
            np.zeros(0, np.int64),
            np.zeros(0, np.int64),
        )

    def __len__(self) -> int:
        return int(self.actions.shape[0])

    def extend(self, episode: EpisodeLabels, iteration: int, seed: int) -> None:
        for key in self.observations:
            stacked = np.stack([np.asarray(obs[key], np.float32) for obs in episode.observations])
            self.observations[key] = np.concatenate([self.observations[key], stacked])
        self.actions = np.concatenate([self.actions, np.asarray(episode.actions, np.float32)])
        count = len(episode.actions)
        self.iteration = np.concatenate([self.iteration, np.full(count, iteration, np.int64)])
        self.episode_seed = np.concatenate([self.episode_seed, np.full(count, seed, np.int64)])

    def seeds_of(self, iteration: int) -> set[int]:
        return {int(s) for s in np.unique(self.episode_seed[self.iteration == iteration])}

    def save(self, path: Path) -> None:
        arrays: dict[str, Any] = {f"obs.{key}": value for key, value in self.observations.items()}
        arrays.update(
            actions=self.actions, iteration=self.iteration, episode_seed=self.episode_seed
        )
        with atomic_path(path, suffix=".npz") as temporary:
            np.savez(temporary, **arrays)

    @classmethod
    def load(cls, path: Path) -> Dataset:
        with np.load(path) as data:
            observations = {
                name.removeprefix("obs."): data[name] for name in data.files if name[:4] == "obs."
            }
            return cls(observations, data["actions"], data["iteration"], data["episode_seed"])

    def observation_batch(self, index: np.ndarray) -> Any:
        if list(self.observations) == [""]:
            return self.observations[""][index]
        return {key: value[index] for key, value in self.observations.items()}


@dataclass
class EpisodeLabels:
    """One episode's states, as observed, and the teacher's action at each."""

    observations: list[dict[str, np.ndarray]]
    actions: list[np.ndarray]
    areas: list[float]


def _observation_shapes(space: spaces.Space[Any]) -> dict[str, tuple[int, ...]]:
    """The stored arrays of an observation: ``""`` for a ``Box``, one per ``Dict`` key."""
    if isinstance(space, spaces.Box):
        return {"": space.shape}
    if isinstance(space, spaces.Dict) and all(
        isinstance(sub, spaces.Box) for sub in space.spaces.values()
    ):
        return {key: sub.shape for key, sub in space.spaces.items() if sub.shape is not None}
    raise TypeError(f"distill stores Box or Dict-of-Box observations, got {space}")


def _as_keyed(observation: Any) -> dict[str, np.ndarray]:
    if isinstance(observation, dict):
        return {key: np.asarray(value) for key, value in observation.items()}
    return {"": np.asarray(observation)}


def load_student(settings: DistillSettings, resume: bool) -> SB3Policy:
    """The student: the output's ``model.zip`` when resuming after a training step, else
    the given model; its task is the ``.json`` record beside it.

    Raises:
        ValueError: a model that is not an actor-critic with a ``Box`` or ``Discrete``
            action, or that has no task record or no ``VecNormalize`` statistics.
    """
    saved = settings.output / MODEL_NAME
    path = saved if resume and saved.is_file() else init_model_path(settings.student, "--student")
    assert path is not None  # the student is required
    student = SB3Policy(None, path)
    if student.task is None:
        raise ValueError(
            f"the student {settings.student} has no task record "
            f"({student.model_path.with_suffix('.json').name}): distill a model exported "
            "with bearing-env train --export, or pretrained:NAME"
        )
    if not isinstance(student.model.action_space, spaces.Box | spaces.Discrete):
        raise ValueError(
            f"distill trains models with Box or Discrete actions; {settings.student} outputs "
            f"{student.model.action_space}"
        )
    if not hasattr(student.model.policy, "action_net"):
        raise ValueError(f"distill trains actor-critic models (PPO, A2C), not {settings.student}")
    if student.obs_normalizer is None:
        raise ValueError(f"{settings.student} has no VecNormalize statistics beside it")
    return student


def play_episode(
    env: Any, teacher: Any, student: SB3Policy, student_acts: bool, seed: int
) -> EpisodeLabels:
    """One episode: who acts is ``student_acts``; the teacher labels every state."""
    from bearing_env.agents.env_access import bearing_env_of

    area_cap = float(bearing_env_of(env).config.task.area_cap)
    observation, info = env.reset(seed=seed)
    teacher.reset(seed=seed)
    student.reset(seed=seed)
    labels = EpisodeLabels([], [], [capped_total_area(info, area_cap)])
    done = False
    while not done:
        taught = teacher.act(observation, info)
        label = np.asarray(taught, np.float32).reshape(-1)
        labels.observations.append(_as_keyed(observation))
        labels.actions.append(label)
        # A discrete teacher's index is stepped as it is; a continuous action as labelled.
        action = (
            student.act(observation, info)
            if student_acts
            else (taught if _discrete(student) else label)
        )
        observation, _, terminated, truncated, info = env.step(action)
        labels.areas.append(capped_total_area(info, area_cap))
        done = bool(terminated or truncated)
    return labels


def _actor_parameters(policy: Any) -> list[Any]:
    """What behaviour cloning trains: the actor's features extractor, network and mean
    head; not the value network, nor the log standard deviation PPO explores with."""
    modules = [policy.pi_features_extractor, policy.mlp_extractor.policy_net, policy.action_net]
    unique: dict[int, Any] = {}
    for module in modules:
        for parameter in module.parameters():
            unique[id(parameter)] = parameter
    return list(unique.values())


def _mean_actions(student: SB3Policy, observations: Any) -> Any:
    """The actor's output on raw observations: the Gaussian's mean (a ``Box`` action) or
    the choice's logits (``Discrete``)."""
    policy = student.model.policy
    assert student.obs_normalizer is not None  # load_student refuses a model without
    normalised = student.obs_normalizer.normalize_obs(observations)
    tensor, _ = policy.obs_to_tensor(normalised)
    distribution = policy.get_distribution(tensor).distribution
    return distribution.logits if _discrete(student) else distribution.mean


def _discrete(student: SB3Policy) -> bool:
    return isinstance(student.model.action_space, spaces.Discrete)


def imitation_error(student: SB3Policy, output: Any, target: Any) -> Any:
    """Per label: :func:`choice_error` of a discrete student, else :func:`action_error`."""
    return choice_error(output, target) if _discrete(student) else action_error(output, target)


def choice_error(logits: Any, target: Any) -> Any:
    """The cross-entropy of the student's choice against the teacher's action index
    (stored as a float in a column of one), per label."""
    import torch

    return torch.nn.functional.cross_entropy(logits, target[:, 0].long(), reduction="none")


def action_error(mean: Any, target: Any) -> Any:
    """Squared distance between actions, per label. The turn (column 0, the turn over
    pi) is an angle: 1 and -1 are the same turn, so its difference is taken mod 2."""
    import torch

    difference = mean - target
    turn = torch.remainder(difference[:, :1] + 1.0, 2.0) - 1.0
    return (torch.cat([turn, difference[:, 1:]], dim=1) ** 2).sum(dim=-1)


def imitation_loss(student: SB3Policy, dataset: Dataset, batch_size: int = 4096) -> float:
    """The mean :func:`imitation_error` of the student on the teacher's labels."""
    import torch

    total = 0.0
    with torch.no_grad():
        for start in range(0, len(dataset), batch_size):
            index = np.arange(start, min(start + batch_size, len(dataset)))
            mean = _mean_actions(student, dataset.observation_batch(index))
            target = torch.as_tensor(dataset.actions[index], device=mean.device)
            total += float(imitation_error(student, mean, target).sum())
    return total / max(len(dataset), 1)


def fit_student(
    student: SB3Policy, dataset: Dataset, settings: DistillSettings, iteration: int
) -> None:
    """``settings.epochs`` passes of minibatch Adam over the whole dataset."""
    import torch

    torch.manual_seed(settings.seed * 1_000 + iteration)
    rng = np.random.default_rng([settings.seed, iteration])
    policy = student.model.policy
    policy.set_training_mode(True)
    optimiser = torch.optim.Adam(_actor_parameters(policy), lr=settings.learning_rate)
    for _ in range(settings.epochs):
        order = rng.permutation(len(dataset))
        for start in range(0, len(order), settings.batch_size):
            index = order[start : start + settings.batch_size]
            mean = _mean_actions(student, dataset.observation_batch(index))
            target = torch.as_tensor(dataset.actions[index], device=mean.device)
            loss = imitation_error(student, mean, target).mean()
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
    policy.set_training_mode(False)


def save_student(student: SB3Policy, record: dict[str, Any], output: Path) -> None:
    """The model, its (unchanged) statistics and its record, in the shipped layout."""
    with atomic_path(output / MODEL_NAME, suffix=".zip") as temporary:
        student.model.save(temporary)
    statistics = student.vecnormalize_path
    if statistics is not None and statistics.resolve() != (output / VECNORMALIZE_NAME).resolve():
        with atomic_path(output / VECNORMALIZE_NAME) as temporary:
            shutil.copyfile(statistics, temporary)
    write_json_atomically(output / RECORD_NAME, record)


def _area_summary(areas: list[list[float]]) -> dict[str, float | None]:
    if not areas:
        return {f"median_total_area_{AREA_MOVE}": None, "median_total_area_final": None}
    after = [series[min(AREA_MOVE, len(series) - 1)] for series in areas]
    final = [series[-1] for series in areas]
    return {
        f"median_total_area_{AREA_MOVE}": float(np.median(after)),
        "median_total_area_final": float(np.median(final)),
    }


@dataclass
class DistillResult:
    output: Path
    labels: int
    iterations: list[dict[str, Any]]
    interrupted: bool = False


def _read_state(output: Path) -> dict[str, Any]:
    path = output / STATE_NAME
    return dict(json.loads(path.read_text())) if path.is_file() else {}


def _check_output(settings: DistillSettings, resume: bool) -> dict[str, Any]:
    """The saved state to resume from (empty for a new run); refuses to mix runs."""
    state = _read_state(settings.output)
    if not resume:
        if state:
            raise FileExistsError(
                f"{settings.output} holds a distillation already: pass --resume to finish "
                "it, or choose another --output"
            )
        return {}
    if not state:
        raise FileNotFoundError(f"--resume: {settings.output} holds no {STATE_NAME}")
    saved = {k: v for k, v in state["settings"].items() if k != "progress"}
    current = {k: v for k, v in settings.as_record().items() if k != "progress"}
    changed = [f"{k} {saved.get(k)!r} -> {v!r}" for k, v in current.items() if saved.get(k) != v]
    if changed:
        raise ValueError(f"--resume with other settings than the run's: {', '.join(changed)}")
    return state


def distill(settings: DistillSettings, resume: bool = False) -> DistillResult:
    """Run (or finish, with ``resume``) a DAgger distillation; see the module doc."""
    state = _check_output(settings, resume)
    student = load_student(settings, resume)
    record = json.loads(student.model_path.with_suffix(".json").read_text())
    env = student.make_env()
    teacher = make_policy(settings.teacher, env)
    dataset_path = settings.output / DATASET_NAME
    action_dim = int(np.prod(student.model.action_space.shape))
    dataset = (
        Dataset.load(dataset_path)
        if resume and dataset_path.is_file()
        else Dataset.empty(env.observation_space, action_dim)
    )
    iterations: list[dict[str, Any]] = list(state.get("iterations", []))
    record = {
        **record,
        "name": "model",
        "source": "distill",
        "distill": {"teacher": settings.teacher, "student": settings.student},
    }
    settings.output.mkdir(parents=True, exist_ok=True)

    def write_state() -> None:
        write_json_atomically(
            settings.output / STATE_NAME,
            {"settings": settings.as_record(), "iterations": iterations, "labels": len(dataset)},
        )

    total = settings.iterations * settings.episodes
    done = sum(len(dataset.seeds_of(i)) for i in range(settings.iterations))
    interrupted = False
    stop = StopRequest()
    with (
        stop_on_signals(stop, STOP_NOTICE),
        progress_bar(
            total, desc="distill", unit="episode", enabled=settings.progress, initial=done
        ) as bar,
    ):
        for iteration in range(settings.iterations):
            if iteration < len(iterations) and iterations[iteration].get("trained"):
                continue
            if iteration == len(iterations):
                iterations.append({"iteration": iteration, "actor": _actor(iteration)})
            entry = iterations[iteration]
            seen = dataset.seeds_of(iteration)
            areas: list[list[float]] = list(entry.get("areas", []))
            for episode in range(settings.episodes):
                seed = settings.episode_seed(iteration, episode)
                if seed in seen:
                    continue
                labels = play_episode(env, teacher, student, iteration > 0, seed)
                dataset.extend(labels, iteration, seed)
                areas.append(labels.areas)
                entry["areas"] = areas
                dataset.save(dataset_path)
                write_state()
                bar.update(1)
                if stop:
                    interrupted = True
                    break
            if interrupted:
                break
            entry.update(_area_summary(areas), loss_before=imitation_loss(student, dataset))
            fit_student(student, dataset, settings, iteration)
            entry.update(loss_after=imitation_loss(student, dataset), labels=len(dataset))
            save_student(student, record, settings.output)
            entry["trained"] = True
            write_state()
            bar.set_postfix(loss=f"{entry['loss_after']:.4f}")
            if stop:
                interrupted = True
                break
    env.close()
    summaries = [{k: v for k, v in entry.items() if k != "areas"} for entry in iterations]
    return DistillResult(settings.output, len(dataset), summaries, interrupted)


def _actor(iteration: int) -> str:
    return "student" if iteration > 0 else "teacher"


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env distill",
        "DAgger: label the states a student SB3 model visits with a planner's actions and "
        "train the student's actor on them; the result fine-tunes with "
        "bearing-env train --init-from OUTPUT/model.zip.",
    )
    parser.add_argument(
        "--student",
        required=True,
        help="the model to train: a .zip exported by bearing-env train --export (its .json "
        "record beside it), or pretrained:NAME",
    )
    parser.add_argument("--teacher", default="lookahead_oracle", help="the labelling policy spec")
    parser.add_argument("--output", type=Path, required=True, help="the run folder")
    parser.add_argument(
        "--resume", action="store_true", help="finish the run in --output (same settings)"
    )
    parser.add_argument("--iterations", type=COUNT, default=4, help="DAgger iterations")
    parser.add_argument("--episodes", type=COUNT, default=50, help="episodes per iteration")
    parser.add_argument("--epochs", type=COUNT, default=20, help="passes over the dataset")
    parser.add_argument("--batch-size", type=COUNT, default=256, help="labels per step")
    parser.add_argument("--learning-rate", type=float, default=3e-4, help="Adam's step size")
    parser.add_argument("--seed", type=SEED, default=0, help="minibatch order and torch")
    parser.add_argument(
        "--seed-start",
        type=at_least(0, TRAINING_SEED_LIMIT - 1),
        default=600_000,
        help="reset seed of the first episode (training range)",
    )
    add_no_progress(parser)
    return parser


def settings_from_args(args: argparse.Namespace) -> DistillSettings:
    """The run the parsed arguments describe (validated: a bad value raises ValueError)."""
    return DistillSettings(
        student=args.student,
        output=args.output,
        teacher=args.teacher,
        iterations=args.iterations,
        episodes=args.episodes,
        epochs=args.epochs,
        batch_size=args.batch_size,
        learning_rate=args.learning_rate,
        seed=args.seed,
        seed_start=args.seed_start,
        progress=not args.no_progress,
    )


def main(argv: Sequence[str] | None = None) -> None:
    args = build_parser().parse_args(sys.argv[1:] if argv is None else list(argv))
    prog = "bearing-env distill"
    try:
        result = distill(settings_from_args(args), resume=args.resume)
    except (FileNotFoundError, FileExistsError, ValueError, TypeError) as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        raise SystemExit(2) from error
    except OSError as error:
        fail(prog, write_error_message(error, args.output, "--output"))
    for entry in result.iterations:
        area = entry.get(f"median_total_area_{AREA_MOVE}")
        shown = "-" if area is None else f"{area:.4g}"
        loss = entry.get("loss_after")
        print(
            f"iteration {entry['iteration']} ({entry['actor']} acted): median total area "
            f"after {AREA_MOVE} moves {shown}, imitation loss "
            f"{entry.get('loss_before', float('nan')):.4f} -> "
            f"{float('nan') if loss is None else loss:.4f}"
        )
    print(f"{result.output / MODEL_NAME}: {result.labels} labels")
    if result.interrupted:
        print("interrupted: continue with --resume", file=sys.stderr)
        raise SystemExit(EXIT_INTERRUPTED)


if __name__ == "__main__":
    main()
