"""Policies by name, for command lines and configs.

A *policy spec* is a string ``NAME[:KEY=VALUE[,KEY=VALUE...]]``:

    random                          RandomPolygonal with its defaults
    random:length=0.25              fixed 25 cm moves
    greedy:n_turns=16,lengths=1     GreedyOneStep with 16 turns at the longest length
    lookahead:depth=3,hypotheses=6  Lookahead, a deeper search over more worlds
    sb3:path=runs/ppo/best_model.zip
    sb3:runs/ppo/best_model.zip     (sb3 only: a bare value is the path)
    pretrained:ppo_khepera          a model shipped under agents/pretrained/, by name
    parallax:label=my_parallax      ``label`` renames the policy in reports

Values are Python literals when they parse as one (``16``, ``0.25``, ``(0.1, 0.2)``,
``True``, ``None``) and strings otherwise.
"""

from __future__ import annotations

import ast
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym

from .base import Policy
from .heuristics import GreedyOneStep, GreedyOracle, Parallax, RandomPolygonal
from .lookahead import Lookahead, LookaheadOracle
from .sb3 import (
    PRETRAINED_DIR,
    SB3Policy,
    find_vecnormalize,
    pretrained_names,
    resolve_model_path,
)


def pretrained_policy(env: gym.Env, name: str, **options: Any) -> SB3Policy:
    """A shipped model by name (``SB3Policy.pretrained``), as a spec-buildable factory."""
    return SB3Policy.pretrained(name, env, **options)


#: Policy classes by spec name (the first name of each class is its canonical one).
POLICY_CLASSES: dict[str, Any] = {
    "random": RandomPolygonal,
    "random_polygonal": RandomPolygonal,
    "parallax": Parallax,
    "greedy": GreedyOneStep,
    "greedy_one_step": GreedyOneStep,
    "oracle": GreedyOracle,
    "greedy_oracle": GreedyOracle,
    "lookahead": Lookahead,
    "lookahead_oracle": LookaheadOracle,
    "sb3": SB3Policy,
    "pretrained": pretrained_policy,
}


@dataclass(frozen=True)
class PolicySpec:
    """A parsed policy spec: the class name, its options and the label to report it as."""

    kind: str
    options: dict[str, Any] = field(default_factory=dict)
    label: str | None = None

    def display_name(self) -> str:
        """The label, or one derived from the kind and options (without building it)."""
        if self.label:
            return self.label
        cls = POLICY_CLASSES[self.kind]
        if self.kind == "sb3":
            from pathlib import Path

            return f"sb3_{Path(str(self.options.get('path', 'model'))).stem}"
        if self.kind == "pretrained":
            return str(self.options.get("name", "pretrained"))
        base = str(getattr(cls, "name", self.kind))
        if not self.options:
            return base
        details = ",".join(f"{key}={value}" for key, value in sorted(self.options.items()))
        return f"{base}[{details}]"

    def to_string(self) -> str:
        """The canonical spec string (parses back to an equal spec)."""
        parts = [f"{key}={value!r}" for key, value in sorted(self.options.items())]
        if self.label:
            parts.append(f"label={self.label!r}")
        return self.kind if not parts else f"{self.kind}:{','.join(parts)}"


def _literal(text: str) -> Any:
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def _string(text: str) -> str:
    """A string option (path, label): quoted or bare."""
    value = _literal(text)
    return value if isinstance(value, str) else text


def _split_options(text: str) -> list[str]:
    """Split on commas that are not inside brackets (so ``lengths=(0.1,0.2)`` survives)."""
    items: list[str]
    current: list[str]
    items, depth, current = [], 0, []
    for char in text:
        if char in "([{":
            depth += 1
        elif char in ")]}":
            depth -= 1
        if char == "," and depth == 0:
            items.append("".join(current))
            current = []
        else:
            current.append(char)
    items.append("".join(current))
    return [item.strip() for item in items if item.strip()]


