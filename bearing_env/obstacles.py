"""Polygonal obstacles in an arena: their forms, their file format, their checks and a
seeded random generator.

An obstacle is a simple polygon given by its vertices ``(x, y)`` in metres (either
orientation, closed implicitly). The ``obstacles`` setting takes:

- a sequence of polygons, each a sequence of at least 3 ``(x, y)`` vertices;
- the path (``str`` or ``os.PathLike``) of a JSON or YAML file (by its suffix:
  ``.json``, ``.yaml``, ``.yml``; YAML needs pyyaml, which the ``train`` extra installs)
  holding ``{"obstacles": [polygon, ...]}``, where a
  polygon is a list of ``[x, y]`` pairs or a mapping ``{"name": ..., "vertices": [...]}``
  (the name is for people; it is not kept);
- a mapping ``{"random": count, "seed": seed}``: ``count`` random boxes from
  :func:`random_obstacles` (the same seed, the same boxes);
- ``None``: the scenario's obstacles (none for most scenarios).

Every polygon must be simple (no self-crossing, non-zero area), lie inside the arena
and not overlap another; anything else raises a ``TypeError`` or ``ValueError`` naming
the value. The simulator's compiled geometry is :mod:`bearing_env.sensing`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from bearing_env.validation import int_at_least, is_integer

if TYPE_CHECKING:  # shapely is imported where it is used: an env without obstacles never needs it
    from shapely.geometry import Polygon

#: An obstacle as the settings hold it: its vertices (x, y) in metres.
Obstacle = tuple[tuple[float, float], ...]
#: File suffixes :func:`load_obstacles` reads.
OBSTACLE_FILE_SUFFIXES: tuple[str, ...] = (".json", ".yaml", ".yml")


def parse_obstacles(spec: Any, width: float, height: float) -> tuple[Obstacle, ...]:
    """The obstacles of a setting (see the module doc), checked against an arena of
    ``width`` x ``height`` metres."""
    if spec is None:
        return ()
    if isinstance(spec, (str, os.PathLike)):
        return parse_obstacles(load_obstacles(spec), width, height)
    if isinstance(spec, Mapping):
        return _random_spec(spec, width, height)
    if isinstance(spec, np.ndarray) and spec.ndim == 3:
        spec = list(spec)
    if not isinstance(spec, (Sequence, np.ndarray)):
        raise TypeError(
            f"obstacles must be a sequence of polygons, a file path, a mapping "
            f"{{'random': count, 'seed': seed}} or None, got {spec!r}"
        )
    polygons = tuple(_polygon(item, index) for index, item in enumerate(spec))
    check_obstacles(polygons, width, height)
    return polygons


def _polygon(item: Any, index: int) -> Obstacle:
    if isinstance(item, Mapping):
        if "vertices" not in item:
            raise ValueError(f"obstacle {index}: a mapping needs 'vertices', got {dict(item)!r}")
        item = item["vertices"]
    try:
        points = np.array(item, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise TypeError(
            f"obstacle {index} must be a list of (x, y) vertices, got {item!r}"
        ) from error
    if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3:
        raise ValueError(f"obstacle {index} must have >= 3 (x, y) vertices, got {item!r}")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"obstacle {index} must have finite vertices, got {points.tolist()}")
    return tuple((float(x), float(y)) for x, y in points)


def check_obstacles(polygons: Sequence[Obstacle], width: float, height: float) -> None:
    """ValueError unless every polygon is simple, inside the arena and apart from the
    others (touching is overlapping: the robot could not pass between them anyway)."""
    if not polygons:
        return
    from shapely.geometry import Polygon

    shapes: list[Polygon] = []
    for index, polygon in enumerate(polygons):
        shape = Polygon(polygon)
        if not shape.is_valid or shape.area <= 0.0:
            raise ValueError(
                f"obstacle {index} must be a simple polygon with an area, got {list(polygon)}"
            )
        xs, ys = zip(*polygon, strict=True)
        if min(xs) < 0.0 or min(ys) < 0.0 or max(xs) > width or max(ys) > height:
            raise ValueError(
                f"obstacle {index} {list(polygon)} leaves the arena {width:g} x {height:g} m"
            )
        for other, earlier in enumerate(shapes):
            if shape.intersects(earlier):
                raise ValueError(f"obstacles {other} and {index} overlap")
        shapes.append(shape)


def load_obstacles(path: str | os.PathLike[str]) -> list[Any]:
    """The polygons of an obstacle file (JSON or YAML by suffix; see the module doc),
    unchecked: :func:`parse_obstacles` checks them against the arena."""
    file = Path(path)
    if file.suffix.lower() not in OBSTACLE_FILE_SUFFIXES:
        raise ValueError(f"obstacle file {str(file)!r} must end in one of {OBSTACLE_FILE_SUFFIXES}")
    try:
        text = file.read_text(encoding="utf-8")
    except OSError as error:
        raise ValueError(f"cannot read obstacle file {str(file)!r}: {error}") from error
    if file.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as error:
            raise ValueError(f"obstacle file {str(file)!r} is not valid JSON: {error}") from error
    else:
        data = _yaml(file, text)
    if not isinstance(data, Mapping) or not isinstance(data.get("obstacles"), list):
        raise ValueError(
            f"obstacle file {str(file)!r} must hold a mapping with an 'obstacles' list, "
            f"got {data!r}"
        )
    unknown = set(data) - {"obstacles"}
    if unknown:
        raise ValueError(f"obstacle file {str(file)!r}: unknown keys {sorted(unknown)}")
    return list(data["obstacles"])


def _yaml(file: Path, text: str) -> Any:
    """A YAML file's data; pyyaml is imported only here (an optional dependency)."""
    try:
        import yaml  # type: ignore[import-untyped]  # why: pyyaml ships no types
    except ImportError as error:
        raise ValueError(
            f"obstacle file {str(file)!r}: YAML needs pyyaml (pip install pyyaml); "
            "or write the file as JSON"
        ) from error
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise ValueError(f"obstacle file {str(file)!r} is not valid YAML: {error}") from error