def parse_policy_spec(spec: str) -> PolicySpec:
    """Parse ``NAME[:KEY=VALUE,...]`` (see the module doc). ValueError on a bad spec."""
    kind, _, rest = spec.strip().partition(":")
    kind = kind.strip().lower()
    if kind not in POLICY_CLASSES:
        raise ValueError(
            f"unknown policy {kind!r} in spec {spec!r}; expected one of {sorted(POLICY_CLASSES)}"
        )
    options: dict[str, Any] = {}
    label = None
    for item in _split_options(rest):
        key, sep, value = item.partition("=")
        if not sep:
            if kind == "sb3" and "path" not in options:
                options["path"] = item
                continue
            if kind == "pretrained" and "name" not in options:
                options["name"] = item
                continue
            raise ValueError(f"policy option {item!r} in {spec!r} is not KEY=VALUE")
        key = key.strip()
        if key == "label":
            label = _string(value.strip())
        else:
            is_text = key == "path" or (kind == "pretrained" and key == "name")
            options[key] = _string(value.strip()) if is_text else _literal(value.strip())
    if kind == "sb3" and "path" not in options:
        raise ValueError(f"policy spec {spec!r}: sb3 needs a model path (sb3:path=...)")
    if kind == "pretrained" and "name" not in options:
        raise ValueError(f"policy spec {spec!r}: pretrained needs a model name (pretrained:NAME)")
    # Aliases collapse to one canonical kind so equal policies get equal specs.
    canonical = next(name for name, cls in POLICY_CLASSES.items() if cls is POLICY_CLASSES[kind])
    return PolicySpec(kind=canonical, options=options, label=label)


def make_policy(spec: str | PolicySpec, env: gym.Env) -> Policy:
    """Build the policy a spec describes for ``env`` (its ``name`` is the spec's label)."""
    parsed = parse_policy_spec(spec) if isinstance(spec, str) else spec
    cls = POLICY_CLASSES[parsed.kind]
    try:
        policy = cls(env, **parsed.options)
    except TypeError as error:
        raise ValueError(f"bad options for policy {parsed.kind!r}: {error}") from error
    policy.name = parsed.display_name()
    return policy


#: The options of a file-reading spec that name its files (see :func:`spec_files`).
FILE_OPTIONS = ("path", "vecnormalize")


def spec_files(spec: str | PolicySpec) -> dict[str, Path]:
    """The files a policy spec reads, by the ``sb3`` option that names each: ``path``
    (the model ``.zip``) and ``vecnormalize`` (its statistics, when it uses any). A
    ``pretrained:NAME`` spec reads the shipped model's files; the heuristics read none.

    With :func:`with_files` this lets a policy run where those paths do not exist (a
    Ray worker on another machine): send the files' bytes, write them there, and build
    the policy from the spec that names the copies.

    Raises:
        FileNotFoundError: the model, or an explicitly given statistics file, is missing.
        ValueError: no shipped model has the ``pretrained`` name.
    """
    parsed = parse_policy_spec(spec) if isinstance(spec, str) else spec
    if parsed.kind == "pretrained":
        name = str(parsed.options["name"])
        model = PRETRAINED_DIR / f"{name}.zip"
        if not model.is_file():
            raise ValueError(f"no pretrained model named {name!r}; available: {pretrained_names()}")
        vecnormalize: Any = parsed.options.get("vecnormalize", "auto")
    elif parsed.kind == "sb3":
        model = resolve_model_path(parsed.options["path"])
        vecnormalize = parsed.options.get("vecnormalize", "auto")
    else:
        return {}
    files = {"path": model}
    if vecnormalize == "auto":
        found = find_vecnormalize(model)
        if found is not None:
            files["vecnormalize"] = found
    elif vecnormalize is not None:
        explicit = Path(str(vecnormalize)).expanduser()
        if not explicit.is_file():
            raise FileNotFoundError(f"VecNormalize statistics not found: {explicit}")
        files["vecnormalize"] = explicit
    return files


def with_files(spec: str | PolicySpec, files: Mapping[str, str | Path]) -> PolicySpec:
    """The spec of the same policy reading ``files`` (option -> path, as
    :func:`spec_files` gives them) instead of its own: an ``sb3`` spec (a
    ``pretrained:NAME`` spec becomes the ``sb3`` spec of copies of the shipped files, with
    the same ``name``), whose ``vecnormalize`` is None when ``files`` holds none.

    Raises:
        ValueError: the spec reads no files, or ``files`` lacks the model (``path``) or
            names an option other than :data:`FILE_OPTIONS`.
    """
    parsed = parse_policy_spec(spec) if isinstance(spec, str) else spec
    if parsed.kind not in ("sb3", "pretrained"):
        raise ValueError(f"policy {parsed.kind!r} reads no files, so none can replace them")
    unknown = sorted(set(files) - set(FILE_OPTIONS))
    if "path" not in files or unknown:
        raise ValueError(
            f"files must name the model ('path') and may name 'vecnormalize', got {sorted(files)}"
        )
    options = dict(parsed.options)  # a pretrained spec's name stays SB3Policy's name
    options["path"] = str(files["path"])
    options["vecnormalize"] = str(files["vecnormalize"]) if "vecnormalize" in files else None
    return PolicySpec(kind="sb3", options=options, label=parsed.label or parsed.display_name())