def _random_spec(spec: Mapping[str, Any], width: float, height: float) -> tuple[Obstacle, ...]:
    if set(spec) != {"random", "seed"}:
        raise ValueError(
            f"random obstacles are {{'random': count, 'seed': seed}}, got {dict(spec)!r}"
        )
    count = int_at_least(spec["random"], 0, "obstacles 'random' count")
    if not is_integer(spec["seed"]) or spec["seed"] < 0:
        raise ValueError(f"obstacles 'seed' must be an int >= 0, got {spec['seed']!r}")
    return random_obstacles(np.random.default_rng(int(spec["seed"])), width, height, count)


def random_obstacles(
    rng: np.random.Generator, width: float, height: float, count: int
) -> tuple[Obstacle, ...]:
    """``count`` boxes (rotated rectangles) in a ``width`` x ``height`` arena, drawn from
    ``rng``: each a tenth to a fifth of the shorter side across, kept a robot-sized gap
    (6% of the shorter side) apart and from the walls, so the free space stays connected
    in practice. Fewer boxes when no more fit (rejection sampling, deterministic)."""
    from shapely.geometry import Polygon

    short = min(width, height)
    gap = 0.06 * short
    boxes: list[Obstacle] = []
    shapes: list[Polygon] = []
    for _ in range(200 * max(count, 1)):
        if len(boxes) == count:
            break
        half_w, half_h = rng.uniform(0.05 * short, 0.1 * short, 2)
        angle = float(rng.uniform(0.0, math.pi))
        reach = math.hypot(half_w, half_h) + gap
        if 2 * reach >= short:
            continue
        cx = float(rng.uniform(reach, width - reach))
        cy = float(rng.uniform(reach, height - reach))
        c, s = math.cos(angle), math.sin(angle)
        corners = tuple(
            (cx + c * u - s * v, cy + s * u + c * v)
            for u, v in ((-half_w, -half_h), (half_w, -half_h), (half_w, half_h), (-half_w, half_h))
        )
        shape = Polygon(corners)
        if any(shape.distance(other) < gap for other in shapes):
            continue
        boxes.append(corners)
        shapes.append(shape)
    return tuple(boxes)


def box(x0: float, y0: float, x1: float, y1: float) -> Obstacle:
    """The axis-aligned rectangle [x0, x1] x [y0, y1], counter-clockwise."""
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
